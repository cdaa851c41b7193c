"""Local changes to a scene, chosen by the render about each of them.

The corner and ring passes (fillets.py, polygons.py) each have many places to change
(a stroke's corners, its small rings) and a few ways to change each. One render per way,
with every place changed that way at once, tells each place's error in a window about it:
a place takes the way whose window error is a given share of its error as it was, or
less (and below it), and the least. The changes taken are then kept only where the whole picture's error
falls; else the scene goes back as it was.
"""
from __future__ import annotations

from typing import Callable, Hashable, Iterable

import numpy as np


def choose_in_windows(scene, render_rgb, target_rgb: np.ndarray, image: np.ndarray, windows: dict,
                      ways: Iterable, allowed: Callable[[Hashable, object], bool],
                      apply: Callable[[dict], None], restore: Callable[[], None],
                      share: float) -> tuple[dict, np.ndarray]:
    """Each place of ``windows`` (key -> (row slice, column slice) of the image) changed the
    way of ``ways`` whose render leaves at most ``share`` of the place's error in its window
    (and the least), where ``allowed(key, way)``. ``apply(choice)`` puts the scene in the
    state {key: way} asks, from the scene as it was; ``restore()`` puts it back.
    ``image``: the scene's render as it was (``render_rgb(scene)``, RGB like
    ``target_rgb``). Returns the choice kept ({} where none, or where the whole picture
    was not better) and the render of the scene as it is left."""
    base = ((image - target_rgb) ** 2).sum(-1)
    was = {key: float(base[win].sum()) for key, win in windows.items()}
    best = {key: (e, None) for key, e in was.items()}  # (a change must lower the error)
    for way in ways:
        trying = {key: way for key in windows if allowed(key, way)}
        if not trying:
            continue
        apply(trying)
        err = ((render_rgb(scene) - target_rgb) ** 2).sum(-1)
        for key in trying:
            e = float(err[windows[key]].sum())
            if e <= share * was[key] and e < best[key][0]:
                best[key] = (e, way)
    choice = {key: way for key, (_, way) in best.items() if way is not None}
    if choice:
        apply(choice)
        after = render_rgb(scene)
        if ((after - target_rgb) ** 2).mean() < ((image - target_rgb) ** 2).mean():
            return choice, after
    restore()
    return {}, image
