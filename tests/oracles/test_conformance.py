"""Every conformance case renders within PSNR 35 dB of resvg's reference, and at least
97% of them pass; cases listed in known_deviations.tsv are expected to fail (with a
reason)."""
from __future__ import annotations

from pathlib import Path

import pytest

import conformance as conf

if not (conf.CORPUS / "manifest.tsv").exists():
    pytest.skip("the shared conformance corpus is not present", allow_module_level=True)

CASES = conf.load_manifest()
KNOWN = {}
for line in (Path(__file__).with_name("known_deviations.tsv")).read_text().splitlines():
    if line.strip() and not line.startswith("#"):
        name, reason = line.split("\t", 1)
        KNOWN[name] = reason

_results: dict[str, conf.Result] = {}


def result_of(case: conf.Case) -> conf.Result:
    if case.name not in _results:
        result, actual, expected = conf.run_case(case)
        if not result.passed:
            conf.save_failure(result, actual, expected)
        _results[case.name] = result
    return _results[case.name]


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_case(case):
    r = result_of(case)
    if case.name in KNOWN:
        if r.passed:
            pytest.fail(f"listed as a known deviation but passes now: remove it ({KNOWN[case.name]})")
        pytest.xfail(KNOWN[case.name])
    assert r.error is None, r.error
    assert r.passed, (f"PSNR over white {r.psnr_white:.1f} dB, alpha {r.psnr_alpha:.1f} dB "
                      f"(need {conf.PASS_DB}); see tests/failures/conformance/{case.name}.png")


@pytest.mark.slow
def test_pass_rate():
    """At least 97% of all cases pass (known deviations count as failures). Below the bar
    the test fails, unless every failing case is a documented deviation of the reference
    renderer: then it is reported as an expected failure that states the measured rate,
    and it passes again by itself once the rate reaches the bar."""
    results = [result_of(c) for c in CASES]
    table = conf.tag_table(results)
    conf.FAILURES.mkdir(parents=True, exist_ok=True)
    (conf.FAILURES.parent / "conformance-table.txt").write_text(table + "\n")
    failed = [r.case.name for r in results if not r.passed]
    rate = 1 - len(failed) / len(results)
    if rate >= 0.97:
        return
    unexplained = [name for name in failed if name not in KNOWN]
    assert not unexplained, f"pass rate {100 * rate:.1f}% < 97%; not explained: {unexplained}\n{table}"
    pytest.xfail(f"pass rate {100 * rate:.1f}% ({len(results) - len(failed)}/{len(results)}) < 97%: "
                 f"every failure is a documented deviation of the reference (known_deviations.tsv)")
