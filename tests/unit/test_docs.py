"""The documents have one job each, and what they state is checked where it can be: the
README is a manual of at most 200 lines that opens with the two set-up commands the
Makefile has, states the limits of vecfit/limits.py and the name lists of vecfit/names.py,
and quotes no benchmark figures (those are in benchmarks/RESULTS.md, which keeps no
dated history; DESIGN.md quotes none either); every relative link and anchor between
the documents leads somewhere; the configs' comments name files that exist."""
import re
from pathlib import Path

import pytest

from vecfit import limits, names

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")
DOCS = ["README.md", "docs/manual.md", "DESIGN.md", "benchmarks/RESULTS.md", "configs/README.md"]
FIGURE = re.compile(r"(?<![\w.])(\d+(\.\d+)? ?dB\b|\d+\.\d+ s\b|\d+(\.\d+)?–\d+(\.\d+)? s\b)")


def _slug(heading: str) -> str:
    """GitHub's anchor of a heading."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower().replace("`", ""))
    return text.replace(" ", "-")


def _anchors(path: Path) -> set:
    return {_slug(line.lstrip("#")) for line in path.read_text(encoding="utf-8").splitlines()
            if line.startswith("#")}


def test_the_readme_is_a_short_manual_that_opens_with_the_two_commands():
    lines = README.splitlines()
    assert len(lines) <= 200, len(lines)
    opening = "\n".join(lines[:6])
    assert re.search(r"^make demo\b", opening, re.M) and re.search(r"^make test\b", opening, re.M)
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    demo = re.search(r"^demo:.*\n\t(.*)$", makefile, re.M).group(1)
    assert "trace examples/chelsea.png -o out/chelsea.svg" in demo
    assert "examples/chelsea.png" in README and "out/chelsea.svg" in README
    assert re.search(r"^test:.*\n\t\$\(PY\) -m pytest -q$", makefile, re.M)


def test_the_readme_quotes_no_figures():
    assert not FIGURE.search(README), FIGURE.search(README).group(0)
    assert "benchmarks/RESULTS.md" in README


def test_design_quotes_no_figures():
    design = (ROOT / "DESIGN.md").read_text(encoding="utf-8")
    quoted = [m.group(0) for m in FIGURE.finditer(design)
              if not design[max(0, m.start() - 2):m.start()] == "≥ "]  # a pass bar, not a figure
    assert not quoted, quoted


def test_results_keep_no_dated_history():
    results = (ROOT / "benchmarks" / "RESULTS.md").read_text(encoding="utf-8")
    assert not re.search(r"^### Session \d", results, re.M)
    assert "**Before**" not in results and "times, before**" not in results
    assert "not re-run since" not in results


HISTORY_WORDS = re.compile(r"\b(before|after|tried|dropped|session \d+|branch|current)\b", re.I)
DATE = re.compile(r"\b20\d\d-\d\d-\d\d\b")
MEASURED = re.compile(r"\bMeasured 20\d\d-\d\d-\d\d\b")
COMMAND = re.compile(r"`(?:python|make|vecfit|cd benchmarks)\b[^`]*`")


def results_sections(text: str) -> dict:
    """RESULTS.md's `## ` sections by heading."""
    return {part.splitlines()[0]: part for part in re.split(r"^## ", text, flags=re.M)[1:]}


def check_results_hold_current_tables(text: str) -> list:
    """What keeps RESULTS.md from being one current table per benchmark: a `### ` heading
    that dates a measurement or tells its history (before, after, a session, a branch), or a
    benchmark's section (its heading names a script) with no paragraph that says when it was
    "Measured YYYY-MM-DD" and gives the command that reproduces it."""
    problems = []
    for heading, body in results_sections(text).items():
        for sub in re.findall(r"^### (.*)$", body, re.M):
            if DATE.search(sub) or HISTORY_WORDS.search(sub):
                problems.append(f"{heading}: ### {sub}")
        if ".py`" in heading:
            paragraphs = re.split(r"\n\s*\n", body)
            if not any(MEASURED.search(p) and COMMAND.search(p[MEASURED.search(p).start():])
                       for p in paragraphs):
                problems.append(f"{heading}: no 'Measured <date> ... `command`' paragraph")
    return problems


def test_results_hold_one_current_table_per_benchmark():
    results = (ROOT / "benchmarks" / "RESULTS.md").read_text(encoding="utf-8")
    assert len(results_sections(results)) >= 25
    assert check_results_hold_current_tables(results) == []


def test_the_check_finds_dated_history_and_missing_provenance():
    section = ("## Tracing (`trace.py`)\n\nMeasured 2026-11-26, the 2-core machine: "
               "`python benchmarks/trace.py`.\n\n| a | b |\n")
    assert check_results_hold_current_tables(section) == []
    dated = section + "\n### The trace alone (2026-11-26)\n\ntext\n"
    told = section + "\n### Colour counts, before and after\n\ntext\n"
    bare = "## Tracing (`trace.py`)\n\nThe trace, 2026-11-26.\n\n| a | b |\n"
    no_command = "## Tracing (`trace.py`)\n\nMeasured 2026-11-26 on the 2-core machine.\n"
    for text in (dated, told, bare, no_command):
        assert len(check_results_hold_current_tables(text)) == 1, text


@pytest.mark.parametrize("doc", DOCS)
def test_every_relative_link_and_anchor_leads_somewhere(doc):
    path = ROOT / doc
    broken = []
    for target in re.findall(r"\]\(([^)\s]+)\)", path.read_text(encoding="utf-8")):
        if re.match(r"[a-z]+:", target):
            continue
        file, _, anchor = target.partition("#")
        dest = (path.parent / file).resolve() if file else path
        if not dest.exists():
            broken.append(target)
        elif anchor and dest.suffix == ".md" and anchor not in _anchors(dest):
            broken.append(target)
    assert not broken, broken


def test_the_readme_states_the_limits_of_limits_py():
    table = {row.split("|")[1].strip(): row.split("|")[2].strip()
             for row in README.splitlines() if row.startswith("| ") and row.count("|") == 3}

    def row(start):
        (value,) = [v for k, v in table.items() if k.startswith(start)]
        return value

    assert row("a render").startswith(f"{limits.MAX_PIXELS // 1_000_000} million pixels")
    assert row("elements, counting").startswith(f"{limits.MAX_ELEMENTS:,}")
    assert row("path segments").startswith(f"{limits.MAX_SEGMENTS:,}")
    assert row("elements nested").startswith(f"{limits.MAX_NESTING} levels")
    assert row("clip paths and masks").startswith(f"{limits.MAX_EFFECT_NESTING} levels")
    assert row("filter steps").startswith(f"{limits.MAX_STEPS}")
    assert row("dashes").startswith(f"{limits.MAX_DASHES:,}")
    assert row("a target image").startswith(f"{limits.MAX_IMAGE_PIXELS // 1_000_000} million pixels")
    assert "0.001 to 10^7 px" in row("canvas") and limits.MIN_CANVAS == 1e-3 and limits.MAX_CANVAS == 1e7


@pytest.mark.parametrize("name", ["MODES", "FILTERS", "LOSSES", "EFFORTS", "JOBS", "FORMATS", "STYLES",
                                  "PAINT_KINDS"])
def test_the_readme_lists_each_choice_as_the_command_line_has_it(name):
    assert "|".join(getattr(names, name)) in README


def test_the_configs_comments_carry_no_measurements_and_name_files_that_exist():
    for path in sorted((ROOT / "configs").glob("*.toml")):
        comments = "\n".join(line.partition("#")[2] for line in path.read_text(encoding="utf-8").splitlines())
        assert not FIGURE.search(comments), (path.name, FIGURE.search(comments).group(0))
        for file in re.findall(r"[\w./]+\.(?:py|md|toml)\b", comments):
            candidates = [ROOT / file, ROOT / "configs" / file, ROOT / "vecfit" / file,
                          *(ROOT / "vecfit").rglob(Path(file).name)]
            assert any(c.exists() and str(c).endswith(file) for c in candidates), (path.name, file)
