"""Regenerate the golden reference images: every NAME.svg in this folder rendered by resvg
(through its Python binding, resvg_py from the dev extra) at the SVG's own size, saved as
NAME.png (8-bit straight RGBA). The committed PNGs were made with resvg 0.48.1 (resvg_py
0.5.0), the release the shared conformance corpus was taken from.

    .venv/bin/python tests/oracles/golden/make_references.py [NAME.svg ...]

Only rerun this on purpose (a new or changed SVG, a resvg upgrade), and look at the new
images before committing them: they are what tests/oracles/test_golden.py trusts.
"""
from __future__ import annotations

import io
import sys
from pathlib import Path

RESVG_VERSION = "0.48.1"
HERE = Path(__file__).resolve().parent


def render(svg: Path) -> bytes:
    import resvg_py
    from PIL import Image

    png = bytes(resvg_py.svg_to_bytes(svg_path=str(svg)))
    with Image.open(io.BytesIO(png)) as im:
        rgba = im.convert("RGBA")
    out = io.BytesIO()
    rgba.save(out, format="PNG", optimize=True)
    return out.getvalue()


def main(argv: list[str]) -> int:
    import resvg_py

    if resvg_py.__resvg_version__ != RESVG_VERSION:
        print(f"warning: resvg {resvg_py.__resvg_version__} installed; the references were made "
              f"with {RESVG_VERSION} (update RESVG_VERSION if you mean to move)", file=sys.stderr)
    svgs = [HERE / Path(a).name for a in argv] if argv else sorted(HERE.glob("*.svg"))
    for svg in svgs:
        data = render(svg)
        svg.with_suffix(".png").write_bytes(data)
        print(f"{svg.with_suffix('.png').name}: {len(data)} bytes")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
