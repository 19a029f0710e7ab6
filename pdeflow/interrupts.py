"""Ctrl-C and SIGTERM: end a command with one line that says what was kept, and no
partial or hidden files.

py-pde's controller turns a KeyboardInterrupt during the run into a normal return;
:meth:`pdeflow.simulate.Run.execute` raises :class:`RunInterrupted` (with the time
reached) instead, so that a truncated run is never written out. SIGTERM (``kill``,
``timeout``) would end the process without unwinding, leaving the temporary files of
storage and movies behind: :func:`signals_interrupt` makes it raise KeyboardInterrupt
like Ctrl-C, so the same clean-up runs. While the results are written,
:func:`deferred_signals` holds both signals back (the results are then complete).

A :class:`Session` (one per command, the block of :func:`signals_interrupt`) records
the signals that came and the outputs written (:func:`note_written`), so that the
command's last line tells the truth: nothing written, or every output complete. It also
keeps a Ctrl-C from being lost: a KeyboardInterrupt raised where Python cannot pass it
on (a ``__del__`` or a weakref callback run by the garbage collector: "Exception ignored
in ...") would let the command finish as if nothing had come; :func:`received` still
says it came (:meth:`~pdeflow.simulate.Run.execute` then raises :class:`RunInterrupted`,
the command ends as interrupted).

The compiled stepping loop runs between two tracker interrupts without returning to
Python, where signal handlers run: :class:`SignalCheck` gives the controller an
interrupt about once a wall-clock second (observers do not change the steps, see
:mod:`pdeflow.solvers.outputs`), so that a signal is handled within about a second.
"""

from __future__ import annotations

import signal
import sys
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pde.trackers.base import TrackerBase
from pde.trackers.interrupts import RealtimeInterrupts

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class RunInterrupted(KeyboardInterrupt):
    """A run ended by Ctrl-C or SIGTERM; ``t`` [s] is the simulation time it reached."""

    def __init__(self, message: str, t: float | None = None):
        super().__init__(message)
        self.t = t


@dataclass
class Session:
    """What one command met: the signals that came (numbers) and the outputs it wrote
    (paths, as told by :func:`note_written`)."""

    signals: list[int] = field(default_factory=list)
    written: list[str] = field(default_factory=list)


_ACTIVE: Session | None = None
"""the session of the running :func:`signals_interrupt` block"""


def received() -> bool:
    """Whether SIGINT or SIGTERM came in the current session (even if its
    KeyboardInterrupt was swallowed on the way, or held back)."""
    return _ACTIVE is not None and bool(_ACTIVE.signals)


def note_written(paths: Iterable[str | Path]) -> None:
    """Record outputs that are now complete under their final names."""
    if _ACTIVE is not None:
        _ACTIVE.written.extend(str(p) for p in paths)


def _raise_interrupt(signum: int, frame: Any) -> None:
    if _ACTIVE is not None:
        _ACTIVE.signals.append(signum)
    raise KeyboardInterrupt(signal.Signals(signum).name)


@contextmanager
def signals_interrupt(session: Session | None = None) -> Iterator[Session]:
    """SIGINT and SIGTERM raise KeyboardInterrupt inside the block and are recorded in
    the yielded :class:`Session` (``session``, or a new one)."""
    global _ACTIVE
    session = Session() if session is None else session
    old = {s: signal.getsignal(s) for s in SIGNALS}
    outer, _ACTIVE = _ACTIVE, session
    old_hook = sys.unraisablehook
    for s in SIGNALS:
        signal.signal(s, _raise_interrupt)
    sys.unraisablehook = _unraisable(old_hook)
    try:
        # signals recorded before the command started (pdeflow.early_signals)
        early = [n for h in set(old.values()) for n in getattr(h, "came", ())]
        if early:
            session.signals.extend(early)
            raise KeyboardInterrupt(signal.Signals(early[0]).name)
        yield session
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)
        sys.unraisablehook = old_hook
        _ACTIVE = outer


def _unraisable(hook: Any) -> Any:
    """``sys.unraisablehook`` that leaves out a KeyboardInterrupt (recorded in the
    session, the command ends as interrupted) and passes the rest to ``hook``."""

    def unraisable(info: Any) -> None:
        if not isinstance(info.exc_value, KeyboardInterrupt):
            hook(info)

    return unraisable


@contextmanager
def deferred_signals() -> Iterator[list[int]]:
    """Hold SIGINT and SIGTERM back inside the block; the yielded list gets the signals
    that came meanwhile, as does the session (the caller then ends, after the block,
    with everything written)."""
    came: list[int] = []

    def hold(signum: int, frame: Any) -> None:
        came.append(signum)
        if _ACTIVE is not None:
            _ACTIVE.signals.append(signum)

    old = {s: signal.getsignal(s) for s in SIGNALS}
    for s in SIGNALS:
        signal.signal(s, hold)
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
