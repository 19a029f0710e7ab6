"""The ``pdeflow`` program: ``python -m pdeflow`` and the ``pdeflow`` command."""

import gc
import sys

from .cli import main


def program() -> None:
    """:func:`pdeflow.cli.main` on the command line's arguments, then exit. SIGINT and
    SIGTERM that come before the command's own handling, or after it, are recorded
    (:mod:`pdeflow.early_signals`, installed when the package was imported)."""
    code = main()
    # frozen, the objects of numba's compiler and of matplotlib are not walked by the
    # garbage collection at exit, which would otherwise walk them all once more
    # (docs/performance.md, "Cold first run")
    gc.freeze()
    sys.exit(code)


if __name__ == "__main__":
    program()
