"""The Study: points, a measure that turns each into a row, and where they run.

Every study of pdeflow is one :class:`Study`: a list of points (anything with a
``labels`` dict: the columns that place the point in the study), a *measure* that turns
one point into a row of numbers, and an :class:`Executor` that runs the measure over the
points. The analysis studies (:mod:`pdeflow.analysis.convergence`,
:mod:`~pdeflow.analysis.workprecision`, :mod:`~pdeflow.analysis.validation`,
:mod:`~pdeflow.analysis.sweep`, :mod:`~pdeflow.analysis.stability`) are thin definitions
on it whose points are runs (:class:`~pdeflow.analysis.points.Point`); so is a study
file of ``pdeflow study`` (:mod:`pdeflow.study.execute`), whose points are the points
of its design, whose measure is one evaluation, and whose rows go to the resumable
results table as they arrive. An optimiser proposes its points as the study goes
(:class:`Proposals`) instead of a list.

Execution is pluggable: an :class:`Executor` is a ``concurrent.futures.Executor`` and
its number of workers: this process (:data:`serial`), a process pool
(:func:`pool_executor`) or a Dask cluster (:func:`dask_executor`, on Dask's own
``concurrent.futures`` interface; :func:`dask_cluster` starts a local one or connects
to a scheduler). The study sends its points in batches, one task per batch and two
batches in flight per worker so that none waits; a batch is sized from the median time
of a point so far to last about :data:`TARGET_BATCH_S`, so that the cost of a task
(about a millisecond on Dask) stays a small fraction of a 5 ms point while an
interruption loses little. For a pool or Dask the measure and the points must pickle
(module-level functions).
"""

from __future__ import annotations

import concurrent.futures as cf
import logging
import math
import os
import statistics
import time
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import partial
from typing import Any, Protocol

from ..trackers.progress import PointsBar

TARGET_BATCH_S = 0.5
"""wall time a batch should take [s]: scheduling overhead << 1 %, little lost on Ctrl-C"""

Row = dict[str, Any]


# --- executors --------------------------------------------------------------------------
class _InProcess(cf.Executor):
    """A ``concurrent.futures`` executor that runs each call when it is submitted."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> cf.Future:
        future: cf.Future = cf.Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except Exception as err:  # noqa: BLE001 - handed to the caller by the future
            future.set_exception(err)
        return future


def _same(obj: Any) -> Any:
    return obj


@dataclass
class Executor:
    """Where a study's batches run: a ``concurrent.futures`` executor and its workers."""

    pool: cf.Executor
    workers: int = 1
    """batches that run at once"""
    everywhere: Callable[[Callable[[], Any]], Any] | None = None
    """runs a call once on every worker (a study's set-up); None: the pool cannot"""
    share: Callable[[Any], Any] = _same
    """what a task receives for an object every task needs (Dask: scattered once)"""
    dashboard: str | None = None


serial = Executor(_InProcess(), 1, everywhere=lambda fn: fn())
"""The default: every point in this process, in order."""


def pool_executor(pool: cf.Executor, workers: int | None = None) -> Executor:
    """An executor on a ``concurrent.futures`` pool of ``workers`` processes (default:
    one per core). A pool cannot run a call on every worker, so a study's set-up is
    skipped: each worker loads what it needs with its first point."""
    return Executor(pool, workers or os.cpu_count() or 1)


def dask_executor(client: Any) -> Executor:
    """An executor on a Dask ``distributed.Client`` (its ``concurrent.futures``
    interface; what every task needs is scattered to every worker once)."""
    return Executor(client.get_executor(pure=False), max(1, len(client.nthreads())),
                    everywhere=client.run,
                    share=partial(client.scatter, broadcast=True),
                    dashboard=client.dashboard_link)


@contextmanager
def dask_cluster(workers: int | None = None,
                 scheduler: str | None = None) -> Iterator[Executor]:
    """A :func:`dask_executor` on an existing cluster (``scheduler``, e.g.
    ``tcp://HOST:PORT``) or on a local cluster of ``workers`` processes (default: one
    per core), closed on exit."""
    from distributed import Client, LocalCluster

    cluster = None
    if scheduler:
        client = Client(scheduler, timeout="20s")
        client.wait_for_workers(1, timeout=60)
    else:
        # processes, one thread each: the kernels hold the GIL between numba calls
        cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1,
                               threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.ERROR)
        client = Client(cluster)
        client.wait_for_workers(len(cluster.workers), timeout=60)
    try:
        yield dask_executor(client)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


# --- the study --------------------------------------------------------------------------
class Labelled(Protocol):
    """A point of a study: its ``labels`` are the first columns of its row."""

    labels: dict[str, Any]


class Proposals(Protocol):
    """Points proposed as the study goes (an optimiser) instead of a fixed list."""

    total: int
    """points to run"""
    generation: int | None
    """points proposed together (a batch stays below a worker's share of them)"""

    def ask(self, n: int) -> list[Any]: ...

    def tell(self, rows: list[Row]) -> None: ...


@dataclass
class _Listed:
    """A fixed list of points as :class:`Proposals` (told nothing)."""

    points: Sequence[Any]
    generation: int | None = None
    _next: int = 0

    @property
    def total(self) -> int:
        return len(self.points)

    def ask(self, n: int) -> list[Any]:
        out = list(self.points[self._next:self._next + n])
        self._next += len(out)
        return out

    def tell(self, rows: list[Row]) -> None:
        pass


def _measured(measure: Callable[[Any], Row], points: list[Any]
              ) -> list[tuple[Row, float]]:
    """One task: the rows of a batch of points and the time each took [s]."""
    out = []
    for point in points:
        t0 = time.perf_counter()
        row = {**point.labels, **measure(point)}
        out.append((row, time.perf_counter() - t0))
    return out


@dataclass
class Execution:
    """What :meth:`Study.run` did: the rows (in the order of the points) and its times."""

    rows: list[Row]
    setup_s: float
    """set-up on every worker [s]"""
    wall_s: float
    """the points, from the first batch sent to the last row back [s]"""
    complete: bool


@dataclass
class Study:
    """Points and the measure that turns each into a row of results."""

    points: Sequence[Labelled] | Proposals
    measure: Callable[[Any], Row]
    setup: Callable[[], Any] | None = None
    """warming only, run once on every worker before the clock starts (e.g. load the
    kernels); skipped by an executor that cannot reach every worker"""
    failed: Callable[[Any, Exception], Row] | None = None
    """the row of each point of a batch that raised (e.g. its worker died): a study of
    thousands of points goes on; None: the error ends the study"""

    def execute(self, executor: Executor = serial, progress: str | None = None
                ) -> list[Row]:
        """The rows ``{**point.labels, **measure(point)}``, in the order of the points;
        ``progress``: the label of a bar over the points on stderr (None: no bar)."""
        if progress is None or not isinstance(self.points, Sequence):
            return self.run(executor).rows
        bar = PointsBar(len(self.points), progress)
        try:
            return self.run(executor, on_rows=bar).rows
        finally:
            bar.close()

    def run(self, executor: Executor = serial,
            on_rows: Callable[[list[Row]], Any] | None = None,
            on_end: Callable[[Execution], Any] | None = None) -> Execution:
        """Run every point on ``executor``. ``on_rows`` gets each batch's rows as it
        arrives (a results table appends them there, so an interruption keeps them);
        ``on_end`` gets the execution when it ends, also by an error or an interrupt."""
        run = Execution([], 0.0, 0.0, False)
        source = (_Listed(self.points) if isinstance(self.points, Sequence)
                  else self.points)
        batches = _Batches(self, executor, source)
        t0 = t_ready = time.perf_counter()
        try:
            if self.setup is not None and executor.everywhere is not None:
                executor.everywhere(self.setup)
            t_ready = time.perf_counter()
            run.setup_s = t_ready - t0
            for rows in batches:
                if on_rows is not None:
                    on_rows(rows)
        finally:
            batches.cancel()
            run.rows = [row for _, row in sorted(batches.done, key=lambda item: item[0])]
            run.wall_s = time.perf_counter() - t_ready
            run.complete = len(run.rows) == source.total
            if on_end is not None:
                on_end(run)
        return run


@dataclass
class _Batches:
    """The study's batches in flight: sent two per worker, sized by the times so far,
    and their rows as each batch finishes."""

    study: Study
    executor: Executor
    source: Proposals
    done: list[tuple[int, Row]] = field(default_factory=list)
    walls: deque[float] = field(default_factory=lambda: deque(maxlen=200))
    pending: dict[cf.Future, tuple[int, list[Any]]] = field(default_factory=dict)
    sent: int = 0

    def __post_init__(self) -> None:
        self.measure = self.executor.share(self.study.measure)

    def size(self) -> int:
        """Points in the next batch: about TARGET_BATCH_S of work, at least one, and
        no more than leaves two batches for every worker."""
        left = self.source.total - self.sent
        n = 1 if not self.walls else math.ceil(
            TARGET_BATCH_S / max(statistics.median(self.walls), 1e-4))
        n = max(1, min(n, left // (2 * self.executor.workers) or 1, left))
        if self.source.generation is not None:
            # a generation of proposals should not wait on one worker's long batch
            n = min(n, max(1, self.source.generation // self.executor.workers))
        return n

    def submit(self) -> None:
        points = self.source.ask(self.size())
        future = self.executor.pool.submit(_measured, self.measure, points)
        self.pending[future] = (self.sent, points)
        self.sent += len(points)

    def rows(self, future: cf.Future) -> list[Row]:
        first, points = self.pending.pop(future)
        try:
            measured = future.result()
        except Exception as err:
            if self.study.failed is None:
                raise
            measured = [({**p.labels, **self.study.failed(p, err)}, 0.0) for p in points]
        self.walls.extend(wall for _, wall in measured)
        rows = [row for row, _ in measured]
        self.done.extend(zip(range(first, first + len(rows)), rows, strict=True))
        self.source.tell(rows)
        return rows

    def __iter__(self) -> Iterator[list[Row]]:
        for _ in range(2 * self.executor.workers):
            if self.sent < self.source.total:
                self.submit()
        while self.pending:
            finished, _ = cf.wait(self.pending, return_when=cf.FIRST_COMPLETED)
            for future in finished:
                yield self.rows(future)
                if self.sent < self.source.total:
                    self.submit()

    def cancel(self) -> None:
        """Cancel the batches still in flight (after an error or an interruption)."""
        for future in self.pending:
            future.cancel()
