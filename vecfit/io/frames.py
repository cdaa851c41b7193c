"""`vecfit paint --frames`: renders saved during the optimisation, and a GIF of them."""
from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from .compositing import composite
from .files import atomic_write
from .png import to_uint8


class FrameSaver:
    """An optimisation hook that saves every ``every``-th render as a PNG and, at the end
    (``finish``), an animated GIF of them."""

    GIF_MAX = 256  # longest side of the GIF's frames

    def __init__(self, folder, every: int):
        self.folder, self.every = Path(folder), max(1, every)
        self.files: list[Path] = []

    def __call__(self, step) -> None:
        if step.iteration % self.every:
            return
        background = step.target.background
        rgb = to_uint8(composite(step.image.numpy().astype(np.float64),
                                 (1.0, 1.0, 1.0) if background is None else background))
        path = self.folder / f"frame_{step.iteration:05d}.png"
        atomic_write(path, lambda tmp: Image.fromarray(rgb, "RGB").save(tmp, format="PNG"))
        self.files.append(path)

    def finish(self) -> Path | None:
        if not self.files:
            return None
        frames = []
        for f in self.files:
            with Image.open(f) as im:
                im.thumbnail((self.GIF_MAX, self.GIF_MAX))
                frames.append(im.convert("P", palette=Image.ADAPTIVE))
        gif = self.folder / "optimization.gif"
        atomic_write(gif, lambda tmp: frames[0].save(tmp, format="GIF", save_all=True,
                                                     append_images=frames[1:], duration=60, loop=0))
        return gif
