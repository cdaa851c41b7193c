"""What the reader could not honour: collected per kind, reported once per kind."""
from __future__ import annotations

import warnings

from vecfit.errors import VecfitWarning  # (in the lowest layer: the renderer warns too)

# What happens to each kind that is not simply left out of the drawing.
_NOTES = {
    "clip-path": "drawn unclipped",
    "mask": "drawn unmasked",
    "filter": "drawn unfiltered",
    "filter reference": "not drawn, as browsers do",
    "stroke-dasharray": "more dashes than the limit (vecfit.limits.MAX_DASHES), stroked solid",
    "mix-blend-mode": "blended as normal",
    "marker": "markers not drawn",
    "spreadMethod": "drawn as pad",
    "fr": "focal radius taken as 0",
    "out-of-range numbers": "clamped to +-1e7",
    "invalid path data": "drawn up to the error",
    "invalid points data": "drawn up to the error",
    "css-selector": "rules ignored",
    "paint reference": "not a gradient, painted as none",
    "pattern": "painted as none or the fallback colour",
}
_SHOWN = 8  # names listed in a warning


class Skips:
    """kind -> names of the elements (ids, else tag names) it affected, in order."""

    def __init__(self):
        self.kinds: dict[str, dict[str, None]] = {}

    def add(self, kind: str, name: str) -> None:
        self.kinds.setdefault(kind, {})[name] = None

    def as_dict(self) -> dict[str, list[str]]:
        return {kind: list(names) for kind, names in self.kinds.items()}

    def warn(self, path) -> None:
        """One VecfitWarning per kind."""
        for kind, names in self.kinds.items():
            names = list(names)
            shown = ", ".join(names[:_SHOWN])
            if len(names) > _SHOWN:
                shown += f" and {len(names) - _SHOWN} more"
            note = _NOTES.get(kind, "skipped")
            warnings.warn(f"{path}: {kind}, {note}: {shown}", VecfitWarning,
                          stacklevel=3)
