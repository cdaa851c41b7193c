"""Errors that are the user's to fix (the CLI prints them without a traceback), the
warning for inputs read in part, and the exit codes of the commands."""

EXIT_OK = 0             # done
EXIT_FAILED = 1         # a runtime failure (for batch: some image failed; the others are done)
EXIT_USAGE = 2          # bad usage: options, config, missing input folder
EXIT_INTERRUPTED = 130  # Ctrl-C, as a shell reports a process stopped by it


class VecfitError(Exception):
    """A problem with the user's input or options, with a message meant for them."""


class VecfitWarning(UserWarning):
    """Something in the input that vecfit reads only in part or not at all (the SVG reader's
    skips; a dashed stroke drawn solid)."""


class NonFiniteScene(VecfitError):
    """A scene with NaN or infinite values (the optimiser takes it as a failed step)."""


class SvgError(VecfitError):
    """An SVG file that cannot be read: names the file and the reason."""

    def __init__(self, path, reason: str):
        self.path = str(path)
        self.reason = reason
        super().__init__(f"{self.path}: {reason}")
