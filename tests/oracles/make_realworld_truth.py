"""Truth images and the known-deviations table for tests/oracles/test_realworld.py.

    python tests/oracles/make_realworld_truth.py [NAME ...]

For each named case of the real-world corpus (no names: the candidates in REASONS) it
renders the SVG with resvg at 16x the reference width and height (the files set
preserveAspectRatio="none", so the aspect is the reference's), averages each 16x16 block
and writes tests/oracles/realworld_truth/NAME.png at the reference size. The average is taken
over premultiplied RGBA as floats, in the PNG's own 8-bit (sRGB-encoded, not linearised)
values, which is where resvg and vecfit blend; the result is stored as 8-bit straight
(un-premultiplied) RGBA, as resvg writes its PNGs. Over white this is the mean of the 256
sub-pixel colours, so it is resvg's own parser, geometry and paint with its anti-aliasing
taken to convergence: a fair reference for the cases whose only miss is that anti-aliasing.

It then measures each case (PSNR over white, 8-bit, as test_realworld scores):
resvg_1x_vs_truth_db (the corpus's reference PNG against the truth image),
vecfit_4x4_vs_resvg_db (the score at 4x4; the test renders 8x8), vecfit_4x4_vs_truth_db and
vecfit_32x32_vs_truth_db (vecfit converged). A case is a known deviation, and its row goes
into tests/oracles/realworld_deviations.tsv (other rows are kept), only where resvg 1x is the
outlier: vecfit at 32x32 samples is within test_realworld.CONVERGED_DB (45) of the truth
image and resvg 1x at least test_realworld.OUTLIER_MARGIN_DB (10) farther from it.
Otherwise its row and truth image are removed and it is printed as not listed. The reason
column comes from REASONS below.

Needs resvg_py (the dev extra) and the shared corpus. Renders one case at a time.
"""
from __future__ import annotations

import csv
import io
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent)]

import conformance as conf  # noqa: E402
import test_realworld as rw  # noqa: E402

K = 16  # supersampling factor per axis
COLUMNS = ["name", "reason", "resvg_1x_vs_truth_db", "vecfit_4x4_vs_resvg_db",
           "vecfit_4x4_vs_truth_db", "vecfit_32x32_vs_truth_db"]

# The candidates (the cases that failed against resvg but pass against the truth image) and
# why resvg 1x misses the truth image, per case, from the diagnosis of the failing cases
# (tiny-skia's rasterizer emulated on vecfit's render, one mechanism at a time, scored
# against resvg 1x at 4x4 samples):
#   hairlines: the file has strokes narrower than 1 device px, and drawing them as resvg
#     does (1 px wide, alpha x width) raises the score by 0.8-5.3 dB; removing those strokes
#     from the file cuts resvg's error against the truth image by 16-91%.
#   conflation: drawing each shape alone and compositing the coverages per pixel, as resvg
#     does, raises the score by >= 1.8 dB (shapes abut: the pixels on edges shared by two
#     shapes hold 39-100% of the error).
#   edge quantisation: the case still fails with the above emulated; what is left is the
#     quarter-pixel coverage of resvg's fill edges (vertical edge at x + f: alpha
#     1 - floor(4 f) / 4; slanted edges in steps of 16/255), on logos without shared edges
#     or sub-pixel strokes, or on very fine detail (flags-055).
# Fill-edge quantisation is present in every case; it is named only where it is what is left.
REASONS = {
    "devicon-000": "conflation",
    "flags-001": "hairlines + conflation",
    "flags-011": "hairlines",
    "flags-012": "hairlines",
    "flags-023": "hairlines + conflation",
    "flags-028": "hairlines",
    "flags-029": "hairlines",
    "flags-035": "hairlines",
    "flags-037": "conflation",
    "flags-048": "hairlines",
    "flags-055": "edge quantisation",
    "logos-001": "conflation",
    "logos-004": "conflation",
    "logos-030": "edge quantisation",
    "logos-037": "edge quantisation",
    "logos-040": "conflation",
    "logos-061": "conflation + edge quantisation",
    "logos-066": "edge quantisation",
    "logos-075": "edge quantisation",
    "logos-076": "conflation",
    "logos-045": "edge quantisation",
    "logos-078": "edge quantisation",
    "noto-emoji-084": "conflation",
    "vscode-icons-054": "conflation",
    "vscode-icons-068": "edge quantisation",
}


def truth_image(case: conf.Case) -> np.ndarray:
    """resvg at K x the size, box-averaged over premultiplied RGBA: 8-bit straight RGBA."""
    import resvg_py
    from PIL import Image

    png = bytes(resvg_py.svg_to_bytes(svg_path=str(case.svg), width=case.width * K, height=case.height * K))
    with Image.open(io.BytesIO(png)) as im:
        big = np.asarray(im.convert("RGBA"), dtype=np.float32) / 255.0
    assert big.shape[:2] == (case.height * K, case.width * K), big.shape
    big[..., :3] *= big[..., 3:4]
    mean = big.reshape(case.height, K, case.width, K, 4).mean(axis=(1, 3))
    alpha = mean[..., 3:4]
    straight = np.where(alpha > 0, mean[..., :3] / np.maximum(alpha, 1e-12), 0.0)
    out = np.concatenate([np.clip(straight, 0, 1), alpha], axis=-1)
    return np.floor(out * 255 + 0.5).astype(np.uint8)


def measure(case: conf.Case, truth: Path) -> dict[str, str]:
    a4, error = rw.render(case, samples=4)
    assert error is None, error
    a32, error = rw.render(case, samples=32)
    assert error is None, error
    resvg = conf.load_png(case.png)
    db = {
        "resvg_1x_vs_truth_db": rw.compare(resvg, None, truth)[0],
        "vecfit_4x4_vs_resvg_db": rw.compare(a4, None, case.png)[0],
        "vecfit_4x4_vs_truth_db": rw.compare(a4, None, truth)[0],
        "vecfit_32x32_vs_truth_db": rw.compare(a32, None, truth)[0],
    }
    return {k: f"{v:.2f}" for k, v in db.items()}


def main(names: list[str]) -> None:
    from PIL import Image

    cases = {case.name: case for case in rw.load_cases()}
    rows = rw.load_deviations()
    names = names or sorted(REASONS)
    rw.TRUTH.mkdir(exist_ok=True)
    print("\t".join(COLUMNS), flush=True)
    for name in names:
        case = cases[name]
        truth = rw.TRUTH / f"{name}.png"
        Image.fromarray(truth_image(case), "RGBA").save(truth, optimize=True)
        row = {"name": name, "reason": REASONS.get(name, rows.get(name, {}).get("reason", "")),
               **measure(case, truth)}
        converged = float(row["vecfit_32x32_vs_truth_db"])
        listed = (converged >= rw.CONVERGED_DB
                  and float(row["resvg_1x_vs_truth_db"]) <= converged - rw.OUTLIER_MARGIN_DB)
        if listed:
            rows[name] = row
        else:
            rows.pop(name, None)
            truth.unlink()
        print("\t".join(row[c] for c in COLUMNS) + ("" if listed else "\t(not listed: resvg 1x is not "
              "the outlier)"), flush=True)
    with open(rw.DEVIATIONS, "w", newline="") as f:
        w = csv.DictWriter(f, COLUMNS, delimiter="\t", lineterminator="\n")
        w.writeheader()
        for name in sorted(rows):
            w.writerow({c: rows[name][c] for c in COLUMNS})


if __name__ == "__main__":
    main(sys.argv[1:])
