"""The samples a fit's node joins are judged at (vecfit/jobs/scoring.py, judging_samples):
the cheap 2 x 2 where its noise is small beside the picture's error (a photo's trace), the
report's eval_samples where the noise would be most of it (flat art, line drawings)."""
from __future__ import annotations

import numpy as np

from vecfit.fitting.settings import Settings
from vecfit.jobs.scoring import CHEAP_JUDGE, JUDGE_NOISE_SHARE, judging_samples, rendered_rgb
from vecfit.export import scene_of_svg

WHITE = (1.0, 1.0, 1.0, 1.0)
SIZE = 64
# An edgy scene: stripes and a disc, each edge a pixel's sampling noise at 2 x 2.
SVG = (f'<svg xmlns="http://www.w3.org/2000/svg" width="{SIZE}" height="{SIZE}">'
       + "".join(f'<rect x="{3 + 7 * i}.3" y="2.7" width="3.4" height="40" fill="#203040"/>' for i in range(8))
       + '<circle cx="32.2" cy="48.6" r="12.3" fill="#c04020"/></svg>')


def _scene():
    return scene_of_svg(SVG.encode())[0]


def _settings(**changes):
    return Settings.defaults(threads=1, **changes)


def test_a_picture_far_from_its_target_is_judged_at_2x2():
    # the target is the render plus a mid-grey error everywhere: 2 x 2's noise is tiny beside it
    scene = _scene()
    settings = _settings(eval_samples=4, simplify_samples=0)
    goal = np.clip(rendered_rgb(scene, SIZE, SIZE, settings, WHITE) + 0.2, 0, 1)
    assert judging_samples(scene, SIZE, SIZE, settings, WHITE, goal).samples == CHEAP_JUDGE


def test_a_picture_on_its_target_is_judged_at_eval_samples():
    # the target is the converged render: what 2 x 2 measures is its own noise
    scene = _scene()
    settings = _settings(eval_samples=4, simplify_samples=0)
    goal = rendered_rgb(scene, SIZE, SIZE, _settings(eval_samples=16), WHITE)
    cheap = _settings(eval_samples=CHEAP_JUDGE)
    first = rendered_rgb(scene, SIZE, SIZE, cheap, WHITE)
    noise = 0.5 * float(((rendered_rgb(scene, SIZE, SIZE, cheap, WHITE, 1) - first) ** 2).mean())
    assert noise > JUDGE_NOISE_SHARE * float(((first - goal) ** 2).mean())  # (the case is what it says)
    assert judging_samples(scene, SIZE, SIZE, settings, WHITE, goal).samples == 4


def test_a_setting_or_a_cheap_report_decides_without_a_render():
    scene = _scene()
    goal = np.zeros((SIZE, SIZE, 3))
    assert judging_samples(scene, SIZE, SIZE, _settings(eval_samples=4, simplify_samples=3), WHITE, goal).samples == 3
    assert judging_samples(scene, SIZE, SIZE, _settings(eval_samples=1, simplify_samples=0), WHITE, goal).samples == 1
