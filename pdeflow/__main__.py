"""The ``pdeflow`` program: ``python -m pdeflow`` and the ``pdeflow`` command."""

import gc
import signal
import sys


class EarlySignals:
    """The handler of SIGINT and SIGTERM outside the command's own (before it starts,
    while its modules are imported, and after it ended): it records the signal.
    :func:`pdeflow.interrupts.signals_interrupt` ends the command at once if one came
    before it; one that comes after the command ended changes nothing."""

    def __init__(self) -> None:
        self.came: list[int] = []

    def __call__(self, signum: int, frame: object) -> None:
        self.came.append(signum)


def program() -> None:
    """:func:`pdeflow.cli.main` on the command line's arguments, then exit."""
    early = EarlySignals()
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, early)
    from .cli import main

    code = main()
    # frozen, the objects of numba's compiler and of matplotlib are not walked by the
    # garbage collection at exit, which would otherwise walk them all once more
    # (docs/performance.md, "Cold first run")
    gc.freeze()
    sys.exit(code)


if __name__ == "__main__":
    program()
