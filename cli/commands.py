"""The vecfit command line. Parses options, reports progress and errors; the work is
done by the vecfit package. Exit codes: 0 ok, 1 a runtime failure (some inputs could
not be processed), 2 bad usage."""
from __future__ import annotations

import signal
import sys
import threading
import time
import warnings
from pathlib import Path

import click

from vecfit.errors import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_USAGE
from vecfit.names import (EFFORTS, FILTERS, FORMATS, GROUP_BY, JOBS, LOSSES, MAX_DECIMALS, MODES, PAINT_KINDS,
                          STACKINGS, STYLES)
from vecfit.renderer.options import RenderOptions

# Path types, shared by the options: click looks up its translation of the type's name for
# each one made (file-system look-ups, three dozen types a start).
FILE = click.Path(dir_okay=False)
FOLDER = click.Path(file_okay=False)
EXISTING_FOLDER = click.Path(exists=True, file_okay=False)

DEVICE_OPTION = dict(metavar="auto|cpu|cuda[:N]",
                     help="Where pixels are shaded: auto (a GPU when vecfit was built with CUDA and "
                          "one is present), cpu, or cuda (GPU N with cuda:N).")


def _echo_err(message: str) -> None:
    click.echo(message, err=True)


def _show_warning(message, category, filename, lineno, file=None, line=None):
    _echo_err(f"warning: {message}")


def _print_version(ctx, param, value):
    if not value or ctx.resilient_parsing:
        return
    from vecfit import __version__
    from vecfit.renderer.device import core_build
    click.echo(f"vecfit {__version__} (core: {core_build()})")
    ctx.exit()


def _import_torch_holding_ctrl_c() -> None:
    """Imports torch with Ctrl-C held back until the import is done, then raised as a
    KeyboardInterrupt. Raised inside torch's own import, in its C++ module set-up, a
    KeyboardInterrupt aborts the process (SIGABRT, "terminate called after throwing an
    instance of 'pybind11::error_already_set'"), seen with a Ctrl-C 0.4 s after start."""
    if "torch" in sys.modules or threading.current_thread() is not threading.main_thread():
        return
    pending = []
    previous = signal.signal(signal.SIGINT, lambda *_: pending.append(True))
    try:
        import torch  # noqa: F401
    finally:
        signal.signal(signal.SIGINT, previous)
    if pending:
        raise KeyboardInterrupt


# Commands that may run without torch: they import it themselves where they need it
# (trace when it refines, once its settings are known; render for the files that
# _scene_to_render says need it).
_WITHOUT_TORCH = {"info", "trace", "render"}


class _Main(click.Group):
    """The command group. A Ctrl-C anywhere (while torch is imported, too) ends the
    command with "interrupted" and exit code 130, as a shell expects, where click would
    print "Aborted!" and exit 1."""

    def parse_args(self, ctx, args):
        ctx.meta["vecfit.help"] = any(a in ("-h", "--help") for a in args)  # (help needs no torch)
        ctx.meta["vecfit.command"] = next((a for a in args if not a.startswith("-")), None)
        return super().parse_args(ctx, args)

    def invoke(self, ctx):
        if not ctx.meta.get("vecfit.help") and ctx.meta.get("vecfit.command") not in _WITHOUT_TORCH:
            _import_torch_holding_ctrl_c()  # (info reads the SVG without torch)
        return super().invoke(ctx)

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, False, **extra)
        try:
            rv = super().main(args, prog_name, complete_var, False, **extra)
        except KeyboardInterrupt:
            rv = EXIT_INTERRUPTED
        except click.exceptions.Abort as e:  # click's wrapping of Ctrl-C, or of end of input
            rv = EXIT_INTERRUPTED if isinstance(e.__cause__, KeyboardInterrupt) else EXIT_FAILED
        except click.ClickException as e:
            e.show()
            sys.exit(e.exit_code)
        else:
            sys.exit(rv if isinstance(rv, int) else 0)
        _echo_err("interrupted" if rv == EXIT_INTERRUPTED else "Aborted!")
        sys.exit(rv)


@click.group(cls=_Main, context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--version", is_flag=True, expose_value=False, is_eager=True, callback=_print_version,
              help="Show the version and the compiled core's build, then exit.")
def main():
    """vecfit: turn raster images into vector graphics and refine vector graphics
    against images, with a differentiable rasterizer."""
    warnings.showwarning = _show_warning


@main.command()
@click.argument("inputs", nargs=-1, required=True, type=FILE)
@click.option("-o", "--output", type=FILE,
              help="Output PNG (one input); OUT.pdf or OUT.dxf converts the SVG to that format.")
@click.option("--out-dir", type=FOLDER, help="Folder for outputs, NAME.svg -> NAME.png.")
@click.option("--width", type=click.IntRange(min=1), help="Width in pixels (default: the SVG's).")
@click.option("--height", type=click.IntRange(min=1), help="Height in pixels (default: the SVG's).")
@click.option("--samples", type=click.IntRange(1, 64), default=RenderOptions.samples, show_default=True,
              help="N: N x N samples per pixel.")
@click.option("--mode", type=click.Choice(MODES), default=RenderOptions.mode, show_default=True,
              help="Anti-aliasing: Monte Carlo samples or the analytical prefilter.")
@click.option("--filter", "filter_", type=click.Choice(FILTERS), default=RenderOptions.filter,
              show_default=True, help="Pixel filter.")
@click.option("--filter-radius", type=click.FloatRange(min=0.5), default=RenderOptions.filter_radius,
              show_default=True, help="Pixel filter radius in pixels (tent, gaussian).")
@click.option("--background", default="none", show_default=True,
              help="none, white, black or #rrggbb[aa].")
@click.option("--seed", type=int, default=RenderOptions.seed, show_default=True, help="Random seed of the samples.")
@click.option("--threads", type=click.IntRange(min=0), default=RenderOptions.threads, help="Threads (0: all cores).")
@click.option("--device", default="auto", show_default=True, **DEVICE_OPTION)
def render(inputs, output, out_dir, width, height, samples, mode, filter_, filter_radius,
           background, seed, threads, device):
    """Render SVG files to PNG (8-bit RGBA)."""
    import vecfit
    from vecfit.errors import VecfitError
    from vecfit.io.colors import parse_background
    from vecfit.io.png import save_png
    from vecfit.renderer.device import resolve as resolve_device
    from vecfit.renderer.forward import render_numpy

    if (output is None) == (out_dir is None):
        raise click.UsageError("give either -o OUT.png (one input) or --out-dir DIR")
    if output is not None and len(inputs) > 1:
        raise click.UsageError("-o takes one input; use --out-dir for several")
    try:
        bg = parse_background(background)
    except VecfitError as e:
        raise click.BadParameter(str(e), param_hint="--background")
    try:
        resolve_device(device)
    except VecfitError as e:
        raise click.BadParameter(str(e), param_hint="--device")
    failed = 0
    for i, src in enumerate(inputs):
        dst = Path(output) if output else Path(out_dir) / (Path(src).stem + ".png")
        start = time.perf_counter()
        if dst.suffix.lower() in (".pdf", ".dxf"):  # a vector copy, not a render
            from vecfit.export import export
            try:
                export(Path(src), dst)
            except VecfitError as e:
                _echo_err(f"error: {e}")
                sys.exit(EXIT_FAILED)
            _echo_err(f"{src} -> {dst} ({time.perf_counter() - start:.2f} s)")
            continue
        try:
            scene, without_torch = _scene_to_render(src)
            draw = render_numpy if without_torch else vecfit.render
            image = draw(scene, width, height, samples=samples, mode=mode, filter=filter_,
                         filter_radius=filter_radius, seed=seed, background=bg, threads=threads, device=device)
            save_png(image, dst)
        except VecfitError as e:
            failed += 1
            _echo_err(f"error: {e}")
            continue
        h, w = image.shape[:2]
        _echo_err(f"[{i + 1}/{len(inputs)}] {src} -> {dst} ({w}x{h}, {time.perf_counter() - start:.2f} s)")
    if failed:
        _echo_err(f"{failed} of {len(inputs)} inputs failed")
        sys.exit(EXIT_FAILED)


def _scene_to_render(src):
    """The SVG at ``src`` as a Scene, and whether it renders without torch (importing
    torch took 1.2 s of the command's 3.4 s for tiger, whose render takes 0.06 s). Read
    into NumPy arrays (vecfit.scene.arrays), a file renders with render_numpy where that
    draws it as vecfit.render does (vecfit.renderer.forward.renders_without_torch); else
    (clip paths, masks, filters, dashes, gradients, rotations, skews) torch is imported
    and the file read again, into tensors. The reader's warnings are said once."""
    import vecfit
    from vecfit.renderer.forward import renders_without_torch
    from vecfit.scene.arrays import numpy_arrays

    said = []
    try:
        with warnings.catch_warnings(record=True) as said, numpy_arrays():
            warnings.simplefilter("always")
            scene = vecfit.load_svg(src)
    finally:
        for w in said:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    if renders_without_torch(scene):
        return scene, True
    _import_torch_holding_ctrl_c()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (said by the first reading)
        return vecfit.load_svg(src), False


@main.command()
@click.argument("svg", required=False, type=FILE)
@click.option("--build", is_flag=True, help="Say how this vecfit was built (compiler, CUDA, devices).")
def info(svg, build):
    """List the shapes, segments and paints of an SVG, and what was skipped; or, with
    --build, what the compiled core has."""
    if build:
        from vecfit.renderer.device import build_summary
        click.echo(build_summary())
    if svg is None:
        if not build:
            raise click.UsageError("give an SVG file, or --build")
        return
    from vecfit.errors import VecfitError
    from vecfit.scene.arrays import numpy_arrays
    from vecfit.scene.summary import summarize
    from vecfit.svg.read import load_svg

    try:
        with warnings.catch_warnings(), numpy_arrays():  # counting needs no torch
            warnings.simplefilter("ignore")
            scene = load_svg(svg)
    except VecfitError as e:
        _echo_err(f"error: {e}")
        sys.exit(EXIT_FAILED)
    click.echo(summarize(scene))


# ------------------------------------------------------------------ optimising commands

def optimize_options(f):
    """Options shared by refine, trace and paint; each overrides the config's value."""
    options = [
        click.option("-o", "--output", type=FILE,
                     help="Output SVG, or PDF or DXF by its suffix (default: NAME.vecfit.svg next to the target)."),
        click.option("--format", "output_format", type=click.Choice(FORMATS),
                     help="Write the result as SVG, PDF (print) or DXF (plotters, cutters). "
                          "[default: -o's suffix, else svg]"),
        click.option("--report", type=FILE,
                     help="JSON report (default: the output's name + .report.json)."),
        click.option("--comparison", type=FILE,
                     help="Comparison PNG (default: the output's name + .compare.png)."),
        click.option("--config", "config_file", type=FILE,
                     help="TOML file overriding the defaults in configs/."),
        click.option("--effort", type=click.Choice(EFFORTS),
                     help="quick: a short refinement; normal: the defaults; best: longer "
                          "(configs/: the [efforts] tables).  [default: normal]"),
        click.option("--iterations", "--iters", type=click.IntRange(min=0), help="Adam iterations."),
        click.option("--loss", type=click.Choice(LOSSES), help="Image loss."),
        click.option("--mode", type=click.Choice(MODES),
                     help="Anti-aliasing while optimising."),
        click.option("--samples", type=click.IntRange(1, 16), help="N: N x N samples per pixel."),
        click.option("--max-size", type=click.IntRange(min=0),
                     help="Optimise on the target downscaled to this longest side (0: full size)."),
        click.option("--background", help="auto (the target's corners), none, white or #rrggbb."),
        click.option("--lr", "learning_rates", multiple=True, metavar="KIND=RATE",
                     help="Learning rate of a parameter kind, e.g. --lr points=1 (repeatable)."),
        click.option("--seed", type=int, help="Random seed."),
        click.option("--threads", type=click.IntRange(min=0), help="Threads (0: all cores)."),
        click.option("--device", **DEVICE_OPTION),
        click.option("--precision", type=click.IntRange(0, MAX_DECIMALS),
                     help="Decimals of the coordinates written (default: what the canvas needs, "
                          "a hundredth of a pixel up to 1,024 px)."),
        click.option("-q", "--quiet", is_flag=True, help="No progress bar."),
    ]
    for option in reversed(options):
        f = option(f)
    return f


def colour_options(f):
    """--palette and --group-by: trace, refine, paint (vecfit/jobs/palette.py, vecfit/svg/layers.py)."""
    f = click.option("--group-by", "group_by", type=click.Choice(GROUP_BY),
                     help="colour: one <g> (an Inkscape layer) per colour, in stacking order.")(f)
    return click.option("--palette", metavar="COLOURS|FILE|auto:N",
                        help="Every paint one of these colours, exactly: '#e63946,#f1faee', a file "
                             "(one colour a line, or a GIMP .gpl), or auto:N (at most N, chosen by the fit).")(f)


def stacking_options(f):
    """--stacking and --gap-filler: trace, refine, paint (vecfit/initial/tracer/cutouts.py)."""
    f = click.option("--gap-filler", "gap_filler", is_flag=True, default=None,
                     help="With cut-outs: draw each shared edge first, as a thin stroke, against the "
                          "seams of renderers that anti-alias each piece on its own.")(f)
    return click.option("--stacking", type=click.Choice(list(STACKINGS)),
                         help="stacked: shapes over one another; cutouts: pieces that do not overlap "
                              "(for cutters and screen printing).  [default: stacked]")(f)


def _parse_learning_rates(items) -> dict:
    out = {}
    for item in items:
        kind, sep, value = item.partition("=")
        try:
            out[kind.strip()] = float(value)
        except ValueError:
            sep = ""
        if not sep:
            raise click.BadParameter(f"expected KIND=RATE, not {item!r}", param_hint="--lr")
    return out


def _resolve_config(command, preset, config_file, options, extra=None):
    """Defaults, preset, --config file, options; a bad setting is a usage error."""
    from vecfit.errors import VecfitError
    from vecfit.jobs.config import resolve

    overrides = {"optimize": {
        "iterations": options["iterations"], "loss": options["loss"], "mode": options["mode"],
        "samples": options["samples"], "max_size": options["max_size"],
        "background": options["background"], "seed": options["seed"],
        "threads": options["threads"], "device": options["device"],
        "lr": _parse_learning_rates(options["learning_rates"]), "palette": options.get("palette"),
    }, "output": {"precision": options["precision"], "group_by": options.get("group_by"),
                  "stacking": options.get("stacking"), "gap_filler": options.get("gap_filler")}, **(extra or {})}
    try:
        return resolve(command, preset=preset, config_file=config_file, overrides=overrides,
                       effort=options["effort"])
    except VecfitError as e:
        _echo_err(f"error: {e}")
        sys.exit(EXIT_USAGE)


class _ProgressBar:
    """A job's listener (vecfit.jobs.protocol.Progress): an Adam progress bar on stderr,
    with the loss, whose length the job gives; its status lines; silent when quiet. The
    bar appears with the first iteration, so an error in the inputs is not preceded by a
    bar (or, in a log, by the bar's label alone)."""

    def __init__(self, label: str, quiet: bool):
        self.label, self.quiet = label, quiet
        self.make = None
        self.bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.__exit__(*exc)

    def start(self, iterations: int) -> None:
        if self.quiet or iterations == 0 or self.bar is not None:
            return
        self.make = lambda: click.progressbar(
            length=iterations, label=self.label, file=sys.stderr, show_pos=True, show_eta=True,
            item_show_func=lambda p: None if p is None else f"loss {p.loss:.5g}")

    def status(self, message: str) -> None:
        if not self.quiet:
            _echo_err(message)

    def __call__(self, progress) -> None:
        if self.make is None:
            return
        if self.bar is None:
            self.bar = self.make()
            self.bar.__enter__()
        self.bar.update(1, current_item=progress)


# The progress bar's label of each job.
_LABELS = {"refine": "refine", "trace": "refine", "paint": "paint", "edit": "edit", "retarget": "retarget"}


def _run_job(name, inputs, config, outputs, quiet):
    """Runs the job ``name`` (vecfit.jobs.protocol) with a progress bar; user errors and
    Ctrl-C end it cleanly."""
    from vecfit.errors import VecfitError
    from vecfit.jobs.protocol import job_function

    try:
        with _ProgressBar(_LABELS[name], quiet) as bar:
            report = job_function(name)(inputs, config, outputs, progress=bar)
    except VecfitError as e:
        _echo_err(f"error: {e}")
        sys.exit(EXIT_FAILED)
    except KeyboardInterrupt:
        _echo_err("interrupted: nothing written")
        sys.exit(EXIT_INTERRUPTED)
    _summarise(report)
    if report["interrupted"]:
        _echo_err(f"interrupted after {report['iterations']} iterations: wrote the best result so far")
        sys.exit(EXIT_INTERRUPTED)


def _outputs(main, output, report, comparison, options, frames=None):
    """The job's Outputs (vecfit.jobs.protocol), in the format asked (--format, or -o's
    suffix); a format the name contradicts, or a place that cannot be written, is a usage
    error said before any work."""
    from vecfit.errors import VecfitError
    from vecfit.jobs.protocol import Outputs

    try:
        outputs = Outputs.beside(main, output, report, comparison, frames, format=options.get("output_format"))
    except VecfitError as e:
        _echo_err(f"error: {e}")
        sys.exit(EXIT_USAGE)
    for path in (outputs.svg, outputs.report, outputs.comparison):
        folder = path.parent
        while not folder.exists() and folder != folder.parent:
            folder = folder.parent
        if path.is_dir() or not folder.is_dir() or not _can_write_in(folder):
            _echo_err(f"error: {path}: cannot write there")
            sys.exit(EXIT_USAGE)
    return outputs


def _can_write_in(folder) -> bool:
    """Whether a file can be made in ``folder`` (tried: permissions alone do not say, for
    root or a read-only file system)."""
    import tempfile
    try:
        with tempfile.TemporaryFile(dir=folder):
            return True
    except OSError:
        return False


def _summarise(report) -> None:
    a, b = report["initial"], report["optimized"]
    _echo_err(f"PSNR {a['psnr']:.2f} -> {b['psnr']:.2f} dB, MSE {a['mse']:.5f} -> {b['mse']:.5f}, "
              f"SSIM {a['ssim']:.4f} -> {b['ssim']:.4f} "
              f"({report['iterations']} iterations, {report['seconds']['total']:.1f} s)")
    click.echo(f"{report.get('format', 'svg')}: {report['output']}")
    click.echo(f"report: {report['report']}")
    click.echo(f"comparison: {report['comparison']}")


@main.command()
@click.argument("target", type=FILE)
@click.argument("init_svg", type=FILE)
@optimize_options
@colour_options
@stacking_options
def refine(target, init_svg, output, report, comparison, config_file, quiet, **options):
    """Optimise INIT_SVG's control points, colours and stroke widths to match TARGET."""
    from vecfit.jobs.protocol import Inputs

    config = _resolve_config("refine", None, config_file, options)
    inputs = Inputs(image=target, svg=init_svg)
    _run_job("refine", inputs, config, _outputs(inputs.main, output, report, comparison, options), quiet)



@main.command()
@click.argument("target", type=FILE)
@click.option("--preset", help="A preset of configs/trace.toml: photo, poster or bw.")
@click.option("--paths", type=click.IntRange(min=1), help="Path budget: at most this many shapes.")
@click.option("--colors", type=click.IntRange(min=1), help="Colours of the k-means quantisation.")
@click.option("--min-area", type=click.FloatRange(min=0), help="Speckle removal: smallest region (pixels).")
@click.option("--tolerance", type=click.FloatRange(min=0, min_open=True),
              help="Largest curve-fitting error (pixels).")
@click.option("--style", type=click.Choice(STYLES),
              help="fills: filled outlines; strokes: line work as stroked centerlines; mixed: "
                   "fills for areas, strokes for line work.  [default: fills]")
@click.option("--refine/--no-refine", default=True, show_default=True,
              help="Refine the trace against the image (else write the trace as it is).")
@click.option("--remove-background", is_flag=True, default=None,
              help="Leave the border's flat colour (or --background's) out: the SVG is transparent there.")
@optimize_options
@colour_options
@stacking_options
def trace(target, preset, paths, colors, min_area, tolerance, style, refine, remove_background, output, report,
          comparison, config_file, quiet, **options):
    """Trace TARGET into an SVG (colour regions fitted with cubic curves), then refine it."""
    from vecfit.jobs.protocol import Inputs

    if not refine:
        options["iterations"] = 0  # the trace written as it is
    config = _resolve_config("trace", preset, config_file, options, extra={"trace": {
        "paths": paths, "colors": colors, "min_area": min_area, "tolerance": tolerance, "style": style,
        "remove_background": remove_background or None}})
    if config["optimize"]["iterations"] > 0:
        _import_torch_holding_ctrl_c()  # (a trace written as it is needs no torch)
    inputs = Inputs(image=target)
    _run_job("trace", inputs, config, _outputs(inputs.main, output, report, comparison, options), quiet)


@main.command()
@click.argument("target", type=FILE)
@click.option("--paths", type=click.IntRange(min=1), help="Number of strokes or shapes.")
@click.option("--kind", type=click.Choice(PAINT_KINDS),
              help="Open cubic strokes or closed filled shapes.")
@click.option("--preset", help="A preset of configs/paint.toml.")
@click.option("--frames", type=FOLDER,
              help="Save the optimisation as frame_NNNNN.png and optimization.gif in this folder.")
@optimize_options
@colour_options
@stacking_options
def paint(target, paths, kind, preset, frames, output, report, comparison, config_file, quiet,
          **options):
    """Paint TARGET with random strokes or shapes fitted by gradient descent."""
    from vecfit.jobs.protocol import Inputs

    config = _resolve_config("paint", preset, config_file, options,
                             extra={"paint": {"paths": paths, "kind": kind}})
    inputs = Inputs(image=target)
    _run_job("paint", inputs, config, _outputs(inputs.main, output, report, comparison, options, frames), quiet)


@main.command()
@click.argument("init_svg", type=FILE)
@click.argument("edited", type=FILE)
@click.option("--mask", type=FILE,
              help="PNG of EDITED's size, white where the edit is (default: where EDITED differs "
                   "from INIT_SVG's render).")
@optimize_options
def edit(init_svg, edited, mask, output, report, comparison, config_file, quiet, **options):
    """Bring an edit made on INIT_SVG's render (EDITED, a PNG) into the SVG: its own
    parameters are fitted to EDITED, changing as little as possible outside the edit.
    Writes NAME.vecfit.svg (elements, ids and groups kept), a report and a comparison
    picture (original | edited | result | difference)."""
    from vecfit.jobs.protocol import Inputs

    config = _resolve_config("edit", None, config_file, options)
    inputs = Inputs(image=edited, svg=init_svg, mask=mask)
    _run_job("edit", inputs, config, _outputs(inputs.main, output, report, comparison, options), quiet)

@main.command()
@click.argument("svg", type=FILE)
@click.option("--width", required=True, metavar="W|P%",
              help="New width: pixels (120) or a percentage of the SVG's (70%).")
@click.option("--height", metavar="H|P%", help="New height (default: unchanged).")
@optimize_options
def retarget(svg, width, height, output, report, comparison, config_file, quiet, **options):
    """Content-aware resizing of SVG (seam carving brought into the vector file): seams of
    least energy are carved out of its render in rounds, and its points are fitted to each
    round's carved image. Writes NAME.vecfit.svg at the new size (every element, id and
    group kept), a report and a comparison picture (input | plain scaling | retargeted).
    --iterations N sets the Adam iterations of the whole run, divided between the rounds
    and the final fit as configs/retarget.toml divides them."""
    from vecfit.jobs.protocol import Inputs

    # --iterations is the whole run's: the job divides it between its rounds
    total, options["iterations"] = options["iterations"], None
    config = _resolve_config("retarget", None, config_file, options,
                             extra={"retarget": {"width": width, "height": height, "iterations": total}})
    inputs = Inputs(svg=svg)
    _run_job("retarget", inputs, config, _outputs(inputs.main, output, report, comparison, options), quiet)


# ------------------------------------------------------------------------------ batch

@main.command()
@click.argument("in_dir", type=EXISTING_FOLDER)
@click.option("-o", "--out-dir", required=True, type=FOLDER,
              help="Folder for the outputs and the summary (not IN_DIR).")
@click.option("--mode", required=True, type=click.Choice(JOBS),
              help="The command run on each image (retarget: on each SVG).")
@click.option("--width", metavar="W|P%", help="retarget: the new width, pixels or a percentage (70%).")
@click.option("--height", metavar="H|P%", help="retarget: the new height (default: unchanged).")
@click.option("--config", "config_file", type=FILE,
              help="TOML file overriding the defaults in configs/.")
@click.option("--preset", help="A preset of the mode's file in configs/.")
@click.option("--effort", type=click.Choice(EFFORTS),
              help="Every image's effort (as the mode's --effort).  [default: normal]")
@click.option("--style", type=click.Choice(STYLES),
              help="trace: every image's style (as trace's --style).")
@click.option("--init-dir", type=EXISTING_FOLDER,
              help="refine, edit: the folder of the SVGs (default: IN_DIR).")
@click.option("-j", "--jobs", type=click.IntRange(min=0), default=1, show_default=True,
              help="Worker processes (0: one per core); 1 works in this process.")
@click.option("--threads", type=click.IntRange(min=1),
              help="Threads per worker (default: the cores divided between the workers; "
                   "1 per task with --scheduler).")
@click.option("--resume/--no-resume", default=True, show_default=True,
              help="Skip images finished with the same settings.")
@click.option("--scheduler", metavar="ADDRESS",
              help="Run the images on this Dask distributed scheduler (needs the "
                   "'distributed' package; paths must be the same on the workers).")
@click.option("--device", **DEVICE_OPTION)
@click.option("--format", "output_format", type=click.Choice(FORMATS), default="svg",
              show_default=True, help="Write each result as NAME.svg, NAME.pdf or NAME.dxf.")
@click.option("--remove-background", is_flag=True, help="trace: leave the border's flat colour out.")
@colour_options
@stacking_options
@click.option("-q", "--quiet", is_flag=True, help="No progress bar or per-image lines.")
def batch(in_dir, out_dir, mode, width, height, config_file, preset, effort, style, init_dir, jobs, threads,
          resume, scheduler, device, output_format, remove_background, palette, group_by, stacking, gap_filler,
          quiet):
    """Run refine, trace, paint or edit on every image in IN_DIR (*.png, *.jpg, *.jpeg,
    *.bmp, *.tif, *.tiff, *.webp; not recursive), or retarget on every SVG there (*.svg,
    *.svgz; --width and/or --height give the new size), writing NAME.svg, NAME.report.json and
    NAME.compare.png per image, and summary.csv, summary.json and index.html (with
    thumbs/) into OUT_DIR. For refine and edit, each image (for edit: the edited render)
    is paired with the SVG of the same name in IN_DIR (or --init-dir); an image without
    one is reported as unpaired. A failing
    image is recorded with its reason and the others go on.

    \b
    Exit codes:
      0    every image done, or skipped as finished
      1    some image failed or was unpaired (the others are done)
      2    bad usage: no IN_DIR, bad options or config, no Dask scheduler
      130  interrupted (Ctrl-C): finished images are kept, nothing half-written
    """
    reporter = None
    try:
        from vecfit.batch import BatchUsageError, run_batch
        from vecfit.batch.progress import Progress

        reporter = Progress(quiet=quiet)
        try:
            result = run_batch(in_dir, out_dir, mode, config_file=config_file, preset=preset,
                               effort=effort, jobs=jobs, threads=threads, resume=resume, init_dir=init_dir,
                               scheduler=scheduler, reporter=reporter, device=device,
                               width=width, height=height, format=output_format, palette=palette,
                               group_by=group_by, remove_background=remove_background, style=style,
                               stacking=stacking, gap_filler=gap_filler)
        except BatchUsageError as e:
            _echo_err(f"error: {e}")
            sys.exit(EXIT_USAGE)
    except KeyboardInterrupt:  # before the run started, or while the summary was written
        if reporter is not None:
            reporter.finish()
        _echo_err("interrupted")
        sys.exit(EXIT_INTERRUPTED)
    counts = ", ".join(f"{n} {status}" for status, n in result.counts.items() if n)
    if not result.rows:
        _echo_err(f"warning: no images in {in_dir}")
    else:
        n = len(result.rows)
        _echo_err(f"{n} image{'s' if n != 1 else ''}: {counts}")
    for path in result.summary.values():
        click.echo(f"summary: {path}")
    if result.interrupted:
        _echo_err("interrupted: finished images are kept; run again to resume")
    sys.exit(result.exit_code)


if __name__ == "__main__":
    main()
