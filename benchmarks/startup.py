"""Start-up: how long the command takes to answer when it has little to do, and whether it
imported torch (over a second of start-up by itself). The commands run byte-compiled, as
a user's install has them (common.user_environment).

    python benchmarks/startup.py [--repeats 7]

Each row runs the command in a fresh process `--repeats` times and gives the median wall
time, also in R, the machine unit measured first (benchmarks/machine.py); `import numpy`
and `import torch` alone are the yardsticks (everything imports numpy), and resvg's
render of tiger as a command (a `python -c` around resvg_py) is the one to beat for
`vecfit render`. "torch" says whether the command's process imported it (checked by
running the command line's main in-process, in a fresh interpreter, and looking at
sys.modules).

    python benchmarks/startup.py --alternate 11 [--baseline DIR]

times `vecfit render` of tiger and resvg's command alternated, 11 rounds, in shuffled order
each round (on a shared machine, a ratio is only worth what was measured in one run): the
medians and the ratio of the render's to resvg's. --baseline adds the same render by
another checkout (DIR, a tree with its vecfit/ and cli/ in place, run with PYTHONPATH=DIR
and byte-compiled as this one is), to compare commits.
"""
from __future__ import annotations

import argparse
import compileall
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from machine import in_r, machine_unit  # (first: it sets RAYON_NUM_THREADS for resvg_py)
import resvg_py
from common import SHARED, user_environment

ROOT = Path(__file__).resolve().parents[1]
EMOJI = SHARED / "realworld" / "cases" / "noto-emoji-000.svg"


def wall(argv: list[str], repeats: int) -> float:
    times, env = [], user_environment()
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run(argv, capture_output=True, check=False, env=env)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def imports_torch(args: list[str]) -> bool:
    code = ("import sys\nfrom vecfit.cli.commands import main\n"
            f"sys.argv = ['vecfit', *{args!r}]\n"
            "try:\n    main()\nexcept SystemExit:\n    pass\nprint('torch' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    return out.stdout.split()[-1:] == ["True"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--alternate", type=int, metavar="ROUNDS",
                    help="Only `vecfit render` of tiger against resvg's command, alternated.")
    ap.add_argument("--baseline", type=Path, help="With --alternate: also this checkout's render.")
    args = ap.parse_args()
    if args.alternate:
        alternate(args.alternate, args.baseline)
        return
    tiger = str(ROOT / "examples" / "tiger.svg")
    emoji = Path(tempfile.mkdtemp()) / "emoji.png"  # a 512-px emoji as `trace --no-refine` gets it
    emoji.write_bytes(bytes(resvg_py.svg_to_bytes(svg_path=str(EMOJI), width=512)))
    traced = str(emoji.with_suffix(".svg"))
    small = str(ROOT / "tests" / "oracles" / "golden" / "caps.svg")
    tiger_png = str(emoji.with_name("tiger.png"))
    rows = [("import numpy", [sys.executable, "-c", "import numpy"], None),
            ("import torch", [sys.executable, "-c", "import torch"], None),
            ("vecfit --version", [sys.executable, "-m", "vecfit", "--version"], ["--version"]),
            ("vecfit info (1 shape)", [sys.executable, "-m", "vecfit", "info", small], ["info", small]),
            ("vecfit info tiger.svg", [sys.executable, "-m", "vecfit", "info", tiger], ["info", tiger]),
            ("vecfit trace emoji.png --no-refine (512 px)",
             [sys.executable, "-m", "vecfit", "trace", str(emoji), "--no-refine", "-q", "-o", traced],
             ["trace", str(emoji), "--no-refine", "-q", "-o", traced]),
            ("vecfit render tiger.svg (495 px)", [sys.executable, "-m", "vecfit", "render", tiger, "-o", tiger_png],
             ["render", tiger, "-o", tiger_png]),
            ("resvg_py render tiger.svg (python -c)",
             [sys.executable, "-c", f"import resvg_py; open({tiger_png!r}, 'wb').write(bytes("
                                    f"resvg_py.svg_to_bytes(svg_path={tiger!r})))"], None)]
    unit = machine_unit()
    print(f"machine unit R = {unit:.4f} s (benchmarks/machine.py)\n")
    print(f"| command | median wall ({args.repeats} runs) | imports torch |")
    print("|---|---|---|")
    for label, argv, cli in rows:
        torch = "" if cli is None else ("yes" if imports_torch(cli) else "no")
        print(f"| {label} | {in_r(wall(argv, args.repeats), unit)} | {torch} |", flush=True)


def alternate(rounds: int, baseline: Path | None) -> None:
    """`vecfit render` of tiger (this checkout's; the baseline's) and resvg's command in
    shuffled order each round, from a folder outside either checkout (so that PYTHONPATH
    decides which vecfit runs): medians and the render's ratio to resvg's."""
    tiger, out = str(ROOT / "examples" / "tiger.svg"), Path(tempfile.mkdtemp())
    env = user_environment()
    runs = {"vecfit render tiger.svg": ([sys.executable, "-m", "vecfit", "render", tiger, "-o", str(out / "new.png")], env),
            "resvg_py render tiger.svg": ([sys.executable, "-c", f"import resvg_py; open({str(out / 'r.png')!r}, 'wb')"
                                           f".write(bytes(resvg_py.svg_to_bytes(svg_path={tiger!r})))"], env)}
    if baseline is not None:
        for folder in ("vecfit", "cli"):
            if (baseline / folder).is_dir():
                compileall.compile_dir(str(baseline / folder), quiet=1)
        runs["baseline's vecfit render"] = ([sys.executable, "-m", "vecfit", "render", tiger, "-o", str(out / "old.png")],
                                            dict(env, PYTHONPATH=str(baseline.resolve())))
    times = {label: [] for label in runs}
    for r in range(rounds):
        order = list(runs)
        random.Random(r).shuffle(order)
        for label in order:
            argv, run_env = runs[label]
            start = time.perf_counter()
            subprocess.run(argv, capture_output=True, check=True, env=run_env, cwd=out)
            times[label].append(time.perf_counter() - start)
    resvg = statistics.median(times["resvg_py render tiger.svg"])
    print(f"{rounds} rounds alternated, load {os.getloadavg()[0]:.1f}\n")
    print("| command | median wall | x resvg_py's |\n|---|---|---|")
    for label, values in times.items():
        print(f"| {label} | {statistics.median(values):.3f} s | {statistics.median(values) / resvg:.2f} |")


if __name__ == "__main__":
    main()
