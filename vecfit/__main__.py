"""`python -m vecfit ...` runs the vecfit command line."""
from vecfit.cli.commands import main

if __name__ == "__main__":
    main(prog_name="vecfit")
