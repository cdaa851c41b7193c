"""The fuzzer's quick run (tests/fuzz/fuzzing.py): 400 cases from seed 0 through render, info,
refine, trace and paint, each ending by the rules (exit 0, 1 or 2 with a clear line; no
traceback, signal, hang, NaN in an SVG, or partial file). About 45 s on 2 cores.
`make fuzz N=5000` runs a long campaign with a summary table."""
from __future__ import annotations

import pytest

from fuzzing import Runner, _seed_files, make_case, run_case

pytestmark = pytest.mark.slow  # over 30 s: `make test-fast` leaves it out

CASES = 400
SEED = 0


def test_fuzz_quick_run():
    seeds = _seed_files()
    runner = Runner()
    failures = []
    try:
        for i in range(CASES):
            case = make_case(SEED, i, seeds)
            problem, _ = run_case(runner, case)
            if problem:
                failures.append(f"case {i} ({' '.join(case.args)}): {problem}")
    finally:
        runner.close()
    assert not failures, "\n".join(failures) + "\n(python tests/fuzz/fuzzing.py -n 1 --start I keeps the files)"
