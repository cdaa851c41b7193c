"""Real SVG files (../shared/realworld: emoji, icons, logos, flags from seven public sets)
render as resvg draws them: a case passes at PSNR >= 35 dB over white, vecfit rendering MC
8x8. The bar (the issue "Real SVG files render as browsers draw them") is 97% of all cases
and 90% within each set and within the tags clip, mask, filter, dasharray and use; the test
fails under it, and under FLOOR, the rate it had last. The table per set and tag is written
to tests/failures/realworld-table.txt.

Known deviations of the reference. resvg (tiny-skia) approximates anti-aliasing at 1x: fill
edges get coverage in quarter-pixel steps, strokes narrower than 1 device px are drawn as
1-px hairlines at reduced alpha (their ink depends on their angle), and shapes that share an
edge are each blended with their own coverage, so the background shows through the seam
(conflation). A case that misses the bar only because of these is listed in
realworld_deviations.tsv, and it also passes when vecfit's render is >= 35 dB from
realworld_truth/NAME.png: resvg's own render of the same file at 16x the size, box-averaged
to the reference size (make_realworld_truth.py). That image uses resvg's parser and geometry
and only takes its anti-aliasing to convergence, so it does not favour vecfit's reading of
the file. The table holds the measurement for each listed case, and a case is listed only
where it shows resvg 1x as the outlier: resvg 1x is under 35 dB from the truth image (it
would miss the bar against it on its own), while vecfit at 32x32 samples agrees with it to
>= 45 dB, so vecfit converges on the image resvg converges on; the rows are checked
(test_known_deviations_are_measured). Where resvg 1x scores >= 35 dB against the truth
image the miss comes from resvg's error and vecfit's sampling noise together (vecfit
converged passes or nearly passes against resvg itself), and the case is not listed. A listed case that passes against resvg directly is counted as passed against
resvg; the table reports the two kinds apart."""
from __future__ import annotations

import csv
import warnings
from pathlib import Path

import numpy as np
import pytest

import conformance as conf
from shared_data import FAILURES, SHARED

CORPUS = SHARED / "realworld"
HERE = Path(__file__).resolve().parent
DEVIATIONS = HERE / "realworld_deviations.tsv"
TRUTH = HERE / "realworld_truth"
BAR, BAR_PER_GROUP = 0.97, 0.90
TAGS_WITH_BAR = ("clip", "mask", "filter", "dasharray", "use")  # (and every set)
# The pass rate now (session 10: clip paths, masks, filters, blend modes, 8x8 samples and
# the known deviations; 367 of 470 when the harness landed): a change that loses cases
# fails the test.
FLOOR = 0.99  # 467 of 470
# A listed deviation must show resvg 1x as the outlier: vecfit converged (32x32 samples;
# the test's 8x8 render has some MC noise) agrees with the truth image to CONVERGED_DB or
# more, and resvg 1x is at least OUTLIER_MARGIN_DB farther from it (ten times the squared
# error), so what separates vecfit from resvg is resvg's anti-aliasing. (A case passes as
# a deviation only where the test's own render is >= 35 dB from the truth image.)
CONVERGED_DB = 45.0
OUTLIER_MARGIN_DB = 10.0

if not (CORPUS / "manifest.tsv").exists():
    pytest.skip("the shared real-world corpus is not present", allow_module_level=True)


def load_cases() -> list[conf.Case]:
    with open(CORPUS / "manifest.tsv", newline="") as f:
        return [conf.Case(row["name"], CORPUS / row["svg"], CORPUS / row["png"], int(row["width"]),
                          int(row["height"]), [t for t in row["tags"].split(",") if t])
                for row in csv.DictReader(f, delimiter="\t")]


def load_deviations() -> dict[str, dict[str, str]]:
    """realworld_deviations.tsv by case name (empty when there is none)."""
    if not DEVIATIONS.exists():
        return {}
    with open(DEVIATIONS, newline="") as f:
        return {row["name"]: row for row in csv.DictReader(f, delimiter="\t")}


# Samples per pixel side of vecfit's render. 8: at 4x4 vecfit's own Monte Carlo noise is
# about 37.6 dB from its converged render on thin-featured logos and flags (logos-078), so a
# score near the bar measured the noise as much as the drawing; from 8x8 to 16x16 the
# scores of the cases near the bar move by 0.2 dB or less (session 10).
SAMPLES = 8


def render(case: conf.Case, samples: int = SAMPLES) -> tuple[np.ndarray | None, str | None]:
    """vecfit's render of the case (MC samples x samples, box filter) as 8-bit straight RGBA
    in [0, 1], or the error that stopped it."""
    import vecfit

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = vecfit.load_svg(case.svg)
        image = vecfit.render(scene, case.width, case.height, samples=samples, mode="mc", filter="box")
    except Exception as e:  # a failure of this case
        return None, f"{type(e).__name__}: {e}"
    return np.floor(np.clip(image.detach().numpy(), 0, 1) * 255 + 0.5).astype(np.float32) / 255.0, None


def compare(actual: np.ndarray | None, error: str | None, png: Path) -> tuple[float, str | None]:
    """PSNR over white of a render against a PNG (0 and the reason where it can't be taken)."""
    if actual is None:
        return 0.0, error
    expected = conf.load_png(png)
    if actual.shape != expected.shape:
        return 0.0, f"size {actual.shape[:2]} against the reference's {expected.shape[:2]}"
    return conf.psnr(conf.over_white(actual), conf.over_white(expected)), None


def score(case: conf.Case, deviations: dict | None = None) -> tuple[float, str | None, float | None]:
    """PSNR over white of vecfit's render (MC 8x8, box filter, as 8-bit) against resvg's, and,
    for a listed known deviation with a truth image, against that image (else None)."""
    actual, error = render(case)
    db, error = compare(actual, error, case.png)
    truth_db = None
    truth = TRUTH / f"{case.name}.png"
    if error is None and case.name in (deviations or {}) and truth.exists():
        truth_db, _ = compare(actual, None, truth)
    return db, error, truth_db


def verdict(db: float, error: str | None, truth_db: float | None) -> str | None:
    """'resvg' (passed against resvg), 'deviation' (passed against the truth image of a listed
    known deviation) or None (failed)."""
    if error is not None:
        return None
    if db >= conf.PASS_DB:
        return "resvg"
    if truth_db is not None and truth_db >= conf.PASS_DB:
        return "deviation"
    return None


def table(rows: list[tuple[conf.Case, str | None]]) -> tuple[str, dict[str, float]]:
    groups: dict[str, list[str | None]] = {}
    for case, how in rows:
        for tag in case.tags:
            groups.setdefault(tag, []).append(how)
    rates = {tag: sum(h is not None for h in v) / len(v) for tag, v in groups.items()}

    def line(name, hows):
        return (f"{name:16s} {sum(h is not None for h in hows):5d} {len(hows):6d} "
                f"{100 * sum(h is not None for h in hows) / len(hows):6.1f}% "
                f"{sum(h == 'resvg' for h in hows):6d} {sum(h == 'deviation' for h in hows):9d}")
    lines = [f"{'set or tag':16s} {'pass':>5s} {'cases':>6s} {'rate':>7s} {'resvg':>6s} {'deviation':>9s}"]
    lines += [line(tag, groups[tag]) for tag in sorted(groups)]
    lines.append(line("ALL", [how for _, how in rows]))
    return "\n".join(lines), rates


@pytest.mark.slow
def test_real_files_render_as_resvg_draws_them():
    deviations = load_deviations()
    scored = [(case, *score(case, deviations)) for case in load_cases()]
    rows = [(case, verdict(db, error, truth_db)) for case, db, error, truth_db in scored]
    text, rates = table(rows)
    passed = sum(how is not None for _, how in rows)
    rate = passed / len(rows)
    failing = sorted(f"{case.name} ({error or f'{db:.1f} dB'}"
                     + (f"; {truth_db:.1f} dB from its truth image" if truth_db is not None else "") + ")"
                     for (case, db, error, truth_db), (_, how) in zip(scored, rows) if how is None)
    known = sorted(f"{case.name} ({db:.1f} dB against resvg, {truth_db:.1f} dB against the truth image; "
                   f"{deviations[case.name]['reason']})"
                   for (case, db, error, truth_db), (_, how) in zip(scored, rows) if how == "deviation")
    FAILURES.mkdir(parents=True, exist_ok=True)
    (FAILURES / "realworld-table.txt").write_text(
        f"{text}\n\nresvg: passed against resvg; deviation: passed as a known deviation "
        f"(realworld_deviations.tsv) against resvg's render at 16x, box-averaged\n\n"
        f"passed as known deviation:\n" + "\n".join(known) + "\n\nfailing:\n" + "\n".join(failing) + "\n")
    assert rate >= FLOOR, f"pass rate {100 * rate:.1f}% fell below the floor {100 * FLOOR:.0f}%\n{text}"
    barred = {case.tags[0] for case, _ in rows} | set(TAGS_WITH_BAR)  # the sets, and those tags
    low = sorted(tag for tag, r in rates.items() if r < BAR_PER_GROUP and tag in barred)
    assert rate >= BAR and not low, (f"pass rate {100 * rate:.1f}% ({passed}/{len(rows)}); under "
                                     f"{100 * BAR_PER_GROUP:.0f}%: {', '.join(low)}\n{text}")


def test_known_deviations_are_measured():
    """Every row of realworld_deviations.tsv names a case of the corpus, has its truth image at
    the case's size, and carries the measurement that makes it a deviation of resvg: resvg 1x
    misses the truth image, and vecfit converged agrees with it."""
    deviations = load_deviations()
    assert deviations, "realworld_deviations.tsv is missing or empty"
    cases = {case.name: case for case in load_cases()}
    bad = []
    for name, row in deviations.items():
        if name not in cases:
            bad.append(f"{name}: not in the corpus")
            continue
        truth = TRUTH / f"{name}.png"
        if not truth.exists():
            bad.append(f"{name}: no {truth.name} in realworld_truth/")
            continue
        if conf.load_png(truth).shape[:2] != (cases[name].height, cases[name].width):
            bad.append(f"{name}: truth image is not {cases[name].width}x{cases[name].height}")
        resvg_db, vecfit32_db = float(row["resvg_1x_vs_truth_db"]), float(row["vecfit_32x32_vs_truth_db"])
        if not resvg_db <= vecfit32_db - OUTLIER_MARGIN_DB:
            bad.append(f"{name}: resvg 1x is {resvg_db} dB from the truth image, not {OUTLIER_MARGIN_DB} dB "
                       f"farther than vecfit converged ({vecfit32_db})")
        if not vecfit32_db >= CONVERGED_DB:
            bad.append(f"{name}: vecfit 32x32 is {vecfit32_db} dB from the truth image (under {CONVERGED_DB})")
        if not row["reason"].strip():
            bad.append(f"{name}: no reason")
    assert not bad, "\n".join(bad)
