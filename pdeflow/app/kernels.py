"""The numba kernels, loaded in the background so that the app can say what it waits for.

pdeflow's kernels are compiled on their first use and cached on disk: after a start with
an empty cache the app waits seconds for its first picture, later starts load the
kernels in a fraction of a second. The app starts :data:`WARMUP` when it is served or
displayed; its pages show :meth:`KernelWarmup.message` (with the elapsed time) until
the kernels are ready, instead of looking frozen.
"""

from __future__ import annotations

import threading
import time
import warnings
from collections.abc import Callable

from ..cases import BASELINE_MODEL, PAPER_MODEL

#: a case that touches every kernel the pages use: both models, the fv-split stepping
#: loop with its trackers' interrupts, on a grid small enough to run in milliseconds
WARMUP_CASE = {
    "case": {"name": "kernel warm-up", "t_end": 0.05,
             "models": [PAPER_MODEL, BASELINE_MODEL]},
    "grid": {"length": 1.0, "cells": 20},
    "initial": {"shape": "column", "L0": 0.5, "H0": 0.5},
    "output": {"snapshot_times": [0.02]},
}


def warm_kernels() -> None:
    """Run every kernel the app uses once: compiles them, or loads them from the cache."""
    from ..cases import Case
    from ..checks import RunWarning
    from ..models.two_layer import hyperbolicity as hyp
    from ..numerics.warmup import prepare
    from ..simulate import case_steppers, run_model

    def spectrum_functions() -> None:
        # called from Python by the hyperbolicity page: compiled as Python-callable
        # twins of the kernels (numerics.numba_hooks.HelperKernel) while a helper process
        # compiles the source stages
        g, r, h1, h2 = 9.81, 0.67, 0.5, 1.0
        hyp.discriminant(h1, h2, 3.0, 0.0, g, r)
        hyp.lower_bound_fl(h1, h2, g, r)
        hyp.upper_bound_fr(h1, h2, g, r)
        hyp.band_lower_edge(h1, h2, g, r, 3.0)

    case = Case.from_dict(WARMUP_CASE, source="<kernel warm-up>")
    # both models' kernels at once: compiled on two cores
    prepare(case_steppers(case), meanwhile=spectrum_functions)
    with warnings.catch_warnings():
        # the warm-up's runs are not the user's: their "still moving" is no news
        warnings.simplefilter("ignore", RunWarning)
        for model in case.models:
            run_model(case, model)


class KernelWarmup:
    """Runs ``work`` (default :func:`warm_kernels`) once, in a daemon thread.

    ``start`` may be called any number of times (by every page of every session); the
    work runs once per process, because the loaded kernels are shared by all sessions.
    """

    def __init__(self, work: Callable[[], None] = warm_kernels):
        self._work = work
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None
        self.started: float | None = None
        """time.monotonic() when the work started [s]"""
        self.finished: float | None = None
        """time.monotonic() when it ended [s] (also after a failure)"""
        self.error: str | None = None
        """one line describing the failure, if the work raised"""

    def start(self) -> None:
        with self._lock:
            if self._thread is not None:
                return
            self.started = time.monotonic()
            self._thread = threading.Thread(target=self._run, name="pdeflow-kernels",
                                            daemon=True)
            self._thread.start()

    def _run(self) -> None:
        try:
            self._work()
        except Exception as err:  # shown on the pages; the server keeps running
            self.error = f"{type(err).__name__}: {err}"
        finally:
            self.finished = time.monotonic()

    @property
    def done(self) -> bool:
        """True once the work has ended (successfully or not)."""
        return self.finished is not None

    @property
    def elapsed(self) -> float:
        """Seconds since the start (until the end, once it has ended) [s]."""
        if self.started is None:
            return 0.0
        return (self.finished or time.monotonic()) - self.started

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the work has ended (for scripts and notebooks); True if it has."""
        self.start()
        assert self._thread is not None
        self._thread.join(timeout)
        return self.done

    def message(self) -> str:
        """What the pages show while they wait, or why they cannot go on."""
        if self.error is not None:
            return f"loading the kernels failed: {self.error}"
        if self.done:
            return f"kernels ready (loaded in {self.elapsed:.1f} s)"
        return (f"compiling kernels (once per machine; later starts load them in under "
                f"a second): elapsed {self.elapsed:.0f} s")


WARMUP = KernelWarmup()
"""The process's warm-up: started by :func:`pdeflow.app.create_app` and the server."""
