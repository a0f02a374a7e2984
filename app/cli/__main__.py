"""`python -m app.cli ...`: the `linpar` command."""
import sys

from app.cli.boundary import main

if __name__ == "__main__":      # not when a worker process (multiprocessing's spawn) imports this module
    sys.exit(main())
