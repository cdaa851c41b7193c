"""vecfit's own fuzzer: hostile SVGs and images through the command line, each checked
against what every input must get: exit 0, 1 or 2 with a clear line, and never a
traceback, a signal, a hang, NaN or inf written into an SVG, or a partial or .tmp file
left behind.

Cases are deterministic from (seed, index). SVGs are mutated from tests/oracles/golden/ (and the
conformance corpus in ../shared when it is there) or built from a grammar of hostile
values; images are broken in the ways image files break. Families added after the second
campaign (issue 28): images with a side of 1 to 12 px through refine, trace, paint, edit
and retarget, and renders under 7 px on a side; hundreds to thousands of tiny shapes
(below a pixel, off the canvas, radii near 0) refined against small targets; one path of
3,000 to 60,000 segments rendered at 64 px in either mode (20 s: a hang); dashed strokes
(valid and hostile stroke-dasharray and stroke-dashoffset on every kind of shape, rendered
or refined). Clip paths, masks and filters (issue 27): references to themselves, to each
other in a loop, to nothing; masks and clips nested up to 1,000 deep; huge, zero and
negative deviations, regions of zero area, offsets past the canvas, unknown steps;
rendered, refined and listed by info. Families of the third campaign (issue 41): images as
cameras and other programs write them (every EXIF orientation, broken EXIF, 16-bit,
palette, CMYK, WebP, TIFF, animated GIF, 1 x N, truncated, empty) through every job that
reads an image; outputs as PDF and DXF (by name or --format, some contradictory) from
jobs and render, each checked complete; palettes (lists, files, auto:N, bad ones), colour
layers, background removal and trace styles. The cases run in a worker
process that imports vecfit once and calls the command line's main in-process (click's
runner): starting a Python that imports torch costs 1-2 s a case. The worker is killed
and restarted after a signal or a time-out, which are recorded as failures.

    python tests/fuzz/fuzzing.py -n 2000 --seed 1      # `make fuzz N=2000`: a summary table
    python tests/fuzz/fuzzing.py --worker              # (what the runner starts)

Failures are saved under tests/failures/fuzz/ (the case's files and what happened);
each one fixed becomes a fixed input in tests/fuzz/hostile/ (tests/fuzz/test_hostile.py).
"""
from __future__ import annotations

import argparse
import json
import os
import random
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]
ROOT = TESTS.parent
SHARED = Path(os.environ.get("VECFIT_SHARED") or ROOT.parent / "shared")
NS = 'xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"'
RESULT = "@@fuzz-result "

# ------------------------------------------------------------------------- the grammar

HOSTILE_NUMBERS = ["NaN", "nan", "inf", "-inf", "Infinity", "1e308", "-1e308", "1e39", "1e400",
                   "4.9e-324", "1e-310", "-0", "0", "-1", "-5", "1e-30", "1e30", "3.4e38",
                   "99999999999999999999", ".", "-", "1e", "0x10", "1,5", "", " ", "1e7",
                   "2147483648", "-2147483649", "1.5.5"]
LENGTH_SUFFIXES = ["", "", "px", "%", "em", "mm", "in", "pt", "xx"]
PATH_GARBAGE = ["M", "Z", "L", "A", "C 1 2", "M 0 0 L", "Q", "0 0 0", "nan", "e", "-", ",,",
                "M1 1 A 0 0 0 1 1 5 5", "M 0 0 A 1e308 1e-308 90 1 1 1 1",
                "M0 0 a -5 -5 0 0 0 10 0", "M0 0 A 1 1 1e308 0 1 5 5", "m 1e308 1e308 l 1e308 1e308",
                "M 0 0 C 1e39 0 0 1e39 1 1", "M0,0L10,10Z" * 3, "\x00", "M 0 0 H 1e-320 V 1e-320"]
TRANSFORMS = ["scale(0)", "scale(1e308)", "scale(1e-308)", "matrix(0 0 0 0 0 0)",
              "matrix(1 2 2 4 0 0)", "matrix(nan 0 0 1 0 0)", "rotate(inf)", "translate(1e308)",
              "skewX(90)", "scale(2)", "scale(-1 1)", "rotate(45 1e308 0)", "matrix(1 0 0 1)",
              "scale(", "translate(1e7 1e7)"]
COLORS = ["red", "#f00", "#ff000080", "rgb(300,-5,nan)", "url(#missing)", "url(#g)", "none",
          "currentColor", "hsl(inf, 50%, 50%)", "#zzzzzz", "rgba(0,0,0,1e308)", "transparent"]


def _num(rng: random.Random) -> str:
    if rng.random() < 0.6:
        return rng.choice(HOSTILE_NUMBERS) + rng.choice(LENGTH_SUFFIXES)
    return f"{rng.uniform(-200, 200):.3g}"


def _path_data(rng: random.Random) -> str:
    kind = rng.randrange(5)
    if kind == 0:  # garbage stitched together
        return " ".join(rng.choice(PATH_GARBAGE) for _ in range(rng.randint(1, 6)))
    if kind == 1:  # a long path: 10^4 to 10^5 segments
        n = rng.choice([10_000, 30_000, 150_000])  # (over the limit of 100,000: refused)
        xs = (f"{(i * 7919) % 64} {(i * 104729) % 64}" for i in range(n))
        return "M 0 0 L " + " ".join(xs) + " Z"
    if kind == 2:  # arcs with zero, negative, huge or tiny radii
        return "M 10 10 " + " ".join(
            f"A {_num(rng)} {_num(rng)} {_num(rng)} {rng.randint(0, 1)} {rng.randint(0, 1)} {_num(rng)} {_num(rng)}"
            for _ in range(rng.randint(1, 4)))
    if kind == 3:  # commands with hostile numbers
        cmds = ["L", "C", "Q", "S", "T", "H", "V", "l", "c", "a"]
        counts = {"L": 2, "C": 6, "Q": 4, "S": 4, "T": 2, "H": 1, "V": 1, "l": 2, "c": 6, "a": 7}
        out = [f"M {_num(rng)} {_num(rng)}"]
        for _ in range(rng.randint(1, 8)):
            c = rng.choice(cmds)
            out.append(c + " " + " ".join(_num(rng) for _ in range(counts[c])))
        return " ".join(out)
    return "M 0 0 " + "L 1 1 " * rng.randint(0, 3) + rng.choice(["Z", "z", "", "Z Z", "M 5 5"])


def _shape(rng: random.Random) -> str:
    attrs = []
    if rng.random() < 0.3:
        attrs.append(f'transform="{rng.choice(TRANSFORMS)}"')
    if rng.random() < 0.4:
        attrs.append(f'fill="{rng.choice(COLORS)}"')
    if rng.random() < 0.4:
        attrs.append(f'stroke="{rng.choice(COLORS)}" stroke-width="{_num(rng)}"')
    if rng.random() < 0.2:
        attrs.append(f'stroke-linejoin="{rng.choice(["round", "miter", "bevel", "x"])}" '
                     f'stroke-miterlimit="{_num(rng)}"')
    if rng.random() < 0.2:
        attrs.append(f'opacity="{_num(rng)}"')
    if rng.random() < 0.2:
        attrs.append(_dash_attrs(rng))
    a = " ".join(attrs)
    kind = rng.randrange(6)
    if kind == 0:
        return f'<rect x="{_num(rng)}" y="{_num(rng)}" width="{_num(rng)}" height="{_num(rng)}" rx="{_num(rng)}" {a}/>'
    if kind == 1:
        return f'<circle cx="{_num(rng)}" cy="{_num(rng)}" r="{_num(rng)}" {a}/>'
    if kind == 2:
        return f'<ellipse cx="5" cy="5" rx="{_num(rng)}" ry="{_num(rng)}" {a}/>'
    if kind == 3:
        return f'<polygon points="{" ".join(_num(rng) for _ in range(rng.randint(0, 9)))}" {a}/>'
    if kind == 4:
        return f'<line x1="{_num(rng)}" y1="0" x2="10" y2="{_num(rng)}" {a}/>'
    return f'<path d="{_path_data(rng)}" {a}/>'


DASH_ARRAYS = ["5 3", "0 4", "1", "10% 5%", "0.5 0.25 0.1", "3,1", "1e-9", "1e-3 1e-3", "-1 2", "0 0",
               "nan", "inf 1", "1e308 1e308", "5 -0", "1,,2", "none", "0", "2em 1mm", "1e-7%",
               " ".join(["1", "2"] * 500)]


def _dash_attrs(rng: random.Random) -> str:
    """stroke-dasharray and -dashoffset, valid or hostile, sometimes with caps that draw dots."""
    dashes = rng.choice(DASH_ARRAYS) if rng.random() < 0.7 else " ".join(_num(rng) for _ in range(rng.randint(1, 5)))
    out = f'stroke-dasharray="{dashes}"'
    if rng.random() < 0.6:
        out += f' stroke-dashoffset="{_num(rng)}"'
    if rng.random() < 0.5:
        out += f' stroke-linecap="{rng.choice(["round", "square", "butt"])}"'
    return out


def dashed_svg(rng: random.Random) -> bytes:
    """Dashed strokes on every kind of shape: open and closed paths of lines, quadratics
    and cubics (several subpaths, zero-length ones), circles, ellipses, rounded rects,
    polylines and lines, under transforms, with per-shape patterns."""
    parts = []
    for _ in range(rng.randint(1, 6)):
        kind = rng.randrange(6)
        stroke = (f'fill="{rng.choice(["none", "#8c4", "url(#g)"])}" stroke="#123" '
                  f'stroke-width="{rng.choice(["0.5", "2", "6", "1e-3", "30", _num(rng)])}" {_dash_attrs(rng)}')
        if rng.random() < 0.3:
            stroke += f' transform="{rng.choice(TRANSFORMS)}"'
        if kind == 0:
            d = "M 5 5 " + " ".join(rng.choice(["L 30 10", "Q 40 40 20 50", "C 0 60 60 0 58 58", "Z", "M 30 30",
                                                "L 30 30", "H 60", "M 10 50 Z"]) for _ in range(rng.randint(1, 8)))
            parts.append(f'<path d="{d}" {stroke}/>')
        elif kind == 1:
            parts.append(f'<circle cx="32" cy="32" r="{rng.choice(["20", "0.01", "0", "1e5", _num(rng)])}" {stroke}/>')
        elif kind == 2:
            parts.append(f'<ellipse cx="32" cy="32" rx="25" ry="{rng.choice(["8", "1e-4", _num(rng)])}" {stroke}/>')
        elif kind == 3:
            parts.append(f'<rect x="4" y="8" width="50" height="40" rx="{rng.choice(["0", "6", "40", _num(rng)])}" '
                         f'{stroke}/>')
        elif kind == 4:
            pts = " ".join(f"{rng.uniform(0, 64):.1f},{rng.uniform(0, 64):.1f}" for _ in range(rng.randint(1, 12)))
            parts.append(f'<{rng.choice(["polyline", "polygon"])} points="{pts}" {stroke}/>')
        else:
            parts.append(f'<line x1="2" y1="{rng.uniform(0, 64):.1f}" x2="62" y2="{rng.uniform(0, 64):.1f}" {stroke}/>')
    defs = ('<defs><linearGradient id="g"><stop offset="0" stop-color="red"/><stop offset="1" '
            'stop-color="blue"/></linearGradient></defs>')
    return f'<svg {NS} width="64" height="64">{defs}{"".join(parts)}</svg>'.encode()


def _gradient(rng: random.Random) -> str:
    n = rng.choice([0, 1, 2, 10_000])
    stops = "".join(f'<stop offset="{i / max(n, 1) if rng.random() < 0.9 else _num(rng)}" '
                    f'stop-color="{rng.choice(COLORS)}" stop-opacity="{_num(rng) if i % 7 == 0 else 1}"/>'
                    for i in range(n))
    tag = rng.choice(["linearGradient", "radialGradient"])
    geo = (f'x1="{_num(rng)}" x2="{_num(rng)}"' if tag == "linearGradient"
           else f'r="{_num(rng)}" fx="{_num(rng)}" cx="{_num(rng)}"')
    units = rng.choice(["", 'gradientUnits="userSpaceOnUse"', 'gradientUnits="objectBoundingBox"'])
    extra = f'gradientTransform="{rng.choice(TRANSFORMS)}"' if rng.random() < 0.3 else ""
    href = 'xlink:href="#g"' if rng.random() < 0.1 else ""  # a cycle
    return f'<{tag} id="g" {geo} {units} {extra} {href}>{stops}</{tag}>'


def _structure(rng: random.Random, body: str) -> str:
    kind = rng.randrange(7)
    if kind == 0:  # deep nesting
        depth = rng.choice([10, 50, 64, 65, 150, 300, 5000])
        g = rng.choice(['<g>', '<g opacity="0.9">', '<g transform="scale(2)">', '<g transform="scale(0.5)">'])
        return g * depth + body + "</g>" * depth
    if kind == 1:  # a <use> chain or cycle
        n = rng.randint(1, 12)
        defs = f'<defs><g id="u0">{body}</g>' + "".join(
            f'<g id="u{i}"><use href="#u{i - 1}"/><use href="#u{i - 1}" x="3"/></g>' for i in range(1, n)) + "</defs>"
        cyc = '<g id="c1"><use href="#c2"/></g><g id="c2"><use href="#c1"/></g>' if rng.random() < 0.3 else ""
        return defs + cyc + f'<use href="#u{n - 1}"/><use href="#{rng.choice(["u0", "missing", "", "c1"])}"/>'
    if kind == 2:  # gradients
        return f"<defs>{_gradient(rng)}</defs>" + body.replace('fill="red"', 'fill="url(#g)"')
    if kind == 3:  # broken CSS
        css = rng.choice(["rect { fill: url(#nothing) }", "* { stroke-width: 1e308 }", "{{{{", ".a { fill: }",
                          "@import url(x.css); path { opacity: nan }", "svg|rect { fill: red", "\x00"])
        return f"<style>{css}</style>" + body
    if kind == 4:  # missing references
        return (body + '<use href="#nowhere"/><rect width="3" height="3" fill="url(#nowhere) red" '
                'stroke="url(#g)" clip-path="url(#none)" filter="url(#f)"/>')
    if kind == 5:  # nested svg and symbols
        return (f'<svg x="{_num(rng)}" width="{_num(rng)}" height="{_num(rng)}" viewBox="{_viewbox(rng)}">{body}</svg>'
                f'<symbol id="s" viewBox="{_viewbox(rng)}">{body}</symbol><use href="#s" width="{_num(rng)}"/>')
    return body


def _viewbox(rng: random.Random) -> str:
    return " ".join(rng.choice(["0", "0", "1", "-10", "1e-30", "3", "1e300", "1e308", "1e-300", "nan",
                                "inf", "1e400", "-5", "64", _num(rng)]) for _ in range(4))


def _root(rng: random.Random) -> str:
    parts = []
    if rng.random() < 0.6:
        parts.append(f'width="{rng.choice(["64", "1e308", "inf", "nan", "0", "-5", "1e9", "1e-30", "50%", _num(rng)])}"')
    if rng.random() < 0.6:
        parts.append(f'height="{rng.choice(["64", "1e308", "0", "1e-300", "50%", "1", _num(rng)])}"')
    if rng.random() < 0.6:
        parts.append(f'viewBox="{_viewbox(rng) if rng.random() < 0.7 else "0 0 64 64"}"')
    if rng.random() < 0.1:
        parts.append(f'preserveAspectRatio="{rng.choice(["none", "xMaxYMax slice", "bogus"])}"')
    return " ".join(parts)


def grammar_svg(rng: random.Random) -> bytes:
    body = "".join(_shape(rng) for _ in range(rng.randint(1, 4))) + '<rect width="5" height="5" fill="red"/>'
    if rng.random() < 0.08:
        return _entities(rng)
    return f'<svg {NS} {_root(rng)}>{_structure(rng, body)}</svg>'.encode()


def _entities(rng: random.Random) -> bytes:
    """An entity bomb: nested entities expanding to many elements (or a billion laughs)."""
    k = rng.choice([3, 4, 5, 9])
    ents = '<!ENTITY e0 "<rect width=\'1\' height=\'1\'/>">' + "".join(
        f'<!ENTITY e{i} "{f"&e{i - 1};" * 10}">' for i in range(1, k + 1))
    return f'<?xml version="1.0"?><!DOCTYPE svg [{ents}]><svg {NS} width="64" height="64">&e{k};</svg>'.encode()


def _seed_files() -> list[Path]:
    files = sorted((TESTS / "oracles" / "golden").glob("*.svg")) + sorted((TESTS / "fuzz" / "hostile").glob("*.svg"))
    conformance = SHARED / "conformance" / "cases"
    if conformance.is_dir():
        files += sorted(conformance.glob("*.svg"))
    return files


_NUMBER_RE = re.compile(rb"-?\d+(?:\.\d+)?(?:e-?\d+)?")


def mutated_svg(rng: random.Random, seeds: list[Path]) -> bytes:
    data = seeds[rng.randrange(len(seeds))].read_bytes()
    for _ in range(rng.randint(1, 4)):
        # (truncation, byte flips and encodings mostly end at the XML parser: rarer)
        kind = rng.choice([0, 0, 0, 3, 3, 5, 6, 6, 7, 1, 2, 4])
        if kind == 0:  # a number replaced by a hostile one
            matches = list(_NUMBER_RE.finditer(data))
            if matches:
                m = rng.choice(matches)
                data = data[:m.start()] + rng.choice(HOSTILE_NUMBERS).encode() + data[m.end():]
        elif kind == 1:  # truncation
            data = data[:rng.randrange(len(data) + 1)]
        elif kind == 2:  # bytes flipped
            b = bytearray(data)
            for _ in range(rng.randint(1, 5)):
                if b:
                    b[rng.randrange(len(b))] = rng.randrange(256)
            data = bytes(b)
        elif kind == 3:  # a hostile shape or structure inserted before </svg>
            i = data.rfind(b"</svg>")
            if i >= 0:
                data = data[:i] + _structure(rng, _shape(rng)).encode() + data[i:]
        elif kind == 4:  # a bad encoding
            data = rng.choice([b'<?xml version="1.0" encoding="bogus"?>', b'<?xml version="1.0" encoding="UTF-16"?>',
                               b"\xff\xfe", b"\xef\xbb\xbf"]) + data.split(b"?>", 1)[-1]
        elif kind == 5:  # a transform on the root
            data = data.replace(b"<svg ", f'<svg transform="{rng.choice(TRANSFORMS)}" '.encode(), 1)
        elif kind == 6:  # the root's size
            data = re.sub(rb'viewBox="[^"]*"', f'viewBox="{_viewbox(rng)}"'.encode(), data, count=1)
        else:  # an attribute value made huge
            data = data.replace(b'="', b'="' + b"9" * rng.choice([40, 400, 4000]), 1)
    return data


# ----------------------------------------------------------------------------- images

def _png_chunk(kind: bytes, payload: bytes) -> bytes:
    return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", zlib.crc32(kind + payload))


def image_case(rng: random.Random) -> tuple[str, bytes]:
    """(file name, bytes) of an image that is broken, odd, or fine."""
    import io

    import numpy as np
    from PIL import Image

    def encoded(im, fmt="PNG"):
        buf = io.BytesIO()
        im.save(buf, format=fmt)
        return buf.getvalue()

    photo = np.array(Image.open(ROOT / "examples" / "chelsea.png").convert("RGB").resize((48, 32)))
    kind = rng.randrange(11)
    if kind == 0:
        data = encoded(Image.fromarray(photo))
        return "truncated.png", data[:rng.randrange(8, len(data))]
    if kind == 1:
        return "empty.png", b""
    if kind == 2:
        return "one.png", encoded(Image.new("RGB", (1, 1), (255, 0, 0)))
    if kind == 3:
        return "deep.png", encoded(Image.fromarray(photo[..., 0].astype(np.uint16) * 257))
    if kind == 4:
        return "grey.png", encoded(Image.fromarray(photo).convert("L"))
    if kind == 5:
        return "palette.png", encoded(Image.fromarray(photo).convert("P"))
    if kind == 6:
        return "clear.png", encoded(Image.new("RGBA", (40, 30), (0, 0, 0, 0)))
    if kind == 7:  # a header declaring 100,000 x 100,000 pixels, and little data
        ihdr = struct.pack(">IIBBBBB", 100_000, 100_000, 8, 2, 0, 0, 0)
        idat = zlib.compress(b"\x00" * 1000)
        return "huge.png", b"\x89PNG\r\n\x1a\n" + _png_chunk(b"IHDR", ihdr) + _png_chunk(b"IDAT", idat) + _png_chunk(b"IEND", b"")
    if kind == 8:
        return "photo.png", encoded(Image.fromarray(photo), "JPEG")  # a JPEG named .png
    if kind == 9:
        return "tiny.png", encoded(Image.fromarray(photo[:rng.randint(1, 12), :rng.randint(1, 12)]))
    return "photo.png", encoded(Image.fromarray(photo))


def noise_png(index: int, side: int) -> bytes:
    """A side x side PNG of uniform noise, the same for the same case index: a target that
    fits nothing well."""
    import io

    import numpy as np
    from PIL import Image
    buf = io.BytesIO()
    Image.fromarray((np.random.default_rng(index).random((side, side, 3)) * 255).astype(np.uint8)).save(buf, "PNG")
    return buf.getvalue()


# ------------------------------------------------- families from the second campaign

def thin_image(rng: random.Random) -> tuple[str, bytes, int, int]:
    """A photo-like image with one side of 1 to 12 pixels and the other 100 to 700: the
    jobs' working sizes shrink the long side and must not take the short one below 11."""
    import io

    import numpy as np
    from PIL import Image
    short, long_ = rng.choice([1, 3, 6, 11, 11, 12, 12]), rng.choice([100, 300, 700])
    w, h = (long_, short) if rng.random() < 0.5 else (short, long_)
    pixels = (np.random.default_rng(rng.randrange(1 << 30)).random((h, w, 3)) * 255).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(pixels).save(buf, format="PNG")
    return "thin.png", buf.getvalue(), w, h


def tiny_shapes_svg(rng: random.Random) -> bytes:
    """Hundreds to thousands of small shapes (radii 0 to 5, some below a pixel or off the
    canvas) on a 200-unit canvas: against a small target most parameters barely touch a
    pixel, and radii crossing 0 make draws come and go."""
    n = rng.choice([200, 800, 2000])
    off = rng.random() < 0.2   # every shape off the canvas
    scale = rng.choice([1.0, 1.0, 0.01])  # 0.01: every shape below a pixel
    parts = []
    for _ in range(n):
        x, y = rng.uniform(0, 200), rng.uniform(0, 200)
        if off:
            x += 400
        r = rng.uniform(0, 5) * scale
        color = f"#{rng.randrange(1 << 24):06x}"
        kind = rng.randrange(3)
        if kind == 0:
            parts.append(f'<circle cx="{x:.2f}" cy="{y:.2f}" r="{r:.3f}" fill="{color}"/>')
        elif kind == 1:
            parts.append(f'<rect x="{x:.2f}" y="{y:.2f}" width="{2 * r:.3f}" height="{r:.3f}" fill="{color}"/>')
        else:
            parts.append(f'<path d="M {x:.2f} {y:.2f} q {r:.2f} {-r:.2f} {2 * r:.2f} 0" stroke="{color}" '
                         f'stroke-width="{r / 2:.3f}" fill="none"/>')
    return f'<svg {NS} width="200" height="200">{"".join(parts)}</svg>'.encode()


def long_path_svg(rng: random.Random) -> bytes:
    """One path of 3,000 to 60,000 segments (lines, quadratics, cubics or all three), a walk
    of short or canvas-wide steps, filled with a colour or a gradient, sometimes stroked
    up to 10^7 wide."""
    n = rng.choice([3000, 10_000, 30_000, 60_000])
    kinds = rng.choice(["L", "C", "LQC", "QC"])
    step = rng.choice([1.0, 4.0, 15.0])
    counts = {"L": 1, "Q": 2, "C": 3}
    x = y = 100.0
    out = [f"M {x:.1f} {y:.1f}"]
    for i in range(n):
        k = kinds[i % len(kinds)]
        pts = []
        for _ in range(counts[k]):
            x = min(max(x + rng.uniform(-step, step), 0.0), 200.0)
            y = min(max(y + rng.uniform(-step, step), 0.0), 200.0)
            pts.append(f"{x:.1f} {y:.1f}")
        out.append(k + " ".join(pts))
    fill = rng.choice(['fill="#3a6"', 'fill="url(#g)"', 'fill="none"'])
    stroke = rng.choice(["", 'stroke="#000" stroke-width="1"', 'stroke="#000" stroke-width="30"',
                         'stroke="green" stroke-width="1e7"'])
    defs = ('<defs><linearGradient id="g"><stop offset="0" stop-color="red"/><stop offset="1" '
            'stop-color="blue"/></linearGradient></defs>')
    return (f'<svg {NS} width="200" height="200">{defs}<path d="{" ".join(out)} Z" {fill} {stroke}/></svg>').encode()


def effects_svg(rng: random.Random) -> bytes:
    """Clip paths, masks and filters at their edges: loops, missing references, deep
    nesting, extreme deviations and regions, and ordinary ones on groups and shapes."""
    defs, body = [], []
    depth = rng.choice([1, 3, 40, 1000])
    kind = rng.choice(["clipPath", "mask"])
    for i in range(depth):  # a chain: each one's content (or the element itself) uses the next
        ref = f"url(#e{i + 1})" if i + 1 < depth else rng.choice(["url(#e0)", "url(#gone)", "none"])
        attr = "clip-path" if kind == "clipPath" else "mask"
        on_self = rng.random() < 0.5
        child = (f'<rect x="{rng.uniform(-20, 60):.1f}" y="{rng.uniform(-20, 60):.1f}" width="{rng.uniform(0, 80):.1f}" '
                 f'height="{rng.uniform(0, 80):.1f}" fill="{rng.choice(["white", "#777", "url(#g)"])}"'
                 + ("" if on_self else f' {attr}="{ref}"') + "/>")
        units = rng.choice(["", ' clipPathUnits="objectBoundingBox"', ' maskUnits="userSpaceOnUse"',
                            ' maskContentUnits="objectBoundingBox"', ' transform="scale(0)"'])
        defs.append(f'<{kind} id="e{i}"{units}' + (f' {attr}="{ref}"' if on_self else "") + f">{child}</{kind}>")
    std = rng.choice(["0", "-3", "2", "1e6", "1e30", "3 0", "nan", "1e-9"])
    region = rng.choice(['', ' width="0"', ' height="-5"', ' x="1e30"', ' filterUnits="userSpaceOnUse" '
                         'x="0" y="0" width="1e9" height="1e9"', ' primitiveUnits="objectBoundingBox"'])
    steps = [f'<feGaussianBlur stdDeviation="{std}" result="b"/>',
             f'<feOffset dx="{rng.choice(["5", "-1e9", "0.5"])}" dy="3"/>',
             '<feFlood flood-color="red" flood-opacity="0.5"/>', '<feComposite in="SourceGraphic" in2="b" operator='
             f'"{rng.choice(["over", "in", "arithmetic", "bogus"])}" k2="1" k3="1"/>',
             '<feMerge><feMergeNode in="b"/><feMergeNode in="nowhere"/></feMerge>',
             f'<feDropShadow stdDeviation="{std}"/>', '<feColorMatrix type="saturate" values="0"/>',
             '<feBlend mode="multiply" in2="SourceAlpha"/>', '<feTurbulence baseFrequency="0.1"/>']
    defs.append(f'<filter id="f"{region}>{"".join(rng.sample(steps, rng.randint(0, 4)))}</filter>')
    defs.append('<linearGradient id="g"><stop offset="0" stop-color="white"/><stop offset="1" '
                'stop-color="black"/></linearGradient>')
    for _ in range(rng.randint(1, 6)):
        effect = rng.choice(['clip-path="url(#e0)"', 'mask="url(#e0)"', 'filter="url(#f)"', 'filter="url(#nope)"',
                             'clip-path="url(#e0)" filter="url(#f)"', 'style="mask: url(#e0)"', ""])
        shape = rng.choice([f'<circle cx="{rng.uniform(0, 64):.1f}" cy="{rng.uniform(0, 64):.1f}" r="{rng.uniform(0, 30):.1f}"',
                            '<path d="M 5 5 C 60 0 0 60 60 60 Z" stroke="#036" stroke-width="3"',
                            '<rect width="64" height="64"'])
        if rng.random() < 0.4:
            body.append(f'<g {effect} opacity="0.8">{shape} fill="#c33"/>{shape} fill="#8a4"/></g>')
        else:
            body.append(f'{shape} fill="#8a4" {effect}/>')
    nested = rng.random() < 0.2
    inner = "".join(body)
    if nested:
        inner = f'<svg x="8" y="8" width="40" height="40" viewBox="0 0 64 64">{inner}</svg>'
    return f'<svg {NS} width="64" height="64"><defs>{"".join(defs)}</defs>{inner}</svg>'.encode()


# ------------------------------------------------------------------------------ cases

# ------------------------------------------------- families from the third campaign

def format_image(rng: random.Random) -> tuple[str, bytes]:
    """(file name, bytes) of an image in a format or layout a camera, a scanner or another
    program writes (issue 41): every EXIF orientation and broken EXIF (JPEG and PNG's
    eXIf), 16-bit, palette with a transparent index, CMYK, WebP, TIFF, animated GIF,
    1 x N pixels; some truncated or empty."""
    import io

    import numpy as np
    from PIL import Image

    photo = Image.open(ROOT / "examples" / "chelsea.png").convert("RGB").resize((36, 24))
    kind = rng.randrange(12)

    def saved(im, fmt, **kw):
        buf = io.BytesIO()
        im.save(buf, format=fmt, **kw)
        return buf.getvalue()

    if kind <= 1:  # an EXIF orientation, 1 to 8 or out of range
        exif = Image.Exif()
        exif[0x0112] = rng.choice([1, 2, 3, 4, 5, 6, 7, 8, 0, 9, 65535])
        fmt = "JPEG" if kind == 0 else "PNG"
        name, data = f"oriented.{fmt.lower()}", saved(photo, fmt, exif=exif.tobytes())
    elif kind == 2:  # EXIF that is not EXIF
        junk = bytes(rng.randrange(256) for _ in range(rng.choice([0, 3, 16, 200])))
        fmt = rng.choice(["JPEG", "PNG"])
        name, data = f"badexif.{fmt.lower()}", saved(photo, fmt, exif=rng.choice([b"Exif\x00\x00", b"MM\x00*"]) + junk)
    elif kind == 3:
        a = np.asarray(photo).astype(np.uint16) * 257
        name, data = "deep.png", saved(Image.fromarray(a[..., 0]), "PNG")  # 16-bit grey
    elif kind == 4:
        im = photo.convert("P", palette=Image.Palette.ADAPTIVE, colors=rng.choice([2, 16, 256]))
        name, data = "indexed.png", saved(im, "PNG", transparency=rng.randrange(2))
    elif kind == 5:
        name, data = "cmyk.jpg", saved(photo.convert("CMYK"), "JPEG")
    elif kind == 6:
        im = photo.convert("RGBA") if rng.random() < 0.5 else photo
        name, data = "photo.webp", saved(im, "WEBP", lossless=rng.random() < 0.5)
    elif kind == 7:
        im = rng.choice([photo, photo.convert("RGBA"), photo.convert("CMYK"), photo.convert("I;16")])
        name, data = "scan.tiff", saved(im, "TIFF")
    elif kind == 8:
        frames = [photo, photo.transpose(Image.Transpose.FLIP_LEFT_RIGHT), Image.new("RGB", (36, 24), "red")]
        name, data = "moving.gif", saved(frames[0], "GIF", save_all=True, append_images=frames[1:], duration=50, loop=0)
    elif kind == 9:
        w, h = (1, rng.choice([1, 2, 50, 300])) if rng.random() < 0.5 else (rng.choice([2, 50, 300]), 1)
        name, data = "line.png", saved(photo.resize((w, h)), "PNG")
    elif kind == 10:
        name, data = rng.choice(["empty.webp", "empty.tiff", "empty.gif", "empty.jpg"]), b""
    else:
        name, data = "clear.webp", saved(Image.new("RGBA", (20, 20), (0, 0, 0, 0)), "WEBP", lossless=True)
    if kind < 10 and rng.random() < 0.15:
        data = data[:rng.randrange(1, max(2, len(data)))]
    return name, data


def output_format_args(rng: random.Random) -> tuple[list[str], list[str]]:
    """An output in SVG, PDF or DXF, by name or by --format (issue 38), with the files the
    command may write; some contradictory (a usage error, nothing written)."""
    fmt = rng.choice(["svg", "pdf", "dxf"])
    how = rng.random()
    if how < 0.45:
        args = ["-o", f"out.{fmt}"]
    elif how < 0.9:
        args = ["-o", "out", "--format", fmt] if rng.random() < 0.5 else ["--format", fmt, "-o", f"out.{fmt}"]
    else:
        args = ["-o", "out.svg", "--format", rng.choice(["pdf", "dxf"])]
    return args, ["out.svg", "out.pdf", "out.dxf", "out", "out.report.json", "out.compare.png"]


PALETTES = ["#e63946,#f1faee,#1d3557", "auto:3", "auto:1", "auto:0", "auto:-2", "auto:x", "", ",",
            "#zzzzzz", "red, blue", "#fff", "missing.gpl", "palette.txt", "palette.gpl"]


def colour_and_style_args(rng: random.Random, command: str) -> list[str]:
    """This wave's options (issues 37, 38, 39), valid and not: palettes (lists, files,
    auto:N, auto:0, bad colours), colour layers, background removal, trace styles,
    cut-outs and the gap filler."""
    args = []
    if rng.random() < 0.5:
        args += ["--palette", rng.choice(PALETTES)]
    if rng.random() < 0.3:
        args += ["--group-by", rng.choice(["colour", "none"])]
    if command == "trace" and rng.random() < 0.3:
        args.append("--remove-background")
    if command == "trace" and rng.random() < 0.4:
        args += ["--style", rng.choice(["strokes", "mixed", "fills"])]
    if rng.random() < 0.3:  # cut-outs (issue 37), with and without the gap filler, some refused
        args += ["--stacking", rng.choice(["cutouts", "cutouts", "stacked"])]
    if rng.random() < 0.2:
        args.append("--gap-filler")
    if rng.random() < 0.2:  # a scan's blur fitted through (optimize.target_blur), in a config file
        args += ["--config", rng.choice(sorted(k for k in PALETTE_FILES if k.startswith("blur")))]
    return args


PALETTE_FILES = {"palette.txt": b"#ff0000\n00ff00\n  \nblue\n12 34 56\n",
                 "palette.gpl": b"GIMP Palette\nName: x\n#\n255 0 0 red\n0 0 255\tblue\n",
                 **{f"blur-{k}.toml": b"[optimize]\ntarget_blur = " + v + b"\n" for k, v in
                    {"auto": b'"auto"', "none": b"0", "some": b"1.5", "most": b"8", "past": b"9.5", "below": b"-1",
                     "word": b'"sharp"', "yes": b"true", "nan": b"nan"}.items()}}


@dataclass
class Case:
    index: int
    kind: str                     # what made it (grammar, mutation, image, ...)
    command: str                  # render, info, refine, trace, paint
    args: list[str]               # the command line; files named relative to the case folder
    files: dict[str, bytes] = field(default_factory=dict)
    timeout: float = 30.0
    outputs: list[str] = field(default_factory=list)  # files the command may write


def make_case(seed: int, index: int, seeds: list[Path] | None = None) -> Case:
    rng = random.Random(f"{seed}:{index}")
    seeds = seeds if seeds is not None else _seed_files()
    roll = rng.random()
    if roll < 0.1:  # images as cameras and other programs write them; outputs as PDF and DXF
        return _third_campaign_case(rng, index)
    roll = (roll - 0.1) / 0.9  # (the older families keep their shares)
    if roll < 0.12:  # an image through refine / trace / paint, a few iterations
        name, data = image_case(rng)
        command = rng.choice(["refine", "trace", "paint"])
        files = {name: data}
        args = [command, name]
        if command == "refine":
            svg = mutated_svg(rng, seeds) if rng.random() < 0.5 else (
                f'<svg {NS} viewBox="0 0 48 32"><rect width="48" height="32" fill="#888"/>'
                f'<circle cx="20" cy="16" r="9" fill="red"/></svg>').encode()
            files["init.svg"] = svg
            args.append("init.svg")
        elif command == "paint":
            args += ["--paths", "4"]
        else:
            args += ["--paths", "6"]
        args += ["-o", "out.svg", "--iterations", str(rng.choice([0, 2, 3])), "--max-size", "48", "-q",
                 "--samples", "1", "--threads", "1"]
        return Case(index, "image", command, args, files, timeout=60,
                    outputs=["out.svg", "out.report.json", "out.compare.png"])
    if roll < 0.16:  # an image with a side under 12 px through every fitting command
        name, data, w, h = thin_image(rng)
        command = rng.choice(["refine", "trace", "paint", "edit", "retarget"])
        svg = (f'<svg {NS} viewBox="0 0 {w} {h}"><rect width="{w}" height="{h}" fill="#888"/>'
               f'<circle cx="{w / 3:g}" cy="{h / 2:g}" r="{min(w, h) / 3:g}" fill="red"/></svg>').encode()
        files = {name: data, "init.svg": svg}
        args = {"refine": ["refine", name, "init.svg"], "trace": ["trace", name, "--paths", "4"],
                "paint": ["paint", name, "--paths", "4"], "edit": ["edit", "init.svg", name],
                "retarget": ["retarget", "init.svg", "--width", "80%"] if w > h else
                            ["retarget", "init.svg", "--width", "100%", "--height", "80%"]}[command]
        args += ["-o", "out.svg", "--iterations", str(rng.choice([0, 2])), "-q", "--samples", "1", "--threads", "1"]
        if command != "retarget":
            args += ["--max-size", str(rng.choice([48, 512]))]
        return Case(index, "thin", command, args, files, timeout=60,
                    outputs=["out.svg", "out.report.json", "out.compare.png"])
    if roll < 0.19:  # many tiny shapes refined against a small target
        side = rng.choice([11, 16, 64])
        args = ["refine", "target.png", "init.svg", "-o", "out.svg", "--iterations", str(rng.choice([1, 3])), "-q",
                "--samples", "1", "--threads", "1", "--mode", rng.choice(["mc", "analytic"])]
        return Case(index, "tiny", "refine", args, {"target.png": noise_png(index, side), "init.svg": tiny_shapes_svg(rng)},
                    timeout=60, outputs=["out.svg", "out.report.json", "out.compare.png"])
    if roll < 0.28:  # clip paths, masks and filters: rendered in either mode, listed, refined
        svg = effects_svg(rng)
        command = rng.choice(["render", "render", "info", "refine"])
        if command == "info":
            return Case(index, "effects", "info", ["info", "in.svg"], {"in.svg": svg})
        if command == "refine":
            args = ["refine", "target.png", "in.svg", "-o", "out.svg", "--iterations", "2", "-q", "--samples", "1",
                    "--threads", "1", "--mode", rng.choice(["mc", "analytic"])]
            return Case(index, "effects", "refine", args, {"target.png": noise_png(index, 32), "in.svg": svg},
                        timeout=60, outputs=["out.svg", "out.report.json", "out.compare.png"])
        mode = rng.choice(["mc", "analytic"])
        return Case(index, "effects", "render", ["render", "in.svg", "-o", "out.png", "--width", "64", "--mode", mode,
                                                 "--samples", "1", "--threads", "1"],
                    {"in.svg": svg}, timeout=20, outputs=["out.png"])
    if roll < 0.31:  # one very long path at 64 px (a hang: 20 s)
        mode = rng.choice(["mc", "analytic"])
        return Case(index, "longpath", "render", ["render", "in.svg", "-o", "out.png", "--width", "64", "--mode", mode,
                                                  "--samples", "1", "--threads", "1"],
                    {"in.svg": long_path_svg(rng)}, timeout=20, outputs=["out.png"])
    if roll < 0.35:  # dashed strokes, rendered, or refined (the dashes follow the points)
        svg = dashed_svg(rng)
        mode = rng.choice(["mc", "analytic"])
        if rng.random() < 0.7:
            return Case(index, "dashes", "render", ["render", "in.svg", "-o", "out.png", "--width", "64", "--mode", mode,
                                                    "--samples", "1", "--threads", "1"], {"in.svg": svg},
                        timeout=30, outputs=["out.png"])
        # (the writer keeps attributes it does not change: no NaN or inf words in them,
        # which the oracle would find in out.svg)
        svg = re.sub(rb"\b(nan|inf|infinity)\b", b"1e39", svg, flags=re.I)
        args = ["refine", "target.png", "init.svg", "-o", "out.svg", "--iterations", "2", "-q", "--samples", "1",
                "--threads", "1", "--mode", mode]
        return Case(index, "dashes", "refine", args, {"target.png": noise_png(index, 32), "init.svg": svg},
                    timeout=60, outputs=["out.svg", "out.report.json", "out.compare.png"])
    kind = "mutation" if roll < 0.6 else "grammar"
    svg = mutated_svg(rng, seeds) if kind == "mutation" else grammar_svg(rng)
    if rng.random() < 0.2:
        return Case(index, kind, "info", ["info", "in.svg"], {"in.svg": svg})
    size = rng.choice([["--width", "64"], ["--height", "48"], ["--width", "64", "--height", "1"], [],
                       ["--width", str(rng.randint(1, 6))], ["--width", "3", "--height", "2"],
                       ["--width", "200", "--height", str(rng.randint(1, 6))]])
    mode = rng.choice(["mc", "mc", "analytic"])
    return Case(index, kind, "render", ["render", "in.svg", "-o", "out.png", *size, "--mode", mode,
                                        "--samples", "1", "--threads", "1"], {"in.svg": svg},
                outputs=["out.png"])


def _third_campaign_case(rng: random.Random, index: int) -> Case:
    if rng.random() < 0.6:  # an image format through every job that reads an image
        name, data = format_image(rng)
        command = rng.choice(["refine", "trace", "trace", "paint", "edit"])
        files = {name: data, "init.svg": (f'<svg {NS} viewBox="0 0 36 24"><rect width="36" height="24" fill="#888"/>'
                                          f'<circle cx="12" cy="12" r="8" fill="red"/></svg>').encode()}
        args = {"refine": ["refine", name, "init.svg"], "trace": ["trace", name, "--paths", "6"],
                "paint": ["paint", name, "--paths", "4"], "edit": ["edit", "init.svg", name]}[command]
        if command != "edit" and rng.random() < 0.4:
            args += colour_and_style_args(rng, command)
            files.update(PALETTE_FILES)
        args += ["-o", "out.svg", "--iterations", str(rng.choice([0, 2])), "--max-size", "48", "-q",
                 "--samples", "1", "--threads", "1"]
        return Case(index, "formats", command, args, files, timeout=60,
                    outputs=["out.svg", "out.report.json", "out.compare.png"])
    # an output format: a job's result, or render's conversion, of a hostile SVG
    out_args, outputs = output_format_args(rng)
    svg = rng.choice([grammar_svg, effects_svg, dashed_svg])(rng)
    svg = re.sub(rb"\b(nan|inf|infinity)\b", b"1e39", svg, flags=re.I)
    command = rng.choice(["trace", "refine", "render"])
    if command == "render":
        fmt = rng.choice(["pdf", "dxf"])
        return Case(index, "outputs", "render", ["render", "in.svg", "-o", f"out.{fmt}"], {"in.svg": svg},
                    timeout=30, outputs=[f"out.{fmt}"])
    args = (["trace", "target.png", "--paths", "5"] if command == "trace" else ["refine", "target.png", "in.svg"])
    args += [*out_args, *colour_and_style_args(rng, command), "--iterations", str(rng.choice([0, 2])), "-q",
             "--samples", "1", "--threads", "1"]
    return Case(index, "outputs", command, args, {"target.png": noise_png(index, 24), "in.svg": svg, **PALETTE_FILES},
                timeout=60, outputs=outputs)


# ----------------------------------------------------------------------------- oracle

def verdict(case: Case, folder: Path, outcome: dict) -> str | None:
    """What is wrong with how the case ended (None: nothing)."""
    if outcome.get("signal"):
        return f"killed by signal {outcome['signal']}"
    if outcome.get("timeout"):
        return f"no answer within {case.timeout:g} s"
    if outcome.get("exception"):
        return "traceback: " + outcome["exception"].strip().splitlines()[-1]
    text = outcome["stdout"] + outcome["stderr"]
    if "Traceback" in text:
        return "traceback in the output"
    code = outcome["exit_code"]
    if code not in (0, 1, 2):
        return f"exit code {code}"
    if code != 0 and not re.search(r"^(error|Error|Usage):?", outcome["stderr"], re.M):
        return "failed without an error line"
    names = {p.name for p in folder.iterdir()}
    stray = [n for n in names if n.endswith(".tmp") or n.startswith(".")]
    if stray:
        return f"left behind: {', '.join(sorted(stray))}"
    results = [n for n in case.outputs if not n.endswith((".report.json", ".compare.png"))]
    if code == 0 and results and not any((folder / n).exists() for n in results):
        return f"exit 0 but no {' or '.join(results)}"
    for name in case.outputs:
        path = folder / name
        if not path.exists():
            continue
        head = path.read_bytes()[:64].lstrip()
        kind = (".pdf" if head.startswith(b"%PDF-") else ".svg" if head.startswith((b"<", b"\xef\xbb\xbf<"))
                else ".dxf") if name == "out" else path.suffix  # (an output named without a suffix)
        if kind == ".svg":
            text = path.read_text(encoding="utf-8", errors="replace")
            if not text.rstrip().endswith("</svg>"):
                return f"{name} is not a complete SVG"
            # (Text the input already held, such as a filter's stdDeviation="nan" that the
            # writer keeps as it was, is the user's, not vecfit's.)
            found = len(re.findall(r"\b(nan|inf|infinity)\b", text, re.I))
            given = sum(len(re.findall(rb"\b(nan|inf|infinity)\b", data, re.I))
                        for file, data in case.files.items() if file.endswith(".svg"))
            if found > given:
                return f"{name} has nan or inf in it"
        elif kind == ".pdf":
            if not path.read_bytes().rstrip().endswith(b"%%EOF"):
                return f"{name} is not a complete PDF"
        elif kind == ".dxf":
            if not path.read_bytes().rstrip().endswith(b"EOF"):
                return f"{name} is not a complete DXF"
        elif kind == ".png":
            from PIL import Image
            try:
                with Image.open(path) as im:
                    im.load()
            except Exception as e:  # a partial PNG
                return f"{name} cannot be read back ({e})"
    return None


# ----------------------------------------------------------------------------- worker

def _worker() -> None:
    """Reads case folders and command lines (JSON, one a line) from stdin; runs each with
    click's runner in this process; writes the outcome as a RESULT line."""
    import traceback
    import warnings

    from click.testing import CliRunner

    from vecfit.cli.commands import main

    def timed_out(signum, frame):
        raise TimeoutError("the case ran past its time limit")

    signal.signal(signal.SIGALRM, timed_out)
    out = sys.stdout
    for line in sys.stdin:
        job = json.loads(line)
        os.chdir(job["folder"])
        start = time.perf_counter()
        signal.alarm(max(1, int(job["timeout"])))
        outcome = {"exception": None, "timeout": False}
        try:
            with warnings.catch_warnings():
                result = CliRunner().invoke(main, job["args"], catch_exceptions=True)
            outcome.update(exit_code=result.exit_code, stdout=result.stdout, stderr=result.stderr)
            if result.exception is not None and not isinstance(result.exception, SystemExit):
                if isinstance(result.exception, TimeoutError):
                    outcome["timeout"] = True
                else:
                    outcome["exception"] = "".join(traceback.format_exception(result.exception))
        finally:
            signal.alarm(0)
        outcome["seconds"] = time.perf_counter() - start
        out.write(RESULT + json.dumps(outcome) + "\n")
        out.flush()


class Runner:
    """The worker process: started on demand, restarted after it dies or hangs."""

    def __init__(self, env: dict | None = None):
        self.env = env
        self.proc = None

    def _start(self):
        self.proc = subprocess.Popen([sys.executable, str(Path(__file__).resolve()), "--worker"],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                     text=True, env=self.env, cwd=str(ROOT))

    def run(self, case: Case, folder: Path) -> dict:
        if self.proc is None or self.proc.poll() is not None:
            self._start()
        self.proc.stdin.write(json.dumps({"folder": str(folder), "args": case.args, "timeout": case.timeout}) + "\n")
        self.proc.stdin.flush()
        deadline = time.monotonic() + case.timeout + 20  # (the worker's own alarm comes first)
        import selectors
        sel = selectors.DefaultSelector()
        sel.register(self.proc.stdout, selectors.EVENT_READ)
        try:
            while True:
                left = deadline - time.monotonic()
                if left <= 0 or not sel.select(timeout=left):
                    self.close()
                    return {"timeout": True}
                line = self.proc.stdout.readline()
                if not line:  # the worker died
                    code = self.proc.wait()
                    self.proc = None
                    return {"signal": -code if code < 0 else None, "exception": f"worker exited with {code}"}
                if line.startswith(RESULT):
                    return json.loads(line[len(RESULT):])
        finally:
            sel.close()

    def close(self):
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc = None


def run_case(runner: Runner, case: Case, keep_failures: Path | None = None) -> tuple[str | None, dict]:
    with tempfile.TemporaryDirectory(prefix="vecfit-fuzz-") as tmp:
        folder = Path(tmp)
        for name, data in case.files.items():
            (folder / name).write_bytes(data)
        outcome = runner.run(case, folder)
        problem = verdict(case, folder, outcome)
        if problem and keep_failures is not None:
            dest = keep_failures / f"case-{case.index}"
            shutil.rmtree(dest, ignore_errors=True)
            dest.mkdir(parents=True)
            for name, data in case.files.items():
                (dest / name).write_bytes(data)
            (dest / "what.json").write_text(json.dumps({"problem": problem, "args": case.args,
                                                        "outcome": outcome}, indent=1))
    return problem, outcome


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("-n", type=int, default=300, help="number of cases")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--start", type=int, default=0, help="first case index")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        _worker()
        return 0
    failures_dir = TESTS / "failures" / "fuzz"
    seeds = _seed_files()
    runner = Runner()
    table: dict[tuple[str, str], Counter] = {}
    failures = []
    started = time.perf_counter()
    try:
        for i in range(args.start, args.start + args.n):
            case = make_case(args.seed, i, seeds)
            problem, outcome = run_case(runner, case, failures_dir)
            row = table.setdefault((case.command, case.kind), Counter())
            row["cases"] += 1
            row["seconds"] += outcome.get("seconds", 0.0)
            if problem:
                row["failed"] += 1
                failures.append((case.index, case.command, problem))
            else:
                row[f"exit {outcome['exit_code']}"] += 1
    finally:
        runner.close()
    print(f"{'command':8} {'made by':9} {'cases':>6} {'exit 0':>7} {'exit 1':>7} {'exit 2':>7} {'failed':>7} {'s/case':>7}")
    for (command, kind), c in sorted(table.items()):
        print(f"{command:8} {kind:9} {c['cases']:6} {c['exit 0']:7} {c['exit 1']:7} {c['exit 2']:7} "
              f"{c['failed']:7} {c['seconds'] / c['cases']:7.2f}")
    print(f"{args.n} cases (seed {args.seed}) in {time.perf_counter() - started:.0f} s; {len(failures)} failed")
    for index, command, problem in failures:
        print(f"  case {index} ({command}): {problem}  -> {failures_dir / f'case-{index}'}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
