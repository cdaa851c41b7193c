"""SVG filter steps on a layer, in torch (differentiable; a blur is linear, so its
gradient is exact).

A layer is premultiplied sRGB RGBA [h, w, 4] over a frame of pixels that is the filter's
region. Steps that say so (color-interpolation-filters: linearRGB, the default) work on
linear-light colour and hand back sRGB; results are kept in sRGB, so a step's inputs are
converted on the way in, as resvg does. Numbers follow resvg where SVG leaves room:
offsets move by whole pixels (truncated), deviations under 0.05 px do not blur, and the
regions are whole pixels.
"""
from __future__ import annotations

import math
from typing import Optional

import torch
import torch.nn.functional as F

# Past this kernel radius a blur is done with FFTs (a direct convolution would take
# seconds on a wide deviation).
FFT_RADIUS = 48


def region_rect(filt, bounds) -> Optional[tuple[float, float, float, float]]:
    """The filter region in the element's user space, x, y, width, height; None where it
    is empty (bounding-box units on an element without an area: SVG then draws nothing)."""
    x, y, w, h = filt.region
    if filt.units == "objectBoundingBox":
        box = _box(bounds)
        if box is None:
            return None
        bx, by, bw, bh = box
        x, y, w, h = bx + x * bw, by + y * bh, w * bw, h * bh
    if not (w > 0 and h > 0) or not all(math.isfinite(v) for v in (x, y, w, h)):
        return None
    return x, y, w, h


def _box(bounds):
    if bounds is None:
        return None
    (x0, y0), (x1, y1) = bounds
    if not (x1 - x0 > 0 and y1 - y0 > 0):
        return None
    return x0, y0, x1 - x0, y1 - y0


def apply(filt, source: torch.Tensor, frame, pixels: torch.Tensor, bounds) -> torch.Tensor:
    """``source`` (premultiplied sRGB over ``frame``, the filter region in pixels)
    through ``filt``'s steps. ``pixels`` maps the element's user space to frame pixels."""
    m = pixels.detach().double()
    scale = (math.hypot(float(m[0, 0]), float(m[1, 0])), math.hypot(float(m[0, 1]), float(m[1, 1])))
    units = (1.0, 1.0)
    box = _box(bounds)
    if filt.primitive_units == "objectBoundingBox":
        units = (box[2], box[3]) if box is not None else (0.0, 0.0)
    h, w = source.shape[:2]
    results: dict[str, torch.Tensor] = {}
    previous = source
    for step in filt.steps:
        run = _Step(step, source, previous, results, scale, units)
        out = run.result()
        out = out * _subregion_mask(step, filt, frame, m, box, h, w, units)
        previous = out
        if step.result:
            results[step.result] = out
    return previous


class _Step:
    def __init__(self, step, source, previous, results, scale, units):
        self.step, self.source, self.previous, self.results = step, source, previous, results
        self.scale, self.units = scale, units
        self.linear = step.linear_rgb

    def input(self, name: str) -> torch.Tensor:
        """An input in this step's colour space."""
        if name == "SourceGraphic":
            image = self.source
        elif name == "SourceAlpha":
            image = torch.cat([torch.zeros_like(self.source[..., :3]), self.source[..., 3:]], dim=-1)
        elif name in self.results:
            image = self.results[name]
        else:
            image = self.previous
        return to_linear(image) if self.linear else image

    def done(self, image: torch.Tensor) -> torch.Tensor:
        return to_srgb(image) if self.linear else image

    def px(self, x: float, y: float) -> tuple[float, float]:
        """Lengths in primitive units -> pixels along x and y."""
        return x * self.units[0] * self.scale[0], y * self.units[1] * self.scale[1]

    def result(self) -> torch.Tensor:
        p, kind = self.step.params, self.step.kind
        ins = self.step.inputs
        if kind == "GaussianBlur":
            return self.done(blur(self.input(ins[0]), *self.px(*p["std"])))
        if kind == "Offset":
            return self.done(shift(self.input(ins[0]), *self.px(p["dx"], p["dy"])))
        if kind == "Flood":
            return flood(self.source, p["color"])
        if kind == "ColorMatrix":
            return self.done(color_matrix(self.input(ins[0]), p["type"], p["values"]))
        if kind == "Composite":
            return self.done(composite(self.input(ins[0]), self.input(ins[1]), p["operator"], p.get("k")))
        if kind == "Merge":
            out = torch.zeros_like(self.source)
            for name in ins:
                out = _over(self.input(name), out)
            return self.done(out)
        if kind == "Blend":
            return self.done(blend(self.input(ins[0]), self.input(ins[1]), p["mode"]))
        if kind == "DropShadow":
            return self.done(self.drop_shadow(self.input(ins[0]), p))
        raise ValueError(f"filter step {kind} is not run")

    def drop_shadow(self, image: torch.Tensor, p) -> torch.Tensor:
        alpha = blur(image, *self.px(*p["std"]))[..., 3:]
        color = torch.as_tensor(p["color"], dtype=image.dtype)
        shadow = torch.cat([color[:3] * color[3], color[3:]]) * alpha
        if self.linear:  # the flood colour is sRGB: its layer goes through linear like the input
            shadow = to_linear(shadow)
        return _over(image, shift(shadow, *self.px(p["dx"], p["dy"])))


def _subregion_mask(step, filt, frame, m, box, h, w, units) -> torch.Tensor:
    """1 inside the step's subregion (whole pixels of the frame), 0 outside."""
    x, y, sw, sh = step.region
    if all(v is None for v in step.region):
        return torch.ones((h, w, 1))
    if filt.primitive_units == "objectBoundingBox" and box is not None:
        bx, by, bw, bh = box
        x = None if x is None else bx + x * bw
        y = None if y is None else by + y * bh
        sw = None if sw is None else sw * bw
        sh = None if sh is None else sh * bh
    # What is not given is the frame's (the filter region's): in pixels directly.
    inv = torch.linalg.inv(m)
    fx0, fy0 = (inv @ torch.tensor([0.0, 0.0, 1.0], dtype=torch.float64))[:2].tolist()
    fx1, fy1 = (inv @ torch.tensor([float(w), float(h), 1.0], dtype=torch.float64))[:2].tolist()
    x = min(fx0, fx1) if x is None else x
    y = min(fy0, fy1) if y is None else y
    sw = abs(fx1 - fx0) if sw is None else sw
    sh = abs(fy1 - fy0) if sh is None else sh
    corners = torch.tensor([[x, y, 1.0], [x + sw, y, 1.0], [x, y + sh, 1.0], [x + sw, y + sh, 1.0]],
                           dtype=torch.float64) @ m.T
    x0, y0 = math.floor(float(corners[:, 0].min())), math.floor(float(corners[:, 1].min()))
    x1, y1 = math.ceil(float(corners[:, 0].max())), math.ceil(float(corners[:, 1].max()))
    mask = torch.zeros((h, w, 1))
    mask[max(y0, 0):max(min(y1, h), 0), max(x0, 0):max(min(x1, w), 0)] = 1.0
    return mask


# ------------------------------------------------------------------ colour spaces

def to_linear(image: torch.Tensor) -> torch.Tensor:
    """Premultiplied sRGB -> premultiplied linear-light RGB."""
    return _transfer(image, lambda c: torch.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055).clamp_min(1e-12) ** 2.4))


def to_srgb(image: torch.Tensor) -> torch.Tensor:
    """Premultiplied linear-light RGB -> premultiplied sRGB."""
    return _transfer(image, lambda c: torch.where(c <= 0.0031308, c * 12.92,
                                                  1.055 * c.clamp_min(1e-12) ** (1 / 2.4) - 0.055))


def _transfer(image, curve):
    alpha = image[..., 3:]
    safe = alpha.clamp_min(1e-6)
    color = (image[..., :3] / safe).clamp(0, 1)
    out = torch.where(alpha > 1e-6, curve(color) * alpha, torch.zeros_like(color))
    return torch.cat([out, alpha], dim=-1)


# ------------------------------------------------------------------------ steps

def blur(image: torch.Tensor, sigma_x: float, sigma_y: float) -> torch.Tensor:
    """A Gaussian blur with deviations in pixels along x and y (under 0.05: none)."""
    sigma_x = sigma_x if sigma_x >= 0.05 else 0.0
    sigma_y = sigma_y if sigma_y >= 0.05 else 0.0
    if sigma_x > 0:
        image = _blur_axis(image, sigma_x, axis=1)
    if sigma_y > 0:
        image = _blur_axis(image, sigma_y, axis=0)
    return image


def _blur_axis(image: torch.Tensor, sigma: float, axis: int) -> torch.Tensor:
    length = image.shape[axis]
    radius = int(math.ceil(3 * sigma))
    t = torch.arange(-min(radius, length), min(radius, length) + 1, dtype=torch.float64)
    kernel = torch.exp(-0.5 * (t / sigma) ** 2)
    # Normalised over its 3-sigma support; a deviation wider than the layer spreads it
    # over more than the layer (kept as the density: it fades, as in resvg).
    kernel = kernel / (kernel.sum() if radius <= length else sigma * math.sqrt(2 * math.pi))
    kernel = kernel.to(image.dtype)
    radius = min(radius, length)
    lines = image.movedim(axis, -1).movedim(-2, 0)  # [4, other, length]
    flat = lines.reshape(-1, 1, length)
    if radius <= FFT_RADIUS:
        out = F.conv1d(F.pad(flat, (radius, radius)), kernel.view(1, 1, -1))
    else:
        n = length + 2 * radius
        size = 1 << (n - 1).bit_length()
        spectrum = torch.fft.rfft(flat, n=size) * torch.fft.rfft(kernel, n=size)
        out = torch.fft.irfft(spectrum, n=size)[..., radius:radius + length]
    return out.reshape(lines.shape).movedim(0, -2).movedim(-1, axis)


def shift(image: torch.Tensor, dx: float, dy: float) -> torch.Tensor:
    """Moved by whole pixels (truncated, as resvg), transparent where it uncovers."""
    dx, dy = int(dx), int(dy)
    h, w = image.shape[:2]
    if dx == 0 and dy == 0:
        return image
    if abs(dx) >= w or abs(dy) >= h:
        return torch.zeros_like(image)
    piece = image[max(-dy, 0):h - max(dy, 0), max(-dx, 0):w - max(dx, 0)]
    return F.pad(piece.permute(2, 0, 1), (max(dx, 0), max(-dx, 0), max(dy, 0), max(-dy, 0))).permute(1, 2, 0)


def flood(like: torch.Tensor, color) -> torch.Tensor:
    c = torch.as_tensor(color, dtype=like.dtype)
    return torch.cat([c[:3] * c[3], c[3:]]).expand_as(like).clone()


def color_matrix(image: torch.Tensor, kind: str, values) -> torch.Tensor:
    alpha = image[..., 3:]
    rgb = torch.where(alpha > 1e-6, image[..., :3] / alpha.clamp_min(1e-6), torch.zeros_like(image[..., :3]))
    straight = torch.cat([rgb.clamp(0, 1), alpha], dim=-1)
    if kind == "luminanceToAlpha":
        lum = straight[..., 0:1] * 0.2125 + straight[..., 1:2] * 0.7154 + straight[..., 2:3] * 0.0721
        out = torch.cat([torch.zeros_like(rgb), lum], dim=-1)
    else:
        matrix = torch.as_tensor(_matrix(kind, values), dtype=image.dtype)  # [4, 5]
        out = straight @ matrix[:, :4].T + matrix[:, 4]
    out = out.clamp(0, 1)
    return torch.cat([out[..., :3] * out[..., 3:], out[..., 3:]], dim=-1)


def _matrix(kind: str, values) -> list:
    if kind == "saturate":
        s = values[0] if values else 1.0
        return [[0.213 + 0.787 * s, 0.715 - 0.715 * s, 0.072 - 0.072 * s, 0, 0],
                [0.213 - 0.213 * s, 0.715 + 0.285 * s, 0.072 - 0.072 * s, 0, 0],
                [0.213 - 0.213 * s, 0.715 - 0.715 * s, 0.072 + 0.928 * s, 0, 0],
                [0, 0, 0, 1, 0]]
    if kind == "hueRotate":
        a = math.radians(values[0] if values else 0.0)
        c, s = math.cos(a), math.sin(a)
        return [[0.213 + c * 0.787 - s * 0.213, 0.715 - c * 0.715 - s * 0.715, 0.072 - c * 0.072 + s * 0.928, 0, 0],
                [0.213 - c * 0.213 + s * 0.143, 0.715 + c * 0.285 + s * 0.140, 0.072 - c * 0.072 - s * 0.283, 0, 0],
                [0.213 - c * 0.213 - s * 0.787, 0.715 - c * 0.715 + s * 0.715, 0.072 + c * 0.928 + s * 0.072, 0, 0],
                [0, 0, 0, 1, 0]]
    if len(values) == 20:
        return [values[i:i + 5] for i in range(0, 20, 5)]
    return [[1, 0, 0, 0, 0], [0, 1, 0, 0, 0], [0, 0, 1, 0, 0], [0, 0, 0, 1, 0]]


def _over(top, below):
    return top + below * (1 - top[..., 3:])


def composite(a: torch.Tensor, b: torch.Tensor, operator: str, k=None) -> torch.Tensor:
    """feComposite of ``a`` (in) with ``b`` (in2), premultiplied."""
    aa, ab = a[..., 3:], b[..., 3:]
    if operator == "in":
        return a * ab
    if operator == "out":
        return a * (1 - ab)
    if operator == "atop":
        return a * ab + b * (1 - aa)
    if operator == "xor":
        return a * (1 - ab) + b * (1 - aa)
    if operator == "arithmetic":
        k1, k2, k3, k4 = k
        out = (k1 * a * b + k2 * a + k3 * b + k4).clamp(0, 1)
        return torch.cat([torch.minimum(out[..., :3], out[..., 3:]), out[..., 3:]], dim=-1)
    return _over(a, b)


_BLENDS = {
    "multiply": lambda s, d: s * d,
    "screen": lambda s, d: s + d - s * d,
    "darken": torch.minimum,
    "lighten": torch.maximum,
    "difference": lambda s, d: (s - d).abs(),
    "exclusion": lambda s, d: s + d - 2 * s * d,
    "overlay": lambda s, d: torch.where(d <= 0.5, 2 * s * d, 1 - 2 * (1 - s) * (1 - d)),
    "hard-light": lambda s, d: torch.where(s <= 0.5, 2 * s * d, 1 - 2 * (1 - s) * (1 - d)),
    "color-dodge": lambda s, d: torch.where(d <= 0, torch.zeros_like(d), torch.where(
        s >= 1, torch.ones_like(d), torch.clamp(d / (1 - s).clamp_min(1e-6), max=1))),
    "color-burn": lambda s, d: torch.where(d >= 1, torch.ones_like(d), torch.where(
        s <= 0, torch.zeros_like(d), 1 - torch.clamp((1 - d) / s.clamp_min(1e-6), max=1))),
    "soft-light": lambda s, d: torch.where(
        s <= 0.5, d - (1 - 2 * s) * d * (1 - d),
        d + (2 * s - 1) * (torch.where(d <= 0.25, ((16 * d - 12) * d + 4) * d, d.clamp_min(0).sqrt()) - d)),
}
# (the keywords: vecfit.scene.BLEND_MODES, the ones here and normal)


def blend(a: torch.Tensor, b: torch.Tensor, mode: str) -> torch.Tensor:
    """feBlend: ``a`` (in) blended onto ``b`` (in2), premultiplied (W3C compositing)."""
    if mode not in _BLENDS:
        return _over(a, b)
    aa, ab = a[..., 3:], b[..., 3:]
    ca = torch.where(aa > 1e-6, a[..., :3] / aa.clamp_min(1e-6), torch.zeros_like(a[..., :3]))
    cb = torch.where(ab > 1e-6, b[..., :3] / ab.clamp_min(1e-6), torch.zeros_like(b[..., :3]))
    rgb = a[..., :3] * (1 - ab) + b[..., :3] * (1 - aa) + aa * ab * _BLENDS[mode](ca, cb)
    return torch.cat([rgb, aa + ab - aa * ab], dim=-1)
