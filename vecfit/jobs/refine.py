"""`vecfit refine`: the user's SVG fitted to a target image (the shared job in
vecfit.jobs.fit)."""
from __future__ import annotations

from pathlib import Path

from .fit import Outputs, check_sizes, fit_and_write, load_scene_to_fit, load_target


def run(target_path, svg_path, config: dict, outputs: Outputs, progress=None) -> dict:
    """`vecfit refine`: load, check and fit; see vecfit.jobs.fit.fit_and_write."""
    target_path, svg_path = Path(target_path), Path(svg_path)
    outputs.check_against(target_path, svg_path)
    target = load_target(target_path)
    scene, document = load_scene_to_fit(svg_path)
    check_sizes(scene, target, svg_path, target_path)
    return fit_and_write(scene, document, target, config, outputs, progress,
               inputs={"command": "refine", "target": str(target_path), "init": str(svg_path)})
