"""`python -m dcg ...`: see dcg.cli."""

import sys

from .cli import main

sys.exit(main())
