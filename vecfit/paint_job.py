"""The paint job: random strokes or shapes (vecfit.painterly) fitted to a target with the
loop of `vecfit refine`, with re-seeding and optional frames."""
from __future__ import annotations

import dataclasses
import tempfile
import warnings
from pathlib import Path

from .errors import VecfitError
from .painterly import FrameSaver, PaintSettings, Reseeder, initial_svg
from .refine import Outputs, fit, load_target
from .svg.read import load_svg


def paint_settings(table: dict, seed: int) -> PaintSettings:
    known = {f.name for f in dataclasses.fields(PaintSettings)}
    unknown = sorted(set(table) - known)
    if unknown:
        raise VecfitError(f"unknown paint settings: {', '.join(unknown)}")
    settings = PaintSettings(**{**table, "seed": seed})
    settings.check()
    return settings


def paint(target_path, config: dict, outputs: Outputs, progress=None, frames=None) -> dict:
    """`vecfit paint`: writes SVG, report and comparison (and frames into ``frames``)."""
    target_path = Path(target_path)
    outputs.check_against(target_path)
    target = load_target(target_path)
    settings = paint_settings(config["paint"], config["optimize"]["seed"])
    reseeder = Reseeder(settings, config["optimize"]["iterations"])
    hooks = [reseeder]
    saver = None
    if frames is not None:
        saver = FrameSaver(frames, settings.frames_every)
        hooks.append(saver)
    with tempfile.TemporaryDirectory(prefix="vecfit-paint-") as tmp:
        source = Path(tmp) / (target_path.stem + ".paint.svg")
        source.write_text(initial_svg(target, settings), encoding="utf-8")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = load_svg(source)
        gif = {}

        def frames_entry():
            if saver is None:
                return None
            gif["path"] = saver.finish()
            return {"folder": str(frames), "count": len(saver.files),
                    "gif": str(gif["path"]) if gif["path"] else None}

        return fit(scene, source, target, config, outputs, progress, hooks=hooks,
                   inputs={"command": "paint", "target": str(target_path),
                           "paint": lambda: {"kind": settings.kind, "paths": settings.paths,
                                             "reseeded": reseeder.reseeded,
                                             "reseed_history": reseeder.history},
                           "frames": frames_entry})
