"""The vecfit command line. Parses options, reports progress and errors; the work is
done by the vecfit package. Exit codes: 0 ok, 1 a runtime failure (some inputs could
not be processed), 2 bad usage."""
from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import click

EXIT_FAILURE = 1


def _echo_err(message: str) -> None:
    click.echo(message, err=True)


def _show_warning(message, category, filename, lineno, file=None, line=None):
    _echo_err(f"warning: {message}")


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="vecfit")
def main():
    """vecfit: turn raster images into vector graphics and refine vector graphics
    against images, with a differentiable rasterizer."""
    warnings.showwarning = _show_warning


@main.command()
@click.argument("inputs", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Output PNG (one input).")
@click.option("--out-dir", type=click.Path(file_okay=False), help="Folder for outputs, NAME.svg -> NAME.png.")
@click.option("--width", type=click.IntRange(min=1), help="Width in pixels (default: the SVG's).")
@click.option("--height", type=click.IntRange(min=1), help="Height in pixels (default: the SVG's).")
@click.option("--samples", type=click.IntRange(1, 64), default=2, show_default=True,
              help="N: N x N samples per pixel.")
@click.option("--mode", type=click.Choice(["mc", "analytic"]), default="mc", show_default=True,
              help="Anti-aliasing: Monte Carlo samples or the analytical prefilter.")
@click.option("--filter", "filter_", type=click.Choice(["box", "tent", "gaussian"]), default="box",
              show_default=True, help="Pixel filter.")
@click.option("--filter-radius", type=click.FloatRange(min=0.5), default=0.5, show_default=True,
              help="Pixel filter radius in pixels (tent, gaussian).")
@click.option("--background", default="none", show_default=True,
              help="none, white, black or #rrggbb[aa].")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed of the samples.")
@click.option("--threads", type=click.IntRange(min=0), default=0, help="Threads (0: all cores).")
def render(inputs, output, out_dir, width, height, samples, mode, filter_, filter_radius,
           background, seed, threads):
    """Render SVG files to PNG (8-bit RGBA)."""
    import vecfit
    from vecfit.colors import parse_background
    from vecfit.errors import VecfitError
    from vecfit.imageio import save_png

    if (output is None) == (out_dir is None):
        raise click.UsageError("give either -o OUT.png (one input) or --out-dir DIR")
    if output is not None and len(inputs) > 1:
        raise click.UsageError("-o takes one input; use --out-dir for several")
    try:
        bg = parse_background(background)
    except VecfitError as e:
        raise click.BadParameter(str(e), param_hint="--background")
    failed = 0
    for i, src in enumerate(inputs):
        dst = Path(output) if output else Path(out_dir) / (Path(src).stem + ".png")
        start = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("always")
                scene = vecfit.load_svg(src)
            image = vecfit.render(scene, width, height, samples=samples, mode=mode, filter=filter_,
                                  filter_radius=filter_radius, seed=seed, background=bg,
                                  threads=threads)
            save_png(image, dst)
        except VecfitError as e:
            failed += 1
            _echo_err(f"error: {e}")
            continue
        h, w = image.shape[:2]
        _echo_err(f"[{i + 1}/{len(inputs)}] {src} -> {dst} ({w}x{h}, {time.perf_counter() - start:.2f} s)")
    if failed:
        _echo_err(f"{failed} of {len(inputs)} inputs failed")
        sys.exit(EXIT_FAILURE)


@main.command()
@click.argument("svg", type=click.Path(dir_okay=False))
def info(svg):
    """List the shapes, segments and paints of an SVG, and what was skipped."""
    import vecfit
    from vecfit.describe import describe
    from vecfit.errors import VecfitError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = vecfit.load_svg(svg)
    except VecfitError as e:
        _echo_err(f"error: {e}")
        sys.exit(EXIT_FAILURE)
    click.echo(describe(scene))


if __name__ == "__main__":
    main()
