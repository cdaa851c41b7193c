"""resvg's own test suites for clip paths, clip-rule, masks, feGaussianBlur, feDropShadow,
feOffset, feFlood and dashes (tests/oracles/resvg_suites: the cases without text) render as
resvg draws them: a case passes at PSNR >= 35 dB over white (resvg_suites.py scores them).
The bar is 90% of the cases (the issue's target for these suites). Until clip paths,
masks, filters and dashes are drawn the rate is below it: the test then fails only if the
rate falls below the floor measured when the harness landed, and otherwise reports the rate
as an expected failure. The table per suite and the failing cases are written to
tests/failures/resvg-suites.txt."""
from __future__ import annotations

import pytest

import resvg_suites as suites
from shared_data import FAILURES

# The pass rate when this harness landed (2026-11-26, before clip paths, masks, filters and
# dashes: 18 of 147): a change that loses cases fails the test.
FLOOR = 0.12


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
    if rate < suites.BAR:
        pytest.xfail(f"pass rate {100 * rate:.1f}% ({passed}/{len(results)}), under "
                     f"{100 * suites.BAR:.0f}%; suites under it: {', '.join(low)} "
                     "(clip paths, masks, filters and dashes are not drawn yet)")
