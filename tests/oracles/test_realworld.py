"""Real SVG files (../shared/realworld: emoji, icons, logos, flags from seven public sets)
render as resvg draws them: a case passes at PSNR >= 35 dB over white. The bar is 97% of
all cases and 90% within each set and feature tag (the issue "Real SVG files render as
browsers draw them"). Until clip paths, masks, filters and dashes are drawn the rate is
below it: the test then fails only if the rate falls below the floor measured when the
harness landed, and otherwise reports the rate as an expected failure. The table per set
and tag is written to tests/failures/realworld-table.txt."""
from __future__ import annotations

import csv
import warnings

import numpy as np
import pytest

import conformance as conf
from shared_data import FAILURES, SHARED

CORPUS = SHARED / "realworld"
BAR, BAR_PER_GROUP = 0.97, 0.90
# The pass rate when this harness landed (2026-11-26, before clip paths, masks, filters
# and dashes): a change that loses cases fails the test.
FLOOR = 0.78  # 367 of 470

if not (CORPUS / "manifest.tsv").exists():
    pytest.skip("the shared real-world corpus is not present", allow_module_level=True)


def load_cases() -> list[conf.Case]:
    with open(CORPUS / "manifest.tsv", newline="") as f:
        return [conf.Case(row["name"], CORPUS / row["svg"], CORPUS / row["png"], int(row["width"]),
                          int(row["height"]), [t for t in row["tags"].split(",") if t])
                for row in csv.DictReader(f, delimiter="\t")]


def score(case: conf.Case) -> tuple[float, str | None]:
    """PSNR over white of vecfit's render (MC 4x4, box filter, as 8-bit) against resvg's."""
    import vecfit

    expected = conf.load_png(case.png)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = vecfit.load_svg(case.svg)
        image = vecfit.render(scene, case.width, case.height, samples=4, mode="mc", filter="box")
    except Exception as e:  # a failure of this case
        return 0.0, f"{type(e).__name__}: {e}"
    actual = np.floor(np.clip(image.numpy(), 0, 1) * 255 + 0.5).astype(np.float32) / 255.0
    if actual.shape != expected.shape:
        return 0.0, f"size {actual.shape[:2]} against the reference's {expected.shape[:2]}"
    return conf.psnr(conf.over_white(actual), conf.over_white(expected)), None


def table(rows: list[tuple[conf.Case, float, str | None]]) -> tuple[str, dict[str, float]]:
    groups: dict[str, list[bool]] = {}
    for case, db, error in rows:
        for tag in case.tags:
            groups.setdefault(tag, []).append(error is None and db >= conf.PASS_DB)
    rates = {tag: sum(v) / len(v) for tag, v in groups.items()}
    lines = [f"{'set or tag':16s} {'pass':>5s} {'cases':>6s} {'rate':>7s}"]
    lines += [f"{tag:16s} {sum(groups[tag]):5d} {len(groups[tag]):6d} {100 * rates[tag]:6.1f}%"
              for tag in sorted(groups)]
    return "\n".join(lines), rates


@pytest.mark.slow
def test_real_files_render_as_resvg_draws_them():
    rows = [(case, *score(case)) for case in load_cases()]
    text, rates = table(rows)
    passed = sum(error is None and db >= conf.PASS_DB for _, db, error in rows)
    rate = passed / len(rows)
    failing = sorted(f"{case.name} ({error or f'{db:.1f} dB'})" for case, db, error in rows
                     if not (error is None and db >= conf.PASS_DB))
    FAILURES.mkdir(parents=True, exist_ok=True)
    (FAILURES / "realworld-table.txt").write_text(
        f"{text}\nALL              {passed:5d} {len(rows):6d} {100 * rate:6.1f}%\n\nfailing:\n"
        + "\n".join(failing) + "\n")
    assert rate >= FLOOR, f"pass rate {100 * rate:.1f}% fell below the floor {100 * FLOOR:.0f}%\n{text}"
    low = sorted(tag for tag, r in rates.items() if r < BAR_PER_GROUP)
    if rate < BAR or low:
        pytest.xfail(f"pass rate {100 * rate:.1f}% ({passed}/{len(rows)}); under {100 * BAR_PER_GROUP:.0f}%: "
                     f"{', '.join(low)} (clip paths, masks, filters and dashes are not drawn yet)")
