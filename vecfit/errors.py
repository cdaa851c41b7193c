"""Errors that are the user's to fix: the CLI prints them without a traceback."""


class VecfitError(Exception):
    """A problem with the user's input or options, with a message meant for them."""


class SvgError(VecfitError):
    """An SVG file that cannot be read: names the file and the reason."""

    def __init__(self, path, reason: str):
        self.path = str(path)
        self.reason = reason
        super().__init__(f"{self.path}: {reason}")
