"""Styling: presentation attributes, the ``style`` attribute and ``<style>`` sheets.

The cascade gives each element its *specified* properties (style attribute over CSS rules
over presentation attributes, ``!important`` CSS over everything); ``computed`` then adds
inheritance from the parent's computed properties. Values stay raw strings: each property
is parsed where it is used, with that property's rule for invalid values.
"""
from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass
from itertools import accumulate, repeat
from operator import itemgetter

from .dom import local_name

# Properties that inherit (SVG 1.1 property table), limited to those the reader looks at.
INHERITED = frozenset({
    "fill", "fill-opacity", "fill-rule", "stroke", "stroke-width", "stroke-opacity",
    "stroke-linecap", "stroke-linejoin", "stroke-miterlimit", "stroke-dasharray",
    "stroke-dashoffset", "color", "visibility", "marker-start", "marker-mid", "marker-end",
    "clip-rule", "color-interpolation-filters",
})
NOT_INHERITED = frozenset({
    "opacity", "display", "stop-color", "stop-opacity", "clip-path", "mask", "filter",
    "overflow", "mask-type", "flood-color", "flood-opacity", "mix-blend-mode", "isolation",
})
PROPERTIES = INHERITED | NOT_INHERITED

_SIMPLE_SELECTOR = re.compile(r"(\*|[A-Za-z_][\w-]*)?((?:[.#][A-Za-z_\-][\w-]*)*)$")
_PART = re.compile(r"[.#][\w-]+")


def without_comments(text: str) -> str:
    """``text`` without its ``/* comments */``. (Found with str.find: the pattern
    "/\\*.*?\\*/" scanned to the end from every unclosed "/*", quadratic.)"""
    parts, i = [], 0
    while (start := text.find("/*", i)) >= 0:
        end = text.find("*/", start + 2)
        if end < 0:
            break  # unclosed, and so is every "/*" after it
        parts.append(text[i:start])
        i = end + 2
    parts.append(text[i:])
    return "".join(parts)


def parse_declarations(text: str) -> list[tuple[str, str, bool]]:
    """``a: b; c: d !important`` -> [(name, value, important)], names lowercased."""
    out = []
    for item in without_comments(text or "").split(";"):
        name, sep, value = item.partition(":")
        if not sep:
            continue
        value = value.strip()
        important = value.lower().endswith("!important")
        if important:
            value = value[: -len("!important")].strip()
        name = name.strip().lower()
        if name == "marker":  # shorthand for the three marker properties
            out += [(f"marker-{k}", value, important) for k in ("start", "mid", "end")]
        elif name and value:
            out.append((name, value, important))
    return out


@dataclass
class _Rule:
    tag: str | None
    ids: tuple[str, ...]
    classes: tuple[str, ...]
    specificity: tuple[int, int, int, int]  # (important, ids, classes, tags), then order
    order: int
    declarations: list[tuple[str, str]]

    def matches(self, tag: str, element_id: str | None, classes: set[str]) -> bool:
        return ((self.tag is None or self.tag == tag)
                and all(i == element_id for i in self.ids)
                and all(c in classes for c in self.classes))


class StyleSheet:
    """Rules of all ``<style>`` elements, with simple selectors only: ``tag``, ``*``,
    ``.class``, ``#id``, their compounds (``rect.a.b``) and comma lists. Other selectors
    are reported through ``unsupported``."""

    def __init__(self):
        self.rules: list[_Rule] = []
        self.unsupported: list[str] = []
        self._index: dict[tuple, list[tuple[int, _Rule]]] | None = None  # made on the first lookup

    def add(self, css: str) -> None:
        css = without_comments(css)
        for prelude, body in _blocks(css):
            if prelude.startswith("@"):
                self.unsupported.append(prelude.split()[0])  # @media, @font-face, ...
                continue
            # (only properties the reader looks at: every element gets each matching rule's)
            decls = [d for d in parse_declarations(body) if d[0] in PROPERTIES]
            # A selector repeated in one prelude makes its rule once, at its last place (an
            # earlier repeat is wholly overridden), and is reported where it first stands.
            selectors = [s.strip() for s in prelude.split(",")]
            last = {s: i for i, s in enumerate(selectors)}
            first = {s: i for i, s in reversed(list(enumerate(selectors)))}
            for i in sorted({*first.values(), *last.values()}):
                self._add_selector(selectors[i], decls if last[selectors[i]] == i else [])
        self._index = None

    def _add_selector(self, selector: str, decls) -> None:
        m = _SIMPLE_SELECTOR.match(selector)
        if not selector or not m:
            self.unsupported.append(selector)
            return
        if not decls:
            return
        tag = None if m.group(1) in (None, "*") else m.group(1)
        parts = _PART.findall(m.group(2))
        ids = tuple(p[1:] for p in parts if p[0] == "#")
        classes = tuple(p[1:] for p in parts if p[0] == ".")
        for important in (False, True):
            chosen = [(n, v) for n, v, imp in decls if imp == important]
            if chosen:
                self.rules.append(_Rule(tag, ids, classes,
                                        (int(important), len(ids), len(classes), int(tag is not None)),
                                        len(self.rules), chosen))

    def _make_index(self) -> None:
        """Sorts the rules (applied in order, later ones take precedence), drops each
        declaration that a later rule of the same selector overrides (that rule matches
        wherever this one does), and files every rule under one key that each element it
        matches has: its first id, else its least used class, else its tag, else "any".
        (Each element had checked every rule: 5,000 rules and 2,000 elements took seconds.)"""
        self.rules.sort(key=lambda r: (r.specificity, r.order))
        later: dict[tuple, set[str]] = {}  # selector -> properties set by its later rules
        for rule in reversed(self.rules):
            names = later.setdefault((rule.tag, rule.ids, rule.classes, rule.specificity[0]), set())
            kept = []
            for name, value in reversed(rule.declarations):
                if name not in names:
                    names.add(name)
                    kept.append((name, value))
            rule.declarations = kept[::-1]
        uses = Counter(c for rule in self.rules for c in rule.classes)
        self._index = {}
        for position, rule in enumerate(self.rules):
            if not rule.declarations:
                continue
            key = (("id", rule.ids[0]) if rule.ids
                   else ("class", min(rule.classes, key=uses.__getitem__)) if rule.classes
                   else ("tag", rule.tag) if rule.tag is not None else ("any",))
            self._index.setdefault(key, []).append((position, rule))

    def declarations_for(self, element, tag: str):
        """(normal, important) declarations of the rules matching ``element``, lowest
        precedence first."""
        if self._index is None:
            self._make_index()
        if not self._index:
            return [], []
        classes = set((element.get("class") or "").split())
        element_id = element.get("id")
        keys = [("any",), ("tag", tag), ("id", element_id)] + [("class", c) for c in classes]
        candidates = sorted((entry for key in keys for entry in self._index.get(key, ())), key=itemgetter(0))
        normal, important = [], []
        for _, rule in candidates:
            if rule.matches(tag, element_id, classes):
                (important if rule.specificity[0] else normal).extend(rule.declarations)
        return normal, important


_BRACE_STEP = {"{": 1, "}": -1}


def _blocks(css: str):
    """(prelude, body) of each top-level ``prelude { body }``, nested braces skipped (an
    unclosed block runs to the end, less its last character)."""
    # depth[k]: braces opened less braces closed up to css[k], counted in C rather than
    # by a Python loop over the characters
    depth = list(accumulate(map(_BRACE_STEP.get, css, repeat(0))))
    i, n = 0, len(css)
    while i < n:
        open_ = css.find("{", i)
        if open_ < 0:
            return
        try:
            j = depth.index(depth[open_] - 1, open_ + 1) + 1  # past the brace that closes it
        except ValueError:
            j = n
        yield css[i:open_].strip(), css[open_ + 1:j - 1]
        i = j


class Cascade:
    """Specified and computed properties of elements."""

    def __init__(self, sheet: StyleSheet):
        self.sheet = sheet

    def specified(self, element) -> dict[str, str]:
        tag = local_name(element.tag)
        props = {name: value.strip() for name, value in element.attrib.items()
                 if name in PROPERTIES}
        normal, important = self.sheet.declarations_for(element, tag)
        props.update(normal)
        props.update((n, v) for n, v, _ in parse_declarations(element.get("style")))
        props.update(important)
        return props

    def computed(self, element, parent: dict[str, str] | None) -> dict[str, str]:
        """Specified properties plus those inherited from ``parent`` (the parent's computed
        properties). ``inherit`` takes the parent's value of any property."""
        parent = parent or {}
        out = {k: v for k, v in parent.items() if k in INHERITED}
        for name, value in self.specified(element).items():
            if value == "inherit":
                if name in parent:
                    out[name] = parent[name]
                else:
                    out.pop(name, None)
            else:
                out[name] = value
        return out
