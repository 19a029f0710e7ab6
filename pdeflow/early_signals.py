"""SIGINT and SIGTERM before the command's own handling: recorded, not raised.

The ``pdeflow`` program imports py-pde and numba before its first line runs (the
package's ``__init__``), a second or more; a Ctrl-C meanwhile would end Python with its
own traceback. When this process *is* the program (``python -m pdeflow...``, the
``pdeflow`` script), :func:`install` (called first thing by the package) records the
signals instead; :func:`pdeflow.interrupts.signals_interrupt` then ends the command at
once with its one line, and a signal that comes after the command ended changes
nothing. Imported as a library, pdeflow installs no handler. Standard library only: it
runs before anything else is imported.
"""

from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path


class EarlySignals:
    """The recording handler: ``came`` lists the signals' numbers."""

    def __init__(self) -> None:
        self.came: list[int] = []

    def __call__(self, signum: int, frame: object) -> None:
        self.came.append(signum)


def is_program() -> bool:
    """Whether this process runs the ``pdeflow`` program: ``python -m pdeflow`` (or one
    of its modules; while ``-m`` imports the package, ``sys.argv[0]`` is ``-m``) or the
    ``pdeflow`` console script."""
    argv0 = sys.argv[0] if sys.argv else ""
    return argv0 == "-m" or Path(argv0).name == "pdeflow"


def install() -> None:
    """Record SIGINT and SIGTERM (once; main thread only) if this process is the
    program and nothing else handles them yet (Python's defaults)."""
    if not is_program() or threading.current_thread() is not threading.main_thread():
        return
    current = signal.getsignal(signal.SIGINT)
    if isinstance(current, EarlySignals) or current is not signal.default_int_handler:
        return
    early = EarlySignals()
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, early)
