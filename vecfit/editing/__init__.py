"""Raster operations behind `vecfit edit` and `vecfit retarget`: the changed region of an
edit, seam carving, and points carried through removed seams; their settings."""
