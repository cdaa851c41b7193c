"""Initial SVGs for the fitting loop: the tracer (tracer/) and random strokes or shapes
(strokes.py)."""
