"""Ctrl-C and SIGTERM: end a command with one line and no partial or hidden files.

py-pde's controller turns a KeyboardInterrupt during the run into a normal return;
:meth:`pdeflow.simulate.Run.execute` raises :class:`RunInterrupted` (with the time
reached) instead, so that a truncated run is never written out. SIGTERM (``kill``,
``timeout``) would end the process without unwinding, leaving the temporary files of
storage and movies behind: :func:`signals_interrupt` makes it raise KeyboardInterrupt
like Ctrl-C, so the same clean-up runs. While the results are written,
:func:`deferred_signals` holds both signals back (a result is then complete), and
tells afterwards whether one came.

The compiled stepping loop runs between two tracker interrupts without returning to
Python, where signal handlers run: :class:`SignalCheck` gives the controller an
interrupt about once a wall-clock second (observers do not change the steps, see
:mod:`pdeflow.solvers.outputs`), so that a signal is handled within about a second.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from pde.trackers.base import TrackerBase
from pde.trackers.interrupts import RealtimeInterrupts

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class RunInterrupted(KeyboardInterrupt):
    """A run ended by Ctrl-C or SIGTERM; ``t`` [s] is the simulation time it reached."""

    def __init__(self, message: str, t: float | None = None):
        super().__init__(message)
        self.t = t


def _raise_interrupt(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


@contextmanager
def signals_interrupt() -> Iterator[None]:
    """SIGTERM raises KeyboardInterrupt as SIGINT does, inside the block."""
    old = {s: signal.getsignal(s) for s in SIGNALS}
    signal.signal(signal.SIGTERM, _raise_interrupt)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)


@contextmanager
def deferred_signals() -> Iterator[list[int]]:
    """Hold SIGINT and SIGTERM back inside the block; the yielded list gets the signals
    that came meanwhile (the caller then ends, after the block, with everything
    written)."""
    came: list[int] = []
    old = {s: signal.getsignal(s) for s in SIGNALS}
    for s in SIGNALS:
        signal.signal(s, lambda signum, frame: came.append(signum))
    try:
        yield came
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)


class SignalCheck(TrackerBase):
    """A tracker that does nothing, about once a wall-clock second: the compiled loop
    returns to Python there, where a pending signal is handled."""

    def __init__(self, seconds: float = 1.0):
        super().__init__(interrupts=RealtimeInterrupts(duration=seconds))

    def handle(self, field: Any, t: float) -> None:
        """Nothing to do: the return to Python was the point."""
