"""The resource limits vecfit enforces, in one place (the README's "Limits and
guarantees" lists them). Inputs past a limit are refused with one line naming it, so that
no input can make a command crash, hang or take all memory.

One limit is the core's alone: groups with opacity nested in each other (each is
composited as a layer) at most MAX_LAYER_DEPTH deep (csrc/scene/layers.h); prepare_scene
refuses deeper nesting, and Python keeps no copy of it."""

# Canvas: the root <svg>'s width and height in px. Beyond 1e7 px coordinates lose
# float32 precision (vecfit.svg.units.LIMIT clamps numbers to the same range); below
# 1e-3 px the scale to any pixel size overflows.
MAX_CANVAS = 1e7
MIN_CANVAS = 1e-3

# A render: width x height pixels (a float RGBA image of that size is already 1 GB).
MAX_PIXELS = 64_000_000

# Elements of an SVG, counting what entities and <use> references expand to: a guard
# against reference and entity bombs (a few kilobytes that expand to millions of elements).
MAX_ELEMENTS = 100_000

# Path segments in a whole scene (arcs count as the cubics they become). Rendering time
# grows with the segments crossing each tile: 10^6 lines across a 64 px canvas ran past
# 40 s; 99,000, filled and stroked, take 2.2 s (mc) to 223 s (analytic: the stroke's
# distances) on 2 cores, the worst case allowed (benchmarks/RESULTS.md).
MAX_SEGMENTS = 100_000

# Elements nested in each other (Python's recursion would fail around 300).
MAX_NESTING = 200

# Clip paths and masks whose content uses clip paths or masks, ... (each level is a layer
# of every render); deeper ones are left out, with a warning.
MAX_EFFECT_NESTING = 16

# Steps run per filter (a filter of thousands would take minutes); a longer filter is left
# out, with a warning.
MAX_STEPS = 64

# Target images for refine, trace and paint (and batch): width x height pixels, checked
# from the header before the pixels are decoded.
MAX_IMAGE_PIXELS = 100_000_000

# Dashes of the dashed strokes (stroke-dasharray) in a whole scene: each dash is at least
# one segment, so a pattern of 0.001 along a long path would make millions (and they come
# on top of MAX_SEGMENTS). Dashes closer together than the stroke is wide overlap their
# neighbours, and the Monte Carlo backward pass's work grows with the product (2 x 10^4
# dashes 0.003 apart under a 6-wide stroke: 5 minutes for the gradients at 64 px), so
# each dash counts max(1, stroke width / pattern length) times (dash_count in
# vecfit.scene.dashes; at this limit a render and its gradients take a few seconds at
# 64 px). A stroke that would take the scene past it is drawn solid, with a warning
# naming the element.
MAX_DASHES = 100_000
