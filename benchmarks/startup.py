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
"""
from __future__ import annotations

import argparse
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
    args = ap.parse_args()
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


if __name__ == "__main__":
    main()
