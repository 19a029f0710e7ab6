"""``python -m pdeflow``: the same as the ``pdeflow`` command."""

import sys

from .cli import main

sys.exit(main())
