"""What a batch run shows while it works: an overall progress bar on stderr and one line
per finished image."""
from __future__ import annotations

import math
import sys

import click

from .plan import DONE, INTERRUPTED, SKIPPED


def outcome_line(row: dict) -> str:
    """One image's outcome in a line: status, PSNR before -> after, seconds or reason."""
    text = f"{row['file']}: {row['status']}"
    if row["status"] in (DONE, SKIPPED, INTERRUPTED) and row.get("psnr_after") is not None:
        a, b = row.get("psnr_before"), row["psnr_after"]

        def db(v):
            return "inf" if v is not None and math.isinf(v) else f"{v:.2f}" if v is not None else "?"
        text += f", PSNR {db(a)} -> {db(b)} dB"
    if row.get("seconds") is not None and row["status"] != SKIPPED:
        text += f" ({row['seconds']:.2f} s)"
    if row.get("reason"):
        text += f": {row['reason']}"
    return text


def _isatty(f) -> bool:
    try:
        return f.isatty()
    except (AttributeError, ValueError):
        return False


class Progress:
    """Reporter of a batch run: ``start(total)``, ``row(row)`` per image, ``finish()``.
    Quiet: nothing. The bar is drawn only when stderr is a terminal; the lines are
    always written."""

    def __init__(self, quiet: bool = False, file=None):
        self.quiet = quiet
        self.file = file or sys.stderr
        self.bar = None
        self.done = 0
        self.total = 0

    def start(self, total: int) -> None:
        self.total = total
        if self.quiet or total == 0 or not _isatty(self.file):
            return  # no bar in a log: the lines say it all
        self.bar = click.progressbar(length=total, label="batch", file=self.file, show_pos=True,
                                     show_eta=True)
        self.bar.__enter__()

    def row(self, row: dict) -> None:
        self.done += 1
        if self.quiet:
            return
        if self.bar is not None:  # the line goes above the bar: clear the bar's line first
            self.file.write("\r\033[K")
        click.echo(f"[{self.done}/{self.total}] {outcome_line(row)}", file=self.file)
        if self.bar is not None:
            self.bar.update(1)

    def finish(self) -> None:
        if self.bar is not None:
            self.bar.__exit__(None, None, None)
            self.bar = None
