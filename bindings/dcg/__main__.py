"""`python -m dcg ...`: see dcg.cli."""

import sys

from .cli import main

# Guarded: Dask's local worker processes are spawned and import this module again.
if __name__ == "__main__":
    sys.exit(main())
