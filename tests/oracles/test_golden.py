"""Golden images kept in the repository: every tests/oracles/golden/NAME.svg (one rendering feature
each, named in the file's comment) rendered by vecfit's public API must match NAME.png,
resvg's rendering of it (made by tests/oracles/golden/make_references.py). Needs nothing outside
the repository, so a fresh clone checks rendering against a trusted renderer even
without the shared conformance corpus.

Scored as the conformance corpus is (conformance.run_case): Monte Carlo 4x4 samples, box
filter, at the reference's size, quantised to 8 bits as a PNG would hold it; a case passes
at PSNR >= 35 dB both composited over white and on alpha alone. The same bar, because it
separates the two kinds of difference here too: resvg and vecfit anti-alias differently
(resvg also flattens curves and approximates strokes' offsets), so edge pixels differ by a
few levels, which leaves these cases at 36.6 dB and above; a wrong feature (a cap, a fill
rule, a gradient stop, a miter limit) changes whole runs of pixels and scores 17-28 dB on
a channel (tests/oracles/golden/README.md gives the measurements and how the cases avoid resvg's
approximations). Alpha is scored on its own so that an error hidden by compositing over
white (colour where the canvas should be clear) still counts. A failure saves expected |
difference | actual in tests/failures/golden/. A feature vecfit gets wrong stays listed,
as an expected failure with its reason (KNOWN_BUGS).
"""
from __future__ import annotations

import warnings
from pathlib import Path

import pytest
from PIL import Image

import conformance as conf

GOLDEN = Path(__file__).resolve().parent / "golden"
FAILURES = conf.ALL_FAILURES / "golden"
SVGS = sorted(GOLDEN.glob("*.svg"))

# name -> reason, for a feature vecfit gets wrong (checked as xfail(strict=True)).
KNOWN_BUGS: dict[str, str] = {}


def params() -> list:
    return [pytest.param(svg, id=svg.stem,
                         marks=[pytest.mark.xfail(strict=True, reason=KNOWN_BUGS[svg.stem])]
                         if svg.stem in KNOWN_BUGS else [])
            for svg in SVGS]


def test_cases_present():
    assert len(SVGS) >= 20
    assert not set(KNOWN_BUGS) - {s.stem for s in SVGS}
    for svg in SVGS:
        assert svg.with_suffix(".png").exists(), \
            f"{svg.name} has no reference: run tests/oracles/golden/make_references.py {svg.name}"


@pytest.mark.parametrize("svg", params())
def test_golden(svg: Path):
    import vecfit

    # Everything in a golden SVG is meant to be drawn: nothing may be skipped.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        vecfit.load_svg(svg)
    png = svg.with_suffix(".png")
    with Image.open(png) as im:
        width, height = im.size
    case = conf.Case(svg.stem, svg, png, width, height, ["golden"])
    r, actual, expected = conf.run_case(case)
    if not r.passed:
        conf.save_failure(r, actual, expected, FAILURES)
    assert r.error is None, r.error
    assert r.passed, (f"PSNR over white {r.psnr_white:.1f} dB, alpha {r.psnr_alpha:.1f} dB "
                      f"(need {conf.PASS_DB}); see tests/failures/golden/{svg.stem}.png")
