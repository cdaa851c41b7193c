"""The paint job: random strokes or shapes (vecfit.initial.strokes) fitted to a target with the
loop of `vecfit refine`, with re-seeding and optional frames."""
from __future__ import annotations

from vecfit.initial.strokes import PaintSettings, Reseeder, initial_document
from vecfit.io.frames import FrameSaver

from .config import settings_of
from .fit import fit_and_write, generated_scene, load_target
from .protocol import Inputs, Outputs


def run(inputs: Inputs, config: dict, outputs: Outputs, progress=None) -> dict:
    """`vecfit paint`: random strokes or shapes fitted to inputs.image; writes SVG, report
    and comparison (and frames into outputs.frames, when given)."""
    inputs.need("paint", "image")
    target_path, frames = inputs.name("image"), outputs.frames
    outputs.check_against(inputs)
    target, orientation = load_target(inputs.image, return_orientation=True)
    settings = settings_of(PaintSettings, config["paint"], seed=config["optimize"]["seed"])
    reseeder = Reseeder(settings, config["optimize"]["iterations"])
    hooks = [reseeder]
    saver = None
    if frames is not None:
        saver = FrameSaver(frames, settings.frames_every)
        hooks.append(saver)
    document = initial_document(target, settings)
    scene = generated_scene(document)

    def frames_entry():  # called when the report is made, after the last frame
        if saver is None:
            return None
        gif = saver.finish()
        return {"folder": str(frames), "count": len(saver.files), "gif": str(gif) if gif else None}

    return fit_and_write(scene, document, target, config, outputs, progress, hooks=hooks, generated=True,
                         inputs={"command": "paint", "target": str(target_path), "orientation": orientation,
                                 "paint": lambda: {"kind": settings.kind, "paths": settings.paths,
                                                   "reseeded": reseeder.reseeded,
                                                   "reseed_history": reseeder.history},
                                 "frames": frames_entry})
