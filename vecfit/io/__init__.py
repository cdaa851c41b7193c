"""Files in and out besides SVG: raster images (atomic writes), reports, comparison
pictures, frames, colour options and the scene summary of `vecfit info`."""
