"""`python -m vecfit ...` runs the vecfit command line."""
from vecfit.cli.main import main

if __name__ == "__main__":
    main(prog_name="vecfit")
