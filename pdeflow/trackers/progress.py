"""py-pde's progress bar for granular runs: fixed simulation-time updates, "at rest".

Example::

    from pdeflow.trackers import ProgressBar
    eq.solve(state, t_range=5, solver="fv-split", tracker=ProgressBar(0.05, label="5.1"))

``eq.solve(...)`` with its default trackers (``"auto"``) shows this bar
(:meth:`pdeflow.models.base.GranularPDE.solve`).
"""

from __future__ import annotations

import math
from typing import Any

from pde.tools.output import get_progress_bar_class
from pde.trackers import ProgressTracker
from pde.trackers.base import InfoDict, TrackerBase

from ..numerics import warmup

_WAITING = {warmup.COLD: "compiling kernels (once per machine)",
            warmup.CACHED: "loading compiled kernels"}
"""what the bar says before the first interval, by :func:`warmup.status`"""


class ProgressBar(ProgressTracker):
    """py-pde's progress bar, updated at fixed *simulation* times (so that a run's
    result does not depend on the wall clock), which says "at rest" and fills up when
    the ``fv-split`` solver ends a run at rest before t_end.

    While the ``fv-split`` kernels are compiled (the first run on a machine) or loaded
    (the first run in a process), the bar says so; its clock and its estimate of the
    remaining time start once the first interval has been computed, so the estimate is
    simulated time per wall time of the run itself. The bar shows the simulated time
    reached of t_end [s] and the rate in simulated seconds per wall second.

    Args:
        interrupts: simulation time between updates [s] (or anything py-pde accepts).
        label: text in front of the bar (e.g. the model).
    """

    def __init__(self, interrupts: Any = 0.05, *, label: str = "", **kwargs: Any):
        super().__init__(interrupts=interrupts, **kwargs)
        self.label = label
        self._clock_started = False

    def initialize(self, field: Any, info: InfoDict | None = None) -> float:
        # py-pde's initialize draws the bar twice before the first update (empty, then
        # "Initializing"): the bar is made here instead, with its label, drawn once
        result = TrackerBase.initialize(self, field, info)
        self._clock_started = False
        solver = (info or {}).get("solver", {}).get("class")
        waiting = ""
        if solver == "FVSplitSolver":
            waiting = _WAITING.get(warmup.status(), "")
        self._waiting = ": ".join(p for p in (self.label, waiting) if p)
        controller = (info or {}).get("controller", {})
        total = controller.get("t_end")
        # the bar counts simulated seconds: its rate is simulated time per wall second
        # (tqdm's default would read "it/s", or "s/it" when slow); the count is the time
        bar_format = (None if total is None else "{l_bar}{bar}| {n:.4g}/{total:.4g} s "
                      "[{elapsed}<{remaining}, {rate_noinv_fmt}{postfix}]")
        self.progress_bar = get_progress_bar_class(self.fancy)(
            total=total, initial=controller.get("t_start", 0), leave=self.leave,
            desc=self._waiting, unit=" s simulated", bar_format=bar_format)
        self._drawn = (self.progress_bar.n, self._waiting)  # tqdm drew it just now
        return result

    def handle(self, field: Any, t: float) -> None:
        # py-pde's handle draws the bar with an empty label, then this one drew it with
        # its own: two draws per update, a flickering label. One draw here.
        bar = self.progress_bar
        bar.n = round(min(t, bar.total) if bar.total else t, self.ndigits)
        if not self._clock_started and t > bar.initial:
            if self._waiting != self.label:
                # the first interval held the compilation: restart the clock here, so
                # that the remaining time is estimated from the run alone
                bar.start_t = bar.last_print_t = bar._time()
                bar.initial = bar.n
            self._clock_started = True
        desc = self.label if self._clock_started else self._waiting
        if bar.total and bar.n >= bar.total:
            return  # the full bar is drawn by finalize's close (which always draws)
        if (bar.n, desc) != self._drawn:  # py-pde's call at t_start would repeat a draw
            bar.set_description(desc)  # draws the bar
            self._drawn = (bar.n, desc)

    def finalize(self, info: InfoDict | None = None) -> None:
        TrackerBase.finalize(self, info)
        info = info or {}
        bar = self.progress_bar
        rest = info.get("solver", {}).get("rest_time")
        controller = info.get("controller", {})
        t_final = controller.get("t_final", -math.inf)
        if bar.total and (rest is not None
                          or t_final >= controller.get("t_end", math.inf) - self.atol):
            bar.n = bar.total
        if rest is not None:
            bar.set_postfix_str(f"at rest at t = {rest:.4g} s", refresh=False)
        elif not controller.get("successful", True):
            bar.set_postfix_str(f"stopped at t = {t_final:.4g} s", refresh=False)
        bar.set_description(self.label, refresh=False)
        bar.close()


class PointsBar:
    """A bar over the points of a study, a sweep or a convergence study: it advances as
    each batch of rows arrives (``bar(rows)``, the ``on_rows`` of
    :meth:`pdeflow.study.core.Study.run`), drawn once per batch; :meth:`close` ends it.
    It only counts rows: the results do not depend on it.

    Args:
        total: number of points.
        label: text in front of the bar (e.g. 'sweep').
    """

    def __init__(self, total: int, label: str):
        import sys

        self.bar = get_progress_bar_class()(total=total, desc=label, unit="run",
                                            leave=True, file=sys.stderr)

    def __call__(self, rows: list[Any]) -> None:
        self.bar.update(len(rows))

    def close(self) -> None:
        self.bar.close()


__all__ = ["PointsBar", "ProgressBar"]
