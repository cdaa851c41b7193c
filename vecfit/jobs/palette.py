"""The user's colours: ``--palette`` (optimize.palette), read and applied.

A palette is either a list of colours every written paint must be, exactly
("#e63946,#f1faee", a file of one colour a line, or a GIMP .gpl palette), or ``auto:N``:
at most N colours, chosen by the fit. Colours are compared in CIELAB (the tracer's
quantisation space), so "nearest" means nearest as seen.

How a fit ends on a palette (vecfit.jobs.fit): a scene that starts on the palette (a
trace on it; for auto:N at most N distinct paints) keeps its colours throughout: a
list's frozen, auto:N's shared (each of the N fitted as one colour: its paints averaged,
weighted by coverage, after every step). Any other scene (refine's, paint's) is fitted
with free colours first (a paint may drift towards a better palette colour than the one
it started near), then every paint is snapped to its palette colour (a list: the
nearest; auto:N: N colours by k-means of the paints in CIELAB, each weighted by the
pixels it covers), and a short final fit moves geometry only (auto:N's colours shared),
so the outlines settle on the colours that are written.

Only a paint's colour is the palette's: its opacity follows ``optimize.alpha`` as
without a palette (vecfit/fitting/opacity.py: opaque on flat art, free on photographs
and on targets with translucent areas), so a photograph on a palette may blend its N
colours where shapes overlap (with 8 opaque colours astronaut scored 23.4 dB at --effort
quick, below the 24.1 dB of today's 8-colour trace with its 474 region colours).
``optimize.alpha = "fixed"`` keeps every paint opaque, for cutters and screen printing.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vecfit.errors import VecfitError

AUTO = re.compile(r"^\s*auto\s*:\s*(\S*)\s*$", re.IGNORECASE)


@dataclass
class Palette:
    """A parsed ``--palette``: ``colors`` (uint8 [n, 3], in the order given, duplicates
    dropped) or ``auto`` (N: at most N colours chosen by the fit); ``source``: the value
    as given, for the report."""
    source: str
    colors: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.uint8))
    auto: int | None = None

    @property
    def rgb(self) -> np.ndarray:
        """The colours as float64 [n, 3] in [0, 1] (k / 255: the written #rrggbb exactly)."""
        return self.colors.astype(np.float64) / 255.0

    def hex(self) -> list[str]:
        return ["#{:02x}{:02x}{:02x}".format(*map(int, c)) for c in self.colors]


def parse_palette(value: str | None) -> Palette | None:
    """``optimize.palette`` as given ("" or None: no palette). Raises VecfitError with one
    line naming the value or file for an unreadable file, an empty palette, a colour that
    does not parse, or auto:N with N below 1."""
    if value is None or not str(value).strip():
        return None
    text = str(value).strip()
    m = AUTO.match(text)
    if m:
        try:
            n = int(m.group(1))
        except ValueError:
            n = None
        if n is None or n < 1:
            raise VecfitError(f"palette {text!r}: auto:N needs a whole number N of at least 1")
        return Palette(source=text, auto=n)
    if _looks_like_file(text):
        return Palette(source=text, colors=_read_file(Path(text)))
    colours = [_colour(item, f"palette {text!r}") for item in text.split(",") if item.strip()]
    return Palette(source=text, colors=_unique(colours, f"palette {text!r}"))


def _looks_like_file(text: str) -> bool:
    """A value is a file's name unless it reads as colours: it has a comma, starts with
    '#', or is one CSS colour name."""
    if "," in text or text.startswith("#"):
        return Path(text).is_file()
    from vecfit.svg.color import parse_color
    return parse_color(text) is None or Path(text).is_file()


def _colour(item: str, where: str) -> tuple[int, int, int]:
    from vecfit.svg.color import parse_color

    s = item.strip()
    rgba = parse_color(s if s.startswith("#") or not re.fullmatch(r"[0-9a-fA-F]{6}", s) else "#" + s)
    if rgba is None or s.lower() in ("none", "transparent", "currentcolor", "inherit"):
        raise VecfitError(f"{where}: {s!r} is not a colour (#rrggbb, #rgb, rgb(...) or a CSS name)")
    if rgba[3] < 1:
        raise VecfitError(f"{where}: {s!r} is translucent; palette colours are opaque")
    return tuple(int(round(min(max(c, 0.0), 1.0) * 255)) for c in rgba[:3])


def _unique(colours: list, where: str) -> np.ndarray:
    if not colours:
        raise VecfitError(f"{where}: the palette is empty")
    seen = list(dict.fromkeys(colours))
    return np.array(seen, np.uint8).reshape(-1, 3)


def _read_file(path: Path) -> np.ndarray:
    """One colour a line (#rrggbb, rrggbb, a CSS colour, or "R G B"; anything after it a
    name; blank lines and lines starting with ';' or '//' skipped), or a GIMP palette
    ("GIMP Palette" header; "R G B name" lines; Name:, Columns: and '#' comments skipped)."""
    where = f"palette file {str(path)!r}"
    try:
        lines = path.read_text(encoding="utf-8-sig").splitlines()
    except (OSError, UnicodeDecodeError) as e:
        raise VecfitError(f"{where}: cannot be read ({getattr(e, 'strerror', None) or e})") from None
    gimp = bool(lines) and lines[0].strip() == "GIMP Palette"
    colours = []
    for number, raw in enumerate(lines[1:] if gimp else lines, start=2 if gimp else 1):
        line = raw.strip()
        if not line or line.startswith((";", "//")):
            continue
        if gimp and (line.startswith("#") or re.match(r"^(Name|Columns)\s*:", line)):
            continue
        parts = line.split()
        if len(parts) >= 3 and all(re.fullmatch(r"\d{1,3}", p) for p in parts[:3]):
            rgb = tuple(int(p) for p in parts[:3])
            if max(rgb) > 255:
                raise VecfitError(f"{where}, line {number}: {line!r} has a value above 255")
            colours.append(rgb)
        else:
            colours.append(_colour(parts[0], f"{where}, line {number}"))
    return _unique(colours, where)


# ------------------------------------------------------------------------ colours

def to_lab(rgb) -> np.ndarray:
    from vecfit.initial.tracer.quantize import to_lab as lab
    return lab(np.asarray(rgb, np.float64))


def nearest(rgb: np.ndarray, palette_rgb: np.ndarray) -> np.ndarray:
    """Index of the palette colour nearest (CIELAB) to each of ``rgb`` [n, 3] in [0, 1]."""
    from vecfit.initial.tracer.quantize import nearest_centre
    if len(rgb) == 0:
        return np.zeros(0, np.int64)
    return nearest_centre(to_lab(np.reshape(rgb, (-1, 3))), to_lab(palette_rgb)).astype(np.int64)


def nearest_colour(rgba, palette_rgb: np.ndarray):
    """An RGBA tuple's colour replaced by its nearest palette colour (None stays None, as
    does any colour when the palette is empty)."""
    if rgba is None or not len(palette_rgb):
        return rgba
    rgb = np.asarray(palette_rgb, np.float64).reshape(-1, 3)[nearest(np.array([rgba[:3]]), palette_rgb)[0]]
    return (*map(float, rgb), *rgba[3:])


def from_lab(lab: np.ndarray) -> np.ndarray:
    """CIELAB [n, 3] back to sRGB [n, 3] in [0, 1] (clipped): the inverse of to_lab."""
    from vecfit.initial.tracer.quantize import D65_WHITE, SRGB_TO_XYZ
    lab = np.asarray(lab, np.float64)
    fy = (lab[:, 0] + 16) / 116
    f = np.stack([fy + lab[:, 1] / 500, fy, fy - lab[:, 2] / 200], 1)
    xyz = np.where(f > 0.206893, f ** 3, (f - 16 / 116) / 7.787)
    xyz[:, 1] = np.where(lab[:, 0] > 903.3 * 0.008856, xyz[:, 1], lab[:, 0] / 903.3)
    linear = (xyz * D65_WHITE) @ np.linalg.inv(SRGB_TO_XYZ).T
    linear = np.clip(linear, 0, 1)
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055).clip(0, 1)


def auto_palette(rgb: np.ndarray, weight: np.ndarray, n: int, seed: int = 0) -> np.ndarray:
    """At most ``n`` colours (uint8 [k, 3]) for the paints ``rgb`` [m, 3] (in [0, 1]), each
    weighted by ``weight`` [m] (the pixels it covers): weighted k-means in CIELAB
    (k-means++ seeds, Lloyd's steps), the centres rounded to 8 bits."""
    rgb = np.asarray(rgb, np.float64).reshape(-1, 3)
    levels = np.rint(rgb * 255).astype(np.int64)
    key = levels @ np.array([1 << 16, 1 << 8, 1])
    keys, which = np.unique(key, return_inverse=True)
    w = np.bincount(which, np.maximum(np.asarray(weight, np.float64), 1e-6), len(keys))
    distinct = np.stack([keys >> 16, (keys >> 8) & 255, keys & 255], 1)
    if len(distinct) <= n:
        return distinct.astype(np.uint8)
    lab = to_lab(distinct / 255.0).astype(np.float64)
    rng = np.random.default_rng(seed)
    centres = [lab[rng.choice(len(lab), p=w / w.sum())]]
    for _ in range(1, n):  # k-means++ seeding, weighted
        d = ((lab[:, None] - np.array(centres)[None]) ** 2).sum(2).min(1) * w
        if d.sum() <= 0:
            break
        centres.append(lab[rng.choice(len(lab), p=d / d.sum())])
    centres = np.array(centres)
    for _ in range(50):
        assign = ((lab[:, None] - centres[None]) ** 2).sum(2).argmin(1)
        moved = np.array([np.average(lab[assign == j], axis=0, weights=w[assign == j])
                          if (assign == j).any() else centres[j] for j in range(len(centres))])
        if np.abs(moved - centres).max() < 1e-3:
            centres = moved
            break
        centres = moved
    out = np.rint(from_lab(centres) * 255).astype(np.uint8)
    return np.unique(out, axis=0)


# -------------------------------------------------------------------- the Scene

def paint_colors(scene) -> list:
    """The Scene's colour tensors (Solid colours [4], gradient stops [K, 4])."""
    return scene.parameters().get("colors", [])


def coverage(scene, width: int, height: int) -> dict[int, float]:
    """Pixels each colour tensor's shapes cover (id -> its bounding boxes' area, clipped to
    the canvas): the weight of a paint in auto:N's k-means."""
    from vecfit.scene import Circle, Ellipse, Path as ScenePath, Rect
    from vecfit.scene.arrays import to_numpy

    out: dict[int, float] = {}
    for shape in scene.shapes:
        g = shape.geometry
        if isinstance(g, ScenePath):
            p = np.asarray(to_numpy(g.points), np.float64).reshape(-1, 2)
        elif isinstance(g, Rect):
            p = np.stack([to_numpy(g.p_min), to_numpy(g.p_max)]).astype(np.float64)
        elif isinstance(g, Circle):
            c, r = np.asarray(to_numpy(g.center), np.float64), float(to_numpy(g.radius))
            p = np.stack([c - r, c + r])
        elif isinstance(g, Ellipse):
            c, r = np.asarray(to_numpy(g.center), np.float64), np.asarray(to_numpy(g.radii), np.float64)
            p = np.stack([c - r, c + r])
        else:
            continue
        m = np.asarray(to_numpy(shape.transform), np.float64)
        p = p @ m[:2, :2].T + m[:2, 2] if len(p) else p
        if not len(p):
            continue
        x0, y0 = np.clip(p.min(0), 0, [width, height])
        x1, y1 = np.clip(p.max(0), 0, [width, height])
        area = max(x1 - x0, 0.0) * max(y1 - y0, 0.0)
        for paint in (shape.fill, shape.stroke):
            c = getattr(paint, "color", getattr(paint, "colors", None))
            if c is not None:
                out[id(c)] = out.get(id(c), 0.0) + area
    return out


def rows(color) -> "torch.Tensor":
    return color.view(-1, 4)


def snap(scene, palette_rgb: np.ndarray) -> list[tuple[object, np.ndarray]]:
    """Every paint of ``scene`` (solid colours and gradient stops) set to its nearest
    palette colour (CIELAB), in place; returns (tensor, palette index of each row)."""
    import torch
    from vecfit.scene.arrays import to_numpy

    out = []
    with torch.no_grad():
        for c in paint_colors(scene):
            r = rows(c)
            idx = nearest(np.asarray(to_numpy(r), np.float64)[:, :3], palette_rgb)
            r[:, :3] = torch.as_tensor(palette_rgb[idx], dtype=r.dtype)
            out.append((c, idx))
    return out


class SharedColors:
    """A loop hook (vecfit.fitting.loop.Step) for auto:N's final fit: the paints assigned to
    one palette colour stay one colour, their weighted mean after every step (the step of
    a shared parameter: its paints' gradients summed, the projection of Adam's step on the
    tied colours)."""

    def __init__(self, assignment: list[tuple[object, np.ndarray]], weights: dict[int, float], count: int):
        self.assignment, self.count = assignment, count
        self.weights = [max(weights.get(id(c), 0.0), 1e-6) for c, _ in assignment]

    def means(self) -> np.ndarray:
        from vecfit.scene.arrays import to_numpy
        total = np.zeros((self.count, 3))
        mass = np.zeros(self.count)
        for (c, idx), w in zip(self.assignment, self.weights):
            np.add.at(total, idx, w * np.asarray(to_numpy(rows(c)), np.float64)[:, :3])
            np.add.at(mass, idx, w)
        return total / np.maximum(mass, 1e-12)[:, None]

    def apply(self, means: np.ndarray) -> None:
        import torch
        with torch.no_grad():
            for c, idx in self.assignment:
                r = rows(c)
                r[:, :3] = torch.as_tensor(means[idx], dtype=r.dtype)

    def __call__(self, step) -> None:
        self.apply(np.clip(self.means(), 0, 1))

    def finish(self) -> np.ndarray:
        """The shared colours rounded to 8 bits and written into every paint; uint8 [count, 3]."""
        levels = np.rint(np.clip(self.means(), 0, 1) * 255)
        self.apply(levels / 255.0)
        return levels.astype(np.uint8)


# ------------------------------------------------------------------ the fit

# The final geometry-only fit: this share of the iterations (at least POLISH_MIN, at
# most half), its point rate scaled by POLISH_RATE (outlines are in place; they settle
# on the snapped colours' edges).
POLISH_SHARE, POLISH_MIN, POLISH_RATE = 0.15, 10, 0.5


def polish_iterations(iterations: int) -> int:
    if iterations <= 1:
        return 0
    return min(max(POLISH_MIN, int(round(POLISH_SHARE * iterations))), iterations // 2)


def optimize_on_palette(scene, goal, settings, palette: Palette, *, progress=None, hooks=(), keep_alpha=()):
    """``scene`` fitted to ``goal`` (vecfit.fitting.loop) ending with every paint on
    ``palette`` (see the module's docstring); returns (the loop's Result, the colours
    used: uint8 [k, 3]).

    auto:N: the paints are clustered into N at once and fitted as N shared colours
    throughout. A list: a scene already on it (a trace) keeps its colours frozen
    throughout (free colours snapped back after the fit lost a flag's trace 1 dB: the
    outlines had settled on the drifted colours); any other scene is fitted with free
    colours first, then snapped, then polished (geometry only)."""
    import dataclasses
    from vecfit.fitting.loop import optimize
    from vecfit.fitting.result import Result

    h, w = goal.image.shape[:2]
    weights = coverage(scene, w, h)
    rgb, wt = _paint_rows(scene, weights)
    if palette.auto is not None:  # N shared colours, fitted with the geometry from the start
        started = True
    else:
        started = bool(np.isin(_keys(np.rint(rgb * 255)), _keys(palette.colors)).all())
    polish = settings.iterations if started else polish_iterations(settings.iterations)
    results = []
    if polish < settings.iterations:
        first = dataclasses.replace(settings, iterations=settings.iterations - polish)
        results.append(optimize(scene, goal, first, progress=progress, hooks=hooks, keep_alpha=keep_alpha))
        rgb, wt = _paint_rows(scene, weights)
    if palette.auto is not None:
        chosen = auto_palette(rgb, wt, palette.auto, settings.seed) if len(rgb) else np.zeros((0, 3), np.uint8)
        tied = SharedColors(snap(scene, chosen / 255.0), weights, len(chosen))
        polish_hooks, colour_rate = (tied,), settings.lr.get("colors", 0.0)
    else:
        chosen, tied = palette.colors, None
        snap(scene, palette.rgb)
        polish_hooks, colour_rate = (), 0.0
    if started:
        polish_hooks = (*hooks, *polish_hooks)
    if polish > 0 and not any(r.interrupted for r in results):
        last = dataclasses.replace(settings, iterations=polish, lr={**settings.lr, "colors": colour_rate})
        if not started:  # a short fit at the end: outlines are in place, colours snapped
            lr = dict(last.lr)
            if "points" in lr:
                lr["points"] = float(lr["points"]) * POLISH_RATE
            last = dataclasses.replace(last, lr=lr, coarse=0.0, lr_warmup=min(settings.lr_warmup, 3))
        from vecfit.errors import VecfitError
        try:
            results.append(optimize(scene, goal, last, progress=progress, hooks=polish_hooks,
                                    keep_alpha=keep_alpha))
        except VecfitError as e:  # colours were all it had to fit (no geometry rates): keep the snap
            if not str(e).startswith("nothing to optimise"):
                raise
    if tied is not None:
        chosen = tied.finish()
    else:
        snap(scene, palette.rgb)  # (frozen already; this makes it certain)
    return _joined(results or [Result()]), np.unique(np.asarray(chosen, np.uint8).reshape(-1, 3), axis=0)


def _keys(levels) -> np.ndarray:
    levels = np.asarray(levels, np.int64).reshape(-1, 3)
    return levels @ np.array([1 << 16, 1 << 8, 1])


def _paint_rows(scene, weights: dict) -> tuple[np.ndarray, np.ndarray]:
    """Every paint row's RGB [m, 3] and its weight [m] (its shapes' coverage)."""
    from vecfit.scene.arrays import to_numpy
    colours = paint_colors(scene)
    if not colours:
        return np.zeros((0, 3)), np.zeros(0)
    rgb = np.concatenate([np.asarray(to_numpy(rows(c)), np.float64)[:, :3] for c in colours])
    wt = np.concatenate([np.full(rows(c).shape[0], weights.get(id(c), 0.0)) for c in colours])
    return rgb, wt


def _joined(results):
    from vecfit.fitting.result import Result
    first, last = results[0], results[-1]
    return Result(losses=[v for r in results for v in r.losses], best_loss=last.best_loss,
                  iterations=sum(r.iterations for r in results), seconds=sum(r.seconds for r in results),
                  interrupted=any(r.interrupted for r in results),
                  skipped_steps=sum(r.skipped_steps for r in results),
                  parameters=first.parameters or last.parameters,
                  iteration_seconds=[t for r in results for t in r.iteration_seconds],
                  coarse_iterations=first.coarse_iterations, outline_density=first.outline_density,
                  point_rate=first.point_rate)


# ------------------------------------------------------------------- the trace

def traced_on_palette(image: np.ndarray, settings, colours: np.ndarray):
    """The trace (vecfit.initial.tracer) painted with ``colours`` exactly: of its two ways
    (palette_by "pixels" and "regions"), the one whose render is closer to ``image`` (MSE
    over its own corner colour for opaque images, premultiplied RGBA else)."""
    from vecfit.initial.tracer import trace_image
    from vecfit.renderer.forward import render_numpy
    from vecfit.scene.arrays import numpy_arrays
    from vecfit.svg.read import scene_of

    h, w = image.shape[:2]
    best, best_error = None, np.inf
    for way in ("pixels", "regions"):
        traced = trace_image(image, settings, palette=colours, palette_by=way)
        with numpy_arrays():
            drawn = render_numpy(scene_of(traced.document), w, h, samples=2)
        a, b = np.asarray(drawn, np.float64), np.asarray(image, np.float64)
        error = float(((a[..., :3] * a[..., 3:] - b[..., :3] * b[..., 3:]) ** 2).mean()
                      + ((a[..., 3] - b[..., 3]) ** 2).mean())
        if error < best_error:
            best, best_error = traced, error
    return best


# ------------------------------------------------------------------- the report

def written_colours(svg: bytes) -> list[str]:
    """The distinct #rrggbb of the fills, strokes and gradient stops an SVG paints with
    (its background rect's included), sorted."""
    import warnings
    from vecfit.scene.arrays import numpy_arrays, to_numpy
    from vecfit.svg.document import SvgDocument
    from vecfit.svg.numbers import hex_color
    from vecfit.svg.read import scene_of

    document = SvgDocument.parse(svg, "<svg>")
    with numpy_arrays(), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = scene_of(document, for_writing=False)
    out = set()
    for shape in scene.shapes:
        for paint in (shape.fill, shape.stroke):
            c = getattr(paint, "color", getattr(paint, "colors", None))
            if c is not None:
                out.update(hex_color(r) for r in np.asarray(to_numpy(c)).reshape(-1, 4))
    return sorted(out)


def colour_entry(svg: bytes, palette: Palette | None, layers: dict | None) -> dict:
    """The report's "colours" entry: the palette asked for, the colours written, and the
    layers of --group-by colour."""
    used = written_colours(svg)
    entry = {"palette": None if palette is None else palette.source,
             "palette_colours": None if palette is None or palette.auto is not None else palette.hex(),
             "distinct": len(used), "used": used}
    if layers is not None:
        entry["layers"] = layers
    return entry
