"""resvg's own test suites for clip paths, masks, the simple filters and dashes (copied into
resvg_suites/, one folder a suite; its README says from where and which cases): the cases
and their scoring, shared by test_resvg_suites.py and benchmarks/resvg_suites.py.

A case is scored as the real-world corpus is (test_realworld.py): vecfit's render at the
reference PNG's size (load_svg and render, Monte Carlo 4x4, box filter, as 8-bit, through
conformance.run_case) against resvg's PNG, PSNR over white; it passes at conf.PASS_DB. An
exception while loading or rendering fails that case only. The bar is 90% of the cases
(the issue's target for these suites, text left out).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

import conformance as conf

FOLDER = Path(__file__).resolve().parent / "resvg_suites"
# resvg's tests/<category>/<name> folder -> our suite name
SUITES = {
    "clip-path": "masking/clipPath",
    "clip-rule": "masking/clip-rule",
    "mask": "masking/mask",
    "feGaussianBlur": "filters/feGaussianBlur",
    "feDropShadow": "filters/feDropShadow",
    "feOffset": "filters/feOffset",
    "feFlood": "filters/feFlood",
    "stroke-dasharray": "painting/stroke-dasharray",
    "stroke-dashoffset": "painting/stroke-dashoffset",
}
BAR = 0.90


def png_size(path: Path) -> tuple[int, int]:
    from PIL import Image

    with Image.open(path) as im:
        return im.size


def load_cases(suites=None) -> list[conf.Case]:
    """The cases of the named suites (all by default), named suite/file-stem, tagged with
    their suite, at their reference PNG's size."""
    names = list(SUITES) if not suites else list(suites)
    unknown = [s for s in names if s not in SUITES]
    if unknown:
        raise ValueError(f"unknown suites {unknown}; there are {list(SUITES)}")
    cases = []
    for suite in names:
        for svg in sorted((FOLDER / suite).glob("*.svg")):
            png = svg.with_suffix(".png")
            width, height = png_size(png)
            cases.append(conf.Case(f"{suite}/{svg.stem}", svg, png, width, height, [suite]))
    return cases


def passed(result: conf.Result) -> bool:
    """Over white only, as for the real-world files (conf.Result.passed also asks alpha)."""
    return result.error is None and result.psnr_white >= conf.PASS_DB


def run(case: conf.Case) -> tuple[conf.Result, np.ndarray | None, np.ndarray]:
    """conf.run_case, with a render of the wrong size a failure of the case as well."""
    try:
        return conf.run_case(case)
    except Exception as e:  # e.g. shapes that do not broadcast in the PSNR
        return conf.Result(case, 0.0, 0.0, f"{type(e).__name__}: {e}"), None, conf.load_png(case.png)


def score(cases: list[conf.Case]) -> list[conf.Result]:
    return [run(case)[0] for case in cases]


def rates(results: list[conf.Result]) -> dict[str, tuple[int, int]]:
    """suite -> (passed, cases), in SUITES' order."""
    out: dict[str, list[int]] = {}
    for r in results:
        n = out.setdefault(r.case.tags[0], [0, 0])
        n[0] += passed(r)
        n[1] += 1
    return {s: tuple(out[s]) for s in SUITES if s in out}


def table(results: list[conf.Result]) -> str:
    """Markdown: pass, cases and rate per suite, then all of them."""
    lines = ["| suite | pass | cases | rate |", "|---|---:|---:|---:|"]
    for suite, (n, total) in rates(results).items():
        lines.append(f"| {suite} | {n} | {total} | {100 * n / total:.1f}% |")
    n, total = sum(passed(r) for r in results), len(results)
    lines.append(f"| **all** | **{n}** | **{total}** | **{100 * n / max(1, total):.1f}%** |")
    return "\n".join(lines)


def describe(result: conf.Result) -> str:
    """A failing case and why: its PSNR over white, or the error."""
    why = result.error or f"{result.psnr_white:.1f} dB"
    return f"{result.case.name} ({why})"


def failing(results: list[conf.Result]) -> list[str]:
    return [describe(r) for r in results if not passed(r)]
