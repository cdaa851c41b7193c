"""EXIF orientation: how a stored picture is turned upright. Phones store a photo as the
sensor saw it and say in EXIF (tag 0x0112, values 1-8) how to show it; every image a job
reads is turned upright first, and the report's "orientation" entry says what was done.
A broken EXIF block or an orientation outside 1-8 leaves the picture as stored, with a
warning naming the image and the reason."""
from __future__ import annotations

import warnings

from PIL import Image

ORIENTATION_TAG = 0x0112

# value -> (the transpose that makes the stored picture upright, what the report calls it);
# the EXIF 2.3 table, as PIL.ImageOps.exif_transpose applies it
TRANSPOSES = {
    1: (None, "none"),
    2: (Image.Transpose.FLIP_LEFT_RIGHT, "mirror left-right"),
    3: (Image.Transpose.ROTATE_180, "rotate 180"),
    4: (Image.Transpose.FLIP_TOP_BOTTOM, "mirror top-bottom"),
    5: (Image.Transpose.TRANSPOSE, "transpose (mirror across the top-left diagonal)"),
    6: (Image.Transpose.ROTATE_270, "rotate 90 CW"),
    7: (Image.Transpose.TRANSVERSE, "transverse (mirror across the top-right diagonal)"),
    8: (Image.Transpose.ROTATE_90, "rotate 90 CCW"),
}


def _stored_orientation(im: Image.Image) -> tuple[object, str | None]:
    """(the orientation tag's value, None when absent; why the EXIF cannot be trusted, or
    None). Pillow's EXIF parser raises many kinds of error on bad data and warns on a
    truncated block; JPEG's opener reads the block for its dpi and hides a failure, so the
    raw block is parsed again here."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            raw = im.info.get("exif")
            value = None
            if isinstance(raw, (bytes, bytearray)):
                parsed = Image.Exif()
                parsed.load(bytes(raw))
                value = parsed.get(ORIENTATION_TAG)
            if value is None:  # no EXIF block, or none in it: a TIFF's tags, XMP
                value = im.getexif().get(ORIENTATION_TAG)
        except Exception as e:  # the parser's assorted errors all mean a broken block
            return None, f"the EXIF block cannot be read: {type(e).__name__}: {e}"
    complaints = [w for w in caught if issubclass(w.category, UserWarning)]  # (not deprecations)
    if complaints:
        return value, f"the EXIF block is corrupt: {' '.join(str(complaints[0].message).split())}"
    return value, None


def orientation_of(im: Image.Image, name: str) -> tuple[Image.Transpose | None, dict | None]:
    """The transpose that makes ``im`` upright (None: it is upright as stored) and the
    report's "orientation" entry: None without an orientation tag, else {"exif": value,
    "applied": what was done}, with "ignored": the reason when the tag or the EXIF block is
    unusable (then also a warning naming ``name``: the picture is used as stored)."""
    value, broken = _stored_orientation(im)
    if broken is None and value is None:
        return None, None
    if broken is None and not (isinstance(value, int) and value in TRANSPOSES):
        broken = f"the EXIF orientation is {value!r}, not one of 1-8"
    if broken is not None:
        warnings.warn(f"{name}: EXIF orientation ignored, the image is read as stored ({broken})")
        return None, {"exif": value if isinstance(value, int) else None, "applied": "none", "ignored": broken}
    method, applied = TRANSPOSES[value]
    return method, {"exif": value, "applied": applied}


def upright_rgba(im: Image.Image, name: str) -> tuple[Image.Image, dict | None]:
    """``im`` decoded, as RGBA and upright, and its "orientation" entry (orientation_of).
    Decoded first: a PNG's eXIf chunk may follow its pixels."""
    im.load()
    transpose, orientation = orientation_of(im, name)
    rgba = im.convert("RGBA")
    return (rgba if transpose is None else rgba.transpose(transpose)), orientation
