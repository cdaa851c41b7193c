"""The names a user picks from, each list written once: the command line's choices, the
configs' checks and the modules that act on them read them here. (A module of plain
tuples, so that the command line can read them at start-up without loading the core,
NumPy or torch.)"""

# Anti-aliasing (RenderOptions.mode; the core's Mode, csrc/forward/forward.h): Monte Carlo
# samples, or the analytical prefilter.
MODES = ("mc", "analytic")

# Pixel filters (RenderOptions.filter; the core's FILTER_NAMES, in the order of its enum).
FILTERS = ("box", "tent", "gaussian", "parabolic", "hann")

# Image losses of an optimisation ([optimize] loss; vecfit.fitting.losses implements them).
LOSSES = ("l2", "l1", "ssim", "pyramid")

# Efforts of the optimising commands: the [efforts.NAME] tables of configs/ (normal: the
# file as it is).
EFFORTS = ("quick", "normal", "best")

# The jobs (vecfit.jobs.NAME), which batch --mode runs on each input.
JOBS = ("refine", "trace", "paint", "edit", "retarget")

# Output formats of the optimising commands and batch (vecfit.export).
FORMATS = ("svg", "pdf", "dxf")

# What paint draws ([paint] kind): open cubic strokes, or closed filled shapes.
PAINT_KINDS = ("strokes", "shapes")

# Styles of trace ([trace] style): filled regions, strokes, or both.
STYLES = ("fills", "strokes", "mixed")

# How the written shapes are grouped ([output] group_by): as they are, or one <g> a colour
# (vecfit/svg/layers.py; both spellings).
GROUP_BY = ("none", "colour", "color")

# How the written shapes lie ([output] stacking): over one another, or as cut-outs that
# do not overlap (vecfit/initial/tracer/cutouts.py).
STACKINGS = ("stacked", "cutouts")

# The decimals of written coordinates a user may ask for ([output] precision, --precision):
# 0 to this many (float32 coordinates hold no more; vecfit/svg/precision.py).
MAX_DECIMALS = 6
