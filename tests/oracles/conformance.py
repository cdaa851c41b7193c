"""Rendering conformance against the resvg reference corpus in ../shared/conformance.

A case passes when vecfit's render (Monte Carlo, 4x4 samples, box filter, at the case's
size) matches the reference PNG at PSNR >= 35 dB both composited over white and on the
alpha channel alone. test_golden.py scores the golden images kept in the repository with
the same helpers.
"""
from __future__ import annotations

import csv
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from shared_data import CONFORMANCE as CORPUS, FAILURES as ALL_FAILURES
FAILURES = ALL_FAILURES / "conformance"
PASS_DB = 35.0


@dataclass
class Case:
    name: str
    svg: Path
    png: Path
    width: int
    height: int
    tags: list[str]


@dataclass
class Result:
    case: Case
    psnr_white: float
    psnr_alpha: float
    error: str | None = None

    @property
    def passed(self) -> bool:
        return self.error is None and self.psnr_white >= PASS_DB and self.psnr_alpha >= PASS_DB


def load_manifest() -> list[Case]:
    cases = []
    with open(CORPUS / "manifest.tsv", newline="") as f:
        for row in csv.DictReader(f, delimiter="\t"):
            cases.append(Case(row["name"], CORPUS / row["svg"], CORPUS / row["png"],
                              int(row["width"]), int(row["height"]),
                              [t for t in row["tags"].split(",") if t]))
    return cases


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    mse = float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))
    return math.inf if mse == 0 else 10 * math.log10(1.0 / mse)


def over_white(rgba: np.ndarray) -> np.ndarray:
    a = rgba[..., 3:4]
    return rgba[..., :3] * a + (1 - a)


def load_png(path: Path) -> np.ndarray:
    """A PNG as float32 straight RGBA in [0, 1], [H, W, 4]."""
    from PIL import Image

    with Image.open(path) as im:
        return np.asarray(im.convert("RGBA"), dtype=np.float32) / 255.0


def run_case(case: Case) -> tuple[Result, np.ndarray | None, np.ndarray]:
    """Renders the case with vecfit's public API only (load_svg, render) and scores it."""
    import vecfit

    expected = load_png(case.png)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = vecfit.load_svg(case.svg)
        image = vecfit.render(scene, case.width, case.height, samples=4, mode="mc", filter="box")
    except Exception as e:  # recorded as a failure of this case
        return Result(case, 0.0, 0.0, f"{type(e).__name__}: {e}"), None, expected
    # Compare what a PNG would hold: 8-bit straight RGBA.
    levels = np.floor(np.clip(image.detach().cpu().numpy(), 0, 1) * 255 + 0.5)
    actual = levels.astype(np.float32) / 255.0
    return Result(case, psnr(over_white(actual), over_white(expected)),
                  psnr(actual[..., 3], expected[..., 3])), actual, expected


def save_failure(result: Result, actual: np.ndarray | None, expected: np.ndarray,
                 folder: Path = FAILURES) -> Path:
    """expected | difference | actual, composited over white, saved in folder."""
    from PIL import Image

    folder.mkdir(parents=True, exist_ok=True)
    e = over_white(expected)
    a = over_white(actual) if actual is not None else np.zeros_like(e)
    d = 1 - np.clip(np.abs(a - e) * 4, 0, 1)  # amplified, dark where they differ
    strip = np.concatenate([e, d, a], axis=1)
    path = folder / f"{result.case.name}.png"
    Image.fromarray((strip * 255 + 0.5).astype(np.uint8)).save(path)
    return path


def tag_table(results: list[Result]) -> str:
    by_tag: dict[str, list[bool]] = {}
    for r in results:
        for tag in r.case.tags or ["(none)"]:
            by_tag.setdefault(tag, []).append(r.passed)
    lines = [f"{'tag':28s} {'pass':>5s} {'cases':>6s} {'rate':>7s}"]
    for tag in sorted(by_tag):
        v = by_tag[tag]
        lines.append(f"{tag:28s} {sum(v):5d} {len(v):6d} {100 * sum(v) / len(v):6.1f}%")
    n = sum(r.passed for r in results)
    lines.append(f"{'ALL':28s} {n:5d} {len(results):6d} {100 * n / max(1, len(results)):6.1f}%")
    return "\n".join(lines)
