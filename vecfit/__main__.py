"""`python -m vecfit ...` and the `vecfit` script run the vecfit command line."""
import gc
import sys

from vecfit.errors import EXIT_INTERRUPTED


def run() -> None:
    # A Ctrl-C while the command line itself is imported (before its own handling is in
    # place; a loaded machine can take most of a second to get there) still ends with
    # "interrupted" and 130, not a traceback and death by SIGINT.
    try:
        from vecfit.cli.commands import main
    except KeyboardInterrupt:
        sys.stderr.write("interrupted\n")
        sys.exit(EXIT_INTERRUPTED)
    try:
        main(prog_name="vecfit")
    finally:
        # The command is done (its files written and closed) and the process ends: the
        # collector need not traverse what is left (NumPy's, click's and the command's
        # objects) in the interpreter's final collections, a tenth of `vecfit render`.
        gc.freeze()


if __name__ == "__main__":
    run()
