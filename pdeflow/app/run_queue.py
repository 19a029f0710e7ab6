"""The queue of the hillside page's runs: at most one run per core computes, the others
wait in the order they came, and each page can say where its run stands.

The runs go to a :class:`concurrent.futures.ThreadPoolExecutor` of :data:`SLOTS`
workers, shared by every session of the server (a class of 30 pressing "run" at once
computes two runs at a time on two cores and queues the rest). A cancelled run
(a new run on the same page, a closed tab) leaves the queue at once, or stops at its
next frame if it computes. A full queue refuses a run with a one-line reason.
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

from .live_run import LiveRun

SLOTS = max(1, os.cpu_count() or 1)
"""Runs computed at once: one per core."""
MAX_WAITING = 60
"""Runs that may wait at once (two per student of a class of 30)."""


class QueueFull(RuntimeError):
    """The queue holds :data:`MAX_WAITING` runs: a new one is refused."""


class RunQueue:
    """Runs :meth:`LiveRun.execute <pdeflow.app.live_run.LiveRun.execute>` on ``slots``
    worker threads, in the order submitted."""

    def __init__(self, slots: int = SLOTS, max_waiting: int = MAX_WAITING):
        self.slots = slots
        self.max_waiting = max_waiting
        self._pool = ThreadPoolExecutor(max_workers=slots, thread_name_prefix="pdeflow-run")
        self._lock = threading.Lock()
        self._waiting: list[LiveRun] = []

    def submit(self, run: LiveRun) -> None:
        """Queue ``run`` (QueueFull, one line, if the queue is full)."""
        with self._lock:
            if len(self._waiting) >= self.max_waiting:
                raise QueueFull(f"{len(self._waiting)} runs are waiting (the server's "
                                f"limit): try again in a moment")
            self._waiting.append(run)
        self._pool.submit(self._work, run)

    def _work(self, run: LiveRun) -> None:
        with self._lock:
            if run in self._waiting:
                self._waiting.remove(run)
        run.execute()  # a cancelled run ends at once, as 'stopped'

    def position(self, run: LiveRun) -> int:
        """0 once ``run`` computes (or has ended), else its place among the waiting
        runs (1: next)."""
        with self._lock:
            return self._waiting.index(run) + 1 if run in self._waiting else 0

    def cancel(self, run: LiveRun) -> None:
        """Stop ``run``: out of the queue if it waits, at its next frame if it runs."""
        run.cancel()
        with self._lock:
            if run in self._waiting:
                self._waiting.remove(run)
        # a removed run's worker call still comes; execute then ends it as stopped

    @property
    def waiting(self) -> int:
        """Runs waiting for a slot."""
        with self._lock:
            return len(self._waiting)


QUEUE = RunQueue()
"""The server's queue, shared by every session."""
