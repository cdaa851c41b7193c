"""`python -m vecfit ...` and the `vecfit` script run the vecfit command line."""
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
    main(prog_name="vecfit")


if __name__ == "__main__":
    run()
