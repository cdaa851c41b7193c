"""RenderFunction: diffvg's entry point, over vecfit.render.

``serialize_scene`` flattens the shapes and groups into diffvg's argument list (holding the
tensors as they are at that moment, as diffvg does); ``apply`` turns the list into a
vecfit Scene (convert.py) and renders it. The image is differentiable through vecfit's own
autograd function; the background image is composited here, in torch, and the pixel
filter's radius gets its gradient from _FilterRadius.
"""
from __future__ import annotations

import time

import torch

from vecfit import _core
from vecfit.errors import VecfitError
from vecfit.renderer.options import RenderOptions
from vecfit.renderer.pack import pack_scene
from vecfit.renderer.raster import render

from . import device
from .convert import Parsed, to_scene
from .enums import FILTER_NAMES, ColorType, FilterType, OutputType, ShapeType
from .points import colors_at
from .sdf import sdf_at, sdf_image
from .shapes import Circle, Ellipse, LinearGradient, Path, PixelFilter, Polygon, RadialGradient, Rect

_print_timing = False


def set_print_timing(value: bool) -> None:
    global _print_timing
    _print_timing = bool(value)


def _paint_args(paint) -> list:
    if paint is None:
        return [None]
    if isinstance(paint, torch.Tensor):
        return [ColorType.constant, paint]
    if isinstance(paint, LinearGradient):
        return [ColorType.linear_gradient, paint.begin, paint.end, paint.offsets, paint.stop_colors]
    if isinstance(paint, RadialGradient):
        return [ColorType.radial_gradient, paint.center, paint.radius, paint.offsets, paint.stop_colors]
    raise VecfitError(f"a colour must be None, an RGBA tensor or a gradient, not {type(paint).__name__}")


def _shape_args(shape) -> list:
    if isinstance(shape, Circle):
        return [ShapeType.circle, shape.radius, shape.center, shape.stroke_width]
    if isinstance(shape, Ellipse):
        return [ShapeType.ellipse, shape.radius, shape.center, shape.stroke_width]
    if isinstance(shape, Path):
        w = shape.stroke_width
        per_point = isinstance(w, torch.Tensor) and w.dim() > 0 and w.shape[0] > 1
        return [ShapeType.path, shape.num_control_points, shape.points, w if per_point else None,
                bool(shape.is_closed), bool(shape.use_distance_approx), torch.tensor(0.0) if per_point else w]
    if isinstance(shape, Polygon):
        n = shape.points.shape[0] - (0 if shape.is_closed else 1)
        return [ShapeType.path, torch.zeros(n, dtype=torch.int32), shape.points, None,
                bool(shape.is_closed), False, shape.stroke_width]
    if isinstance(shape, Rect):
        return [ShapeType.rect, shape.p_min, shape.p_max, shape.stroke_width]
    raise VecfitError(f"unknown shape type {type(shape).__name__}")


def _merge(fg: torch.Tensor, bg: torch.Tensor) -> torch.Tensor:
    """Straight RGBA ``fg`` over straight RGBA ``bg`` (H x W x 4, or 3 channels: opaque)."""
    if bg.shape[-1] == 3:
        bg = torch.cat([bg, torch.ones_like(bg[..., :1])], dim=-1)
    a, ba = fg[..., 3:], bg[..., 3:]
    alpha = a + (1 - a) * ba
    rgb = fg[..., :3] * a + bg[..., :3] * ba * (1 - a)
    safe = torch.where(alpha > 0, alpha, torch.ones_like(alpha))
    return torch.cat([torch.where(alpha > 0, rgb / safe, torch.zeros_like(rgb)), alpha], dim=-1)


def _difference(image, hi, lo, step):
    """(hi - lo) / step for straight RGBA images, taken on premultiplied colour and carried
    to straight colour with ``image``'s alpha: where a pixel's alpha leaves 0 its
    straight colour jumps from 0 to the shape's, which is not a change to count."""
    premult = lambda im: torch.cat([im[..., :3] * im[..., 3:], im[..., 3:]], dim=-1)  # noqa: E731
    d = (premult(hi) - premult(lo)) / step
    alpha, d_alpha = image[..., 3:], d[..., 3:]
    safe = torch.where(alpha > 0, alpha, torch.ones_like(alpha))
    d_rgb = torch.where(alpha > 0, (d[..., :3] - image[..., :3] * d_alpha) / safe, torch.zeros_like(d[..., :3]))
    return torch.cat([d_rgb, d_alpha], dim=-1)


class _FilterRadius(torch.autograd.Function):
    """Passes the image through; its backward adds the filter radius's dL/dr from
    ``gradient(image, dL/d(image))``: mc_radius_gradient or analytic_radius_gradient."""

    @staticmethod
    def forward(ctx, radius, image, gradient):
        ctx.gradient = gradient
        ctx.save_for_backward(image.detach())
        return image.clone()

    @staticmethod
    def backward(ctx, grad):
        (image,) = ctx.saved_tensors
        with torch.no_grad():
            d_r = torch.tensor(float(ctx.gradient(image, grad.detach())), dtype=torch.float32)
        return d_r, grad, None


class _Blank(torch.autograd.Function):
    """diffvg's image for a filter radius <= 0: transparent black, with zero gradients for
    the tensors given (so that a loss of it still has a graph to go back through)."""

    @staticmethod
    def forward(ctx, shape, *tensors):
        ctx.likes = [(t.shape, t.dtype) for t in tensors]
        return torch.zeros(shape)

    @staticmethod
    def backward(ctx, grad):
        return (None, *(torch.zeros(shape, dtype=dtype) for shape, dtype in ctx.likes))


def _premultiplied_adjoint(image, grad):
    """dL/d(premultiplied RGBA) from dL/d(straight RGBA) of a straight image (no
    background: the adapter composites background images after the render)."""
    alpha, rgb = image[..., 3:], image[..., :3]
    safe = torch.where(alpha > 0, alpha, torch.ones_like(alpha))
    g_rgb = torch.where(alpha > 0, grad[..., :3] / safe, torch.zeros_like(rgb))
    g_a = grad[..., 3:] - (g_rgb * rgb).sum(dim=-1, keepdim=True)
    return torch.cat([g_rgb, g_a], dim=-1)


def mc_radius_gradient(scene, width, height, settings):
    """Monte Carlo mode: the core's estimate of the radius derivative of the filtered
    integral, from samples of its own (see filter_radius_kernel in csrc/common/sampling.h;
    one more pass, on the CPU)."""
    def gradient(image, grad):
        arrays = pack_scene(scene, width, height).arrays()
        core_scene = {k: (v.detach().cpu().float().numpy() if isinstance(v, torch.Tensor) else v)
                      for k, v in arrays.items()}
        image = image.cpu()
        pixels = torch.cat([image[..., :3] * image[..., 3:], image[..., 3:]], dim=-1).contiguous().numpy()
        g = _premultiplied_adjoint(image, grad.cpu()).contiguous().numpy()
        options = RenderOptions(width, height, samples=settings["samples"], filter=settings["filter"],
                                filter_radius=settings["filter_radius"], seed=settings["seed"])
        return _core.filter_radius_grad(core_scene, pixels, g, options.core())
    return gradient


def analytic_radius_gradient(render_at, r):
    """Analytical mode (a smooth function of r, whose kernel the core does not
    differentiate): a central difference of two more renders, 0.2% of r each way (a
    larger step would mix colours across an edge where alpha is near 0; see
    _difference)."""
    def gradient(image, grad):
        h = max(1e-3, 0.002 * r)
        hi_r, lo_r = r + h, max(0.5, r - h)  # the core never filters narrower than 0.5 px
        hi, lo = render_at(hi_r), render_at(lo_r)
        return (grad * _difference(image, hi, lo, hi_r - lo_r)).sum()
    return gradient


def _translated(args: list, step: torch.Tensor) -> list:
    """The serialized scene with every group's shape_to_canvas (and so its gradients'
    canvas coordinates) moved by ``step``."""
    parsed = Parsed(args)
    move = torch.eye(3)
    move[:2, 2] = step
    out = list(args)
    matrices = {id(g[4]) for g in parsed.groups}
    for i, item in enumerate(out):
        if isinstance(item, torch.Tensor) and id(item) in matrices:
            m = item.detach().float()
            if m.shape == (2, 3):
                m = torch.cat([m, torch.tensor([[0.0, 0.0, 1.0]])])
            out[i] = move @ m
    return _shift_gradients(out, parsed, step)


def _shift_gradients(args: list, parsed: Parsed, step: torch.Tensor) -> list:
    """Gradient paints are in canvas coordinates: their points move with the scene."""
    points = set()
    for _, fill, stroke, _, _ in parsed.groups:
        for paint in (fill, stroke):
            if paint is not None and paint[0] != ColorType.constant:
                points.add(id(paint[1][0]))  # begin, or the radial centre
                if paint[0] == ColorType.linear_gradient:
                    points.add(id(paint[1][1]))  # end
    return [item.detach() + step if isinstance(item, torch.Tensor) and id(item) in points else item
            for item in args]


class RenderFunction:
    """diffvg's RenderFunction: ``serialize_scene`` then ``apply``."""

    @staticmethod
    def serialize_scene(canvas_width, canvas_height, shapes, shape_groups,
                        filter=PixelFilter(type=FilterType.box, radius=torch.tensor(0.5)),
                        output_type=OutputType.color, use_prefiltering=False,
                        eval_positions=torch.tensor([])):
        args = [canvas_width, canvas_height, len(shapes), len(shape_groups), output_type,
                use_prefiltering, eval_positions]
        for shape in shapes:
            args.extend(_shape_args(shape))
        for group in shape_groups:
            args.append(group.shape_ids)
            args.extend(_paint_args(group.fill_color))
            args.extend(_paint_args(group.stroke_color))
            args.append(group.use_even_odd_rule)
            args.append(group.shape_to_canvas)
        args.append(filter.type)
        args.append(filter.radius)
        return args

    @staticmethod
    def apply(width, height, num_samples_x, num_samples_y, seed, background_image, *args):
        start = time.perf_counter()
        parsed = Parsed(args)
        positions = parsed.eval_positions
        has_positions = isinstance(positions, torch.Tensor) and positions.numel() > 0
        if parsed.output_type == OutputType.sdf:
            if has_positions:
                out = sdf_at(parsed, positions, device.render_device())
            else:
                out = sdf_image(parsed, int(width), int(height), device.render_device())
            if _print_timing:
                print(f"pydiffvg (vecfit): sdf {time.perf_counter() - start:.4f} s")
            return out.to(device.get_device())
        if has_positions:
            out = colors_at(parsed, positions, device.render_device())
            if _print_timing:
                print(f"pydiffvg (vecfit): colours at points {time.perf_counter() - start:.4f} s")
            return out.to(device.get_device())
        scene = to_scene(parsed)
        ftype = FilterType(int(parsed.filter_type))
        radius = parsed.filter_radius
        r = float(radius.detach()) if isinstance(radius, torch.Tensor) else float(radius)
        if r <= 0:
            # diffvg goes on: no pixel centre is within a radius <= 0 of a sample (its weight
            # test is |dx| > r), so no sample is splatted, the background image neither
            tensors = [a for a in args if isinstance(a, torch.Tensor) and a.is_floating_point()
                       and a.requires_grad] if torch.is_grad_enabled() else []
            return _Blank.apply((int(height), int(width), 4), *tensors).to(device.get_device())
        if parsed.use_prefiltering:
            options = dict(samples=1, mode="analytic")
        else:
            options = dict(samples=max(int(num_samples_x), int(num_samples_y)), mode="mc")
        options.update(filter=FILTER_NAMES[ftype], seed=int(seed), device=device.render_device())

        def render_at(radius_value):
            return render(scene, int(width), int(height), filter_radius=radius_value, **options)

        image = render_at(r)
        if (isinstance(radius, torch.Tensor) and radius.requires_grad and torch.is_grad_enabled()
                and ftype != FilterType.box):
            if parsed.use_prefiltering:
                gradient = analytic_radius_gradient(render_at, r)
            else:
                gradient = mc_radius_gradient(scene, int(width), int(height),
                                               dict(options, filter_radius=r))
            image = _FilterRadius.apply(radius, image, gradient)
        if background_image is not None:
            image = _merge(image, background_image.to(image.device, torch.float32))
        if _print_timing:
            print(f"pydiffvg (vecfit): forward pass {time.perf_counter() - start:.4f} s")
        return image.to(device.get_device())

    @staticmethod
    def render_grad(grad_img, width, height, num_samples_x, num_samples_y, seed, background_image, *args):
        """diffvg's translation gradient image [H, W, 2]: for each pixel, its share of
        dL/d(translation of the whole scene, in canvas units), sum(grad_img * dI/dt) at
        that pixel, for the loss L whose gradient with respect to the image is grad_img.
        Here a central difference of the image over a translation each way, with the same
        samples (five renders): 0.002 px in the analytical mode, where the image is smooth;
        a quarter pixel in Monte Carlo mode, where it counts the samples that an edge
        crosses (noisy per pixel, right on average)."""
        parsed = Parsed(args)
        if parsed.output_type != OutputType.color:
            raise VecfitError("render_grad: pydiffvg on vecfit has the translation gradient for colour output only")
        # a small step where the image is smooth in t (analytical mode); where it is a step
        # function of t (Monte Carlo), one large enough for edges to cross some samples
        h = (0.002 if parsed.use_prefiltering else 0.25) * float(parsed.canvas_width) / int(width)
        grad = grad_img.detach().cpu().float()
        out = []
        with torch.no_grad():
            image = RenderFunction.apply(width, height, num_samples_x, num_samples_y, seed, background_image,
                                         *args).cpu()
            for axis in (0, 1):
                images = []
                for sign in (1.0, -1.0):
                    step = torch.zeros(2)
                    step[axis] = sign * h
                    image = RenderFunction.apply(width, height, num_samples_x, num_samples_y, seed, background_image,
                                                 *_translated(args, step))
                    images.append(image.cpu())
                out.append((_difference(image, images[0], images[1], 2 * h) * grad).sum(dim=-1))
        return torch.stack(out, dim=-1).to(device.get_device())
