"""resvg's own test suites for clip paths, clip-rule, masks, feGaussianBlur, feDropShadow,
feOffset, feFlood and dashes (tests/oracles/resvg_suites: the cases without text) render as
resvg draws them: a case passes at PSNR >= 35 dB over white (resvg_suites.py scores them).
The bar is 90% of the cases (the issue's target for these suites), and the test fails
under it or under FLOOR, the rate it had last. The 6 of 147 left (session 10): masks of
<image> (2; images are not drawn), feOffset and feFlood under a skew and rotation (2;
resvg takes the filter region's box in pixels and scales offsets by the transform's
scale, vecfit does likewise but their pictures differ there), and dash lengths in em
(2; vecfit takes 1 em as 16 px, the files set a font-size). The table per suite and the
failing cases are written to tests/failures/resvg-suites.txt."""
from __future__ import annotations

import pytest

import resvg_suites as suites
from shared_data import FAILURES

# The pass rate now (session 10: 141 of 147; 18 when the harness landed, before clip
# paths, masks, filters and dashes): a change that loses cases fails the test.
FLOOR = 0.95

@pytest.mark.slow
def test_resvg_suites_render_as_resvg_draws_them():
    results = suites.score(suites.load_cases())
    assert results, "no cases found in tests/oracles/resvg_suites"
    passed = sum(suites.passed(r) for r in results)
    rate = passed / len(results)
    text = suites.table(results)
    FAILURES.mkdir(parents=True, exist_ok=True)
    (FAILURES / "resvg-suites.txt").write_text(
        f"{text}\n\nfailing:\n" + "\n".join(suites.failing(results)) + "\n")
    assert rate >= FLOOR, f"pass rate {100 * rate:.1f}% fell below the floor {100 * FLOOR:.0f}%\n{text}"
    low = [s for s, (n, total) in suites.rates(results).items() if n / total < suites.BAR]
    assert rate >= suites.BAR, (f"pass rate {100 * rate:.1f}% ({passed}/{len(results)}), under "
                                f"{100 * suites.BAR:.0f}%; suites under it: {', '.join(low)}\n{text}")
