"""A hillside run computed in a worker thread while the page draws its frames.

:class:`LiveRun` runs each model of a :class:`~pdeflow.app.hillside_setup.HillsideSetup`
with :class:`pdeflow.simulate.Run`, as ``pdeflow run`` would run the downloaded case
file, with a :class:`~pdeflow.trackers.stream.StreamTracker` that appends the total
depth [m] to :attr:`LiveRun.frames` every :data:`FRAMES_PER_T_END`-th of t_end.
The tracker only reads, so the numbers are those of the command line; the page reads
the frames from its own thread as they arrive (appending to a list is atomic).

A run stops early, with a one-line reason and no summary, when it is cancelled (a new
run, a closed tab) or exceeds :data:`WALL_LIMIT_S` of wall time.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import metrics_2d
from ..cases import Case
from ..checks import WARNING_PREFIX, cost_warning, slope_warning, solver_warning
from ..numerics.warmup import prepare
from ..simulate import Run, case_steppers
from ..trackers.stream import RunStopped, StreamTracker
from .hillside_setup import HillsideSetup
from .kernels import WARMUP

FRAMES_PER_T_END = 300
"""Frame interval: t_end / this [s] of simulation time (0.5 s for t_end = 150 s)."""
WALL_LIMIT_S = 60.0
"""The longest a run may compute [s]: a class's server stays free for the next."""
THREADS = 1
"""numba threads per run: the cores go to the runs of several sessions at once (a
flow on a few thousand wet cells gains nothing from a second thread)."""


_COMPILING = threading.Lock()
"""Held while kernels are compiled or loaded: numba must not compile one kernel from
two threads (two sessions' runs, or a run and the app's warm-up)."""


def prepare_kernels(case: Case) -> None:
    """Compile (or load from the cache) the kernels of every model of ``case``, after
    the app's own warm-up if it has started, one caller at a time."""
    with _COMPILING:
        if WARMUP.started is not None:
            WARMUP.wait()
        prepare(case_steppers(case))


@dataclass(frozen=True)
class Frame:
    """The total depth ``depth`` [m] (nx, ny, float32) of one model at time ``t`` [s]."""

    t: float
    depth: np.ndarray


def total_depth(data: np.ndarray) -> np.ndarray:
    """A frame's depth [m] of all layers of a 2D state
    (:func:`pdeflow.metrics_2d.total_depth`), in single precision: enough to draw."""
    return metrics_2d.total_depth(data).astype(np.float32)


class LiveRun:
    """Every model of ``setup``, run in :meth:`execute` (in a worker thread).

    The case is built and checked here, before any work: bad input raises a one-line
    CaseError or ValueError. Attributes the page reads while the run goes:
    :attr:`status`, :attr:`frames`, :attr:`summaries`, :attr:`warnings`,
    :attr:`message`.
    """

    def __init__(self, setup: HillsideSetup, wall_limit_s: float = WALL_LIMIT_S):
        self.setup = setup
        self.case: Case = setup.case()
        self.wall_limit_s = wall_limit_s
        self.frames: dict[str, list[Frame]] = {m: [] for m in self.case.models}
        self.summaries: dict[str, dict[str, Any]] = {}
        self.warnings: list[str] = []
        self.status = "queued"
        """'queued', 'running', 'done', 'stopped' (cancelled or too long), 'failed'"""
        self.message = ""
        """why the run stopped or failed (one line), empty otherwise"""
        self.wall_time_s = 0.0
        self._cancel = threading.Event()
        self._finished = threading.Event()
        self._started = 0.0

    @property
    def models(self) -> list[str]:
        return self.case.models

    @property
    def finished(self) -> bool:
        """Whether the run has ended (done, stopped or failed)."""
        return self._finished.is_set()

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the run has ended; True if it has."""
        return self._finished.wait(timeout)

    def cancel(self) -> None:
        """Stop the run at its next frame (or before it starts)."""
        self._cancel.set()

    def _stop_reason(self) -> str | None:
        if self._cancel.is_set():
            return "cancelled"
        if time.perf_counter() - self._started > self.wall_limit_s:
            return (f"stopped after {self.wall_limit_s:g} s of computing (the page's "
                    f"limit): choose fewer cells or a smaller release")
        return None

    def _warn(self, message: str | None) -> None:
        line = f"{WARNING_PREFIX}{message}"
        if message and line not in self.warnings:
            self.warnings.append(line)

    def _run_model(self, model: str) -> None:
        frames = self.frames[model]
        interval = self.case.t_end / FRAMES_PER_T_END
        tracker = StreamTracker(interval, total_depth,
                                lambda t, depth: frames.append(Frame(t, depth)),
                                self._stop_reason)
        for message in (solver_warning(self.case), slope_warning(self.case),
                        cost_warning(self.case, model)):
            self._warn(message)
        run = Run(self.case, model, threads=THREADS)
        # Run.execute issues the summary's warnings as RunWarnings too (the process's
        # warning filters are global: not caught per thread); the lines shown are the
        # summary's own
        result = run.execute(tracker=tracker)
        self.summaries[model] = result.summary
        for message in result.summary.get("warnings", []):
            self._warn(message)

    def _model_thread(self, model: str, errors: list[BaseException]) -> None:
        try:
            self._run_model(model)
        except BaseException as err:  # handed to execute, which says what it was
            errors.append(err)
            self.cancel()  # the other model stops too: the run as a whole failed

    def execute(self) -> None:
        """Run the models side by side, one thread each, so that their frames arrive
        together (the kernels hold the GIL while they step: the threads take turns
        between frames); never raises (the page shows :attr:`message`)."""
        self._started = time.perf_counter()
        errors: list[BaseException] = []
        try:
            if self._cancel.is_set():
                raise RunStopped("cancelled")
            self.status = "running"
            # both models' kernels compiled (or loaded) before their threads start: numba
            # must not compile one kernel from two threads
            prepare_kernels(self.case)
            # the limit and the wall time count computing, not compiling the kernels
            # (minutes on a fresh machine, once)
            self._started = time.perf_counter()
            threads = [threading.Thread(target=self._model_thread, args=(m, errors),
                                        name=f"pdeflow-{m}", daemon=True)
                       for m in self.models]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            if errors:
                raise next((e for e in errors if not isinstance(e, RunStopped)),
                           errors[0])
            self.status = "done"
        except RunStopped as err:
            self.status, self.message = "stopped", str(err)
        except Exception as err:  # noqa: BLE001 (a worker: the page says what it was)
            self.status, self.message = "failed", f"{type(err).__name__}: {err}"
        finally:
            self.wall_time_s = time.perf_counter() - self._started
            self._finished.set()

    def frame_count(self) -> int:
        """How many frames every model can show: a model that has ended keeps its last
        frame, one still running limits the count to those it has made."""
        counts = [len(f) for m, f in self.frames.items() if m not in self.summaries]
        longest = max((len(f) for f in self.frames.values()), default=0)
        if self.finished:
            return longest
        return min(counts) if counts else longest

    def frame(self, k: int) -> dict[str, Frame]:
        """Every model's frame ``k`` (a model that has ended: its last), of the models
        that have one."""
        return {m: f[min(k, len(f) - 1)] for m, f in self.frames.items() if f}
