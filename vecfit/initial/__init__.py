"""Initial SVGs for the fitting loop: the tracer (trace/) and random strokes or shapes
(strokes.py)."""
