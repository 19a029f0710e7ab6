"""A tracker's states at its own times, whatever else watches the run.

py-pde's tracker collection hands a tracker the current state when its next time lies
less than ``atol`` = 1e-8 s after the time reached (``TrackerCollection.handle``). With
several trackers the time reached is often another tracker's: a storage every t_end/100
and a sample every t_end/200 meet at 6 x 0.006 = 0.036000000000000004 s against
12 x 0.003 = 0.036 s. The fv-split solver hands states interpolated at the time asked
for (:mod:`pdeflow.solvers.outputs`), so the state handed early differs from the one at
the tracker's own time in its last bits, and so would a result read from it (a peak, a
stored frame, an erosion series' duration) depending on which observers are attached.

:class:`OwnTimes` wraps a tracker's interrupts so that it can ask for the same time
again; :class:`AtOwnTimes` is the mixin that does so for a state handed early. A run
with no other tracker is handed exactly the same states as before.
"""

from __future__ import annotations

import copy
from typing import Any

from pde.trackers.interrupts import InterruptData, InterruptsBase, parse_interrupt


class OwnTimes(InterruptsBase):
    """py-pde interrupts (any ``InterruptData``: an interval [s], a list of times [s],
    an interrupts object) that give their due time again after :meth:`ask_again`."""

    def __init__(self, interrupts: InterruptData):
        self.inner = parse_interrupt(interrupts)
        self.due: float | None = None
        self.final = False  # the next state handed is the run's final one
        self._repeat = False

    def copy(self) -> OwnTimes:
        twin = copy.copy(self)
        twin.inner = self.inner.copy()
        return twin

    @property
    def dt(self) -> float:  # type: ignore[override]
        """The spacing [s] of the wrapped interrupts (py-pde reads it for logs)."""
        return self.inner.dt

    def initialize(self, t: float) -> float:
        self._repeat = self.final = False
        self.due = self.inner.initialize(t)
        return self.due

    def ask_again(self) -> None:
        """Make the next call of :meth:`next` give the due time again."""
        self._repeat = True

    def next(self, t: float) -> float:
        if self._repeat and self.due is not None:
            self._repeat = False
            return self.due
        self.due = self.inner.next(t)
        return self.due


class AtOwnTimes:
    """Mixin for a py-pde tracker whose ``interrupt`` is :class:`OwnTimes`: its
    ``handle`` starts with ``if self.handed_early(t): return``, and its ``finalize``
    calls :meth:`final_state_next` before handing the final state (which comes at the
    run's end, not at one of the tracker's times)."""

    interrupt: Any

    def handed_early(self, t: float) -> bool:
        """True, and the tracker's time asked for again, when the state at ``t`` [s]
        comes before the tracker's due time (at another tracker's time)."""
        due = getattr(self.interrupt, "due", None)
        if getattr(self.interrupt, "final", False) or due is None or t >= due:
            return False
        self.interrupt.ask_again()
        return True

    def final_state_next(self) -> None:
        """The next state handed is the run's final one: take it whatever its time
        (until the tracker is initialised for another run)."""
        self.interrupt.final = True


__all__ = ["AtOwnTimes", "OwnTimes"]
