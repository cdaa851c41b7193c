"""`vecfit refine`: the user's SVG fitted to a target image (the shared job in
vecfit.jobs.fit)."""
from __future__ import annotations

from .fit import check_sizes, fit_and_write, load_scene_to_fit, load_target
from .protocol import Inputs, Outputs


def run(inputs: Inputs, config: dict, outputs: Outputs, progress=None) -> dict:
    """`vecfit refine`: the SVG (inputs.svg) fitted to the image (inputs.image); see
    vecfit.jobs.fit.fit_and_write and the job protocol (protocol.py)."""
    inputs.need("refine", "image", "svg")
    target_path, svg_path = inputs.name("image"), inputs.name("svg")
    outputs.check_against(inputs)
    target, orientation = load_target(inputs.image, return_orientation=True)
    scene, document = load_scene_to_fit(inputs.svg)
    check_sizes(scene, target, svg_path, target_path)
    return fit_and_write(scene, document, target, config, outputs, progress,
               inputs={"command": "refine", "target": str(target_path), "orientation": orientation,
                       "init": str(svg_path)})
