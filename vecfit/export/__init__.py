"""SVG's drawing in other formats: PDF for print (export/pdf.py) and DXF for plotters and
cutters (export/dxf.py). Both convert the Scene the SVG reader makes, so every job's
output and any SVG vecfit reads converts alike."""
from __future__ import annotations

import re
import warnings
from pathlib import Path

from vecfit.errors import VecfitError
from vecfit.names import FORMATS
SUFFIXES = {".svg": "svg", ".svgz": "svg", ".pdf": "pdf", ".dxf": "dxf"}


def format_for(path, fmt: str | None = None) -> str:
    """The output format: ``fmt`` if given (svg, pdf, dxf), else the path's suffix (an
    unknown suffix is SVG, as before). An output named for another format than ``fmt``
    is refused: -o x.svg --format pdf is a mistake, not a wish."""
    suffix = Path(path).suffix.lower() if path is not None else ""
    if fmt is None:
        return SUFFIXES.get(suffix, "svg")
    fmt = fmt.strip().lower()
    if fmt not in FORMATS:
        raise VecfitError(f"unknown output format {fmt!r} (svg, pdf or dxf)")
    named = SUFFIXES.get(suffix)
    if named is not None and named != fmt:
        raise VecfitError(f"{path}: the name says {named.upper()} but the format asked is {fmt.upper()}")
    return fmt


def _is_text(svg) -> bool:
    """Whether ``svg`` is the SVG itself (bytes, or text starting with "<"), not a path."""
    return isinstance(svg, bytes) or (isinstance(svg, str) and svg.lstrip().startswith("<"))


def scene_of_svg(svg, name: str = "the SVG"):
    """An SVG (bytes, text or a path) read into a Scene of NumPy arrays (no torch), and
    the unit its root's width is given in ("" for none or px)."""
    from vecfit.scene.arrays import numpy_arrays
    from vecfit.svg.document import SvgDocument
    from vecfit.svg.read import scene_of

    with numpy_arrays():
        if _is_text(svg):
            text = svg.decode("utf-8") if isinstance(svg, bytes) else svg
            document = SvgDocument.parse(text, name)
        else:
            document = SvgDocument.read(svg)
        unit = re.sub(r"[\d.+\-eE\s]", "", document.root.get("width") or "").lower()
        return scene_of(document, for_writing=False), unit


def convert(scene, fmt: str, unit: str = "", curves: str = "polyline") -> bytes:
    """A Scene (tensors or NumPy) as the bytes of a ``fmt`` file (pdf or dxf). A DXF is in
    inches where ``unit`` (the SVG's) is "in", else in millimetres; its curves are
    polylines, or exact splines with ``curves="spline"``."""
    if fmt == "pdf":
        from .pdf import scene_pdf
        return scene_pdf(scene)
    if fmt == "dxf":
        from .dxf import scene_dxf
        return scene_dxf(scene, units="in" if unit == "in" else "mm", curves=curves)
    raise VecfitError(f"cannot convert to {fmt!r} (pdf or dxf)")


def svg_to(svg, fmt: str, name: str = "the SVG", curves: str = "polyline") -> bytes:
    """An SVG (bytes, text or a path) converted to ``fmt`` (pdf or dxf). The reader's own
    warnings are not repeated (the SVG was read, or written, before); the exporter's are."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene, unit = scene_of_svg(svg, name)
    return convert(scene, fmt, unit, curves)


def write(path, payload: bytes) -> None:
    """Bytes saved atomically (nothing half-written)."""
    from vecfit.io.files import atomic_write_bytes

    try:
        atomic_write_bytes(path, payload)
    except OSError as e:
        raise VecfitError(f"{path}: cannot write ({e.strerror or e})") from None


def export(svg, path, fmt: str | None = None, curves: str = "polyline") -> str:
    """Writes the SVG (bytes, text or a path) at ``path`` as PDF, DXF or SVG (``fmt``, or
    the path's suffix); returns the format written."""
    fmt = format_for(path, fmt)
    if fmt == "svg":
        if _is_text(svg):
            payload = svg if isinstance(svg, bytes) else svg.encode("utf-8")
        else:
            payload = Path(svg).read_bytes()
        from vecfit.svg.write import write_bytes
        write_bytes(path, payload)
    else:
        write(path, svg_to(svg, fmt, curves=curves))
    return fmt
