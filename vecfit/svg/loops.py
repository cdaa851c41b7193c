"""Which clip-path and mask references make clip paths or masks loop, found as resvg
finds them, so that which reference of a loop is cut is resvg's choice.

For each <clipPath> (then each <mask>) in document order, the first element in it
(itself included) whose reference leads back to it, directly or through one other
element's subtree, is cut; then it is looked for again. Looked for again from the start
of the document, as resvg does, that scan was quadratic: 1,500 clip paths referring to
themselves (124 KB) took 3.4 s. A cut only takes a reference away, so nothing before the
element just cut can have become a culprit: the scan goes on from that element. And an
element whose subtree holds one referring back is found by a bisection among the
elements that refer to the clip path, by their places in the document, rather than by
walking the subtree for every element that refers to it.
"""
from __future__ import annotations

from bisect import bisect_left

from .dom import local_name
from .effects import func_iri

_KINDS = (("clipPath", "clip-path"), ("mask", "mask"))


def looping_references(root, ids, computed) -> set[tuple[int, str]]:
    """(id of the element, property) of each reference cut; ``ids``: id -> element;
    ``computed``: an element's computed properties."""
    cut: set[tuple[int, str]] = set()
    nodes, first, last = _preorder(root)
    for tag, prop in _KINDS:
        holders = [e for e in nodes if isinstance(e.tag, str) and local_name(e.tag) == tag]
        if holders:
            _cut_loops(holders, prop, nodes, first, last, ids, computed, cut)
    return cut


def _preorder(root):
    """The elements in document order; each one's place in it (by id) and the place of
    the last element of its subtree."""
    nodes, first, last = [], {}, {}
    stack = [(root, False)]
    while stack:
        element, closing = stack.pop()
        if closing:
            last[id(element)] = len(nodes) - 1
            continue
        first[id(element)] = len(nodes)
        nodes.append(element)
        stack.append((element, True))
        stack.extend((child, False) for child in reversed(element))
    return nodes, first, last


def _cut_loops(holders, prop, nodes, first, last, ids, computed, cut) -> None:
    references: dict[int, object] = {}  # id -> the element its ``prop`` names (None: none)

    def target(element):
        key = id(element)
        if key not in references:
            ref = func_iri((computed(element).get(prop) or "").strip()) if isinstance(element.tag, str) else None
            references[key] = ids.get(ref) if ref else None
        return None if (key, prop) in cut else references[key]

    def referring(spans) -> list[int]:
        """Places of the elements within ``spans`` (subtrees, as places) that refer to
        something, each once, in document order."""
        out, reached = [], -1
        for start, stop in sorted(spans):
            for i in range(max(start, reached + 1), stop + 1):
                if target(nodes[i]) is not None:
                    out.append(i)
            reached = max(reached, stop)
        return out

    in_holders = referring((first[id(h)], last[id(h)]) for h in holders)
    links = {id(t): t for i in in_holders if (t := target(nodes[i])) is not None}
    # what refers to each element, from within the subtrees that holders' elements refer to
    pointing: dict[int, list[int]] = {}
    for i in referring((first[key], last[key]) for key in links):
        pointing.setdefault(id(target(nodes[i])), []).append(i)
    skip: dict[tuple[int, int], int] = {}  # (holder, position) -> a later position (past cut ones)

    def first_uncut(holder, entries, i) -> int:
        passed = []
        while i < len(entries) and (id(nodes[entries[i]]), prop) in cut:
            passed.append(i)
            i = skip.get((holder, i), i + 1)
        for p in passed:
            skip[(holder, p)] = i
        return i

    def culprit(child, node):
        link = target(child)
        if link is None:
            return None
        if link is node:
            return child
        entries = pointing.get(id(node), [])
        i = first_uncut(id(node), entries, bisect_left(entries, first[id(link)]))
        return nodes[entries[i]] if i < len(entries) and entries[i] <= last[id(link)] else None

    for node in holders:
        start = bisect_left(in_holders, first[id(node)])
        for i in in_holders[start:bisect_left(in_holders, last[id(node)] + 1)]:
            while (found := culprit(nodes[i], node)) is not None:
                cut.add((id(found), prop))
