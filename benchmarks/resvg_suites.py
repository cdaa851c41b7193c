"""resvg's own test suites (clip paths, masks, simple filters, dashes): the pass rate per suite.

    python benchmarks/resvg_suites.py [-v] [--suite mask ...] [--save DIR]

The cases are those in tests/oracles/resvg_suites (resvg's, without text), scored as
tests/oracles/test_resvg_suites.py does: vecfit's render (MC 4x4, box filter, 8-bit)
against resvg's PNG, PSNR over white, passing at 35 dB. Prints a markdown table per suite;
-v lists each failing case with its PSNR (or error); --save DIR writes, for every case,
DIR/SUITE/NAME.png: resvg's reference | the difference | vecfit's render, over white.
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

from common import ROOT

sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "tests" / "oracles")]
import conformance as conf  # noqa: E402  (shared with the tests)
import resvg_suites as suites  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-v", "--verbose", action="store_true", help="list the failing cases")
    ap.add_argument("--suite", nargs="+", choices=list(suites.SUITES), metavar="NAME",
                    help=f"only these suites ({', '.join(suites.SUITES)})")
    ap.add_argument("--save", type=Path, metavar="DIR",
                    help="write reference | difference | render strips here, one folder a suite")
    args = ap.parse_args()

    start = time.perf_counter()
    results = []
    for case in suites.load_cases(args.suite):
        result, actual, expected = suites.run(case)
        results.append(result)
        if args.save:
            suite, stem = case.name.split("/", 1)
            named = dataclasses.replace(result, case=dataclasses.replace(case, name=stem))
            conf.save_failure(named, actual, expected, args.save / suite)
    seconds = time.perf_counter() - start

    print(suites.table(results))
    print(f"\n{len(results)} cases in {seconds:.1f} s; a case passes at {conf.PASS_DB:g} dB over white")
    if args.verbose:
        print("\nfailing:")
        for line in suites.failing(results):
            print(f"- {line}")


if __name__ == "__main__":
    main()
