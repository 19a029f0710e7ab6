"""Execution of a study on Dask: a local cluster or an existing scheduler.

Points go to the workers in batches (one Dask task per batch), two batches in flight
per worker so that none waits for the client. A batch is sized from the median
evaluation time seen so far to last about ``TARGET_BATCH_S``: Dask's cost per task
(about a millisecond on one machine, more across a network) then stays a small fraction
of a 5 ms evaluation, while an interruption loses at most a few batches. Every batch's
rows are appended to the results table as it arrives (:mod:`.results`), so rerunning the
same command computes only what is missing.
"""

from __future__ import annotations

import logging
import math
import os
import statistics
import sys
import time
from collections import deque
from collections.abc import Callable
from typing import Any

from ..numerics.warmup import prepare
from .designs import Optimiser, design_points
from .evaluate import evaluate_batch, study_steppers, warm
from .results import ResultsTable
from .spec import StudySpec

TARGET_BATCH_S = 0.5
"""wall time a batch should take [s]: scheduling overhead << 1 %, little lost on Ctrl-C"""


def _client(workers: int | None, scheduler: str | None) -> tuple[Any, Any, int]:
    """(client, local cluster or None, number of workers)."""
    from distributed import Client, LocalCluster

    if scheduler:
        client = Client(scheduler, timeout="20s")
        client.wait_for_workers(1, timeout=60)
        return client, None, len(client.scheduler_info()["workers"])
    n = workers or os.cpu_count() or 1
    # processes, one thread each: the kernels hold the GIL between numba calls
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                           dashboard_address=":0", silence_logs=logging.ERROR)
    return Client(cluster), cluster, n


class _Progress:
    def __init__(self, total: int, show: bool) -> None:
        self.total, self.show = total, show
        self.done = self.failed = 0
        self.t0 = time.perf_counter()

    def update(self, rows: list[dict[str, Any]]) -> None:
        self.done += len(rows)
        self.failed += sum(r["status"] != "ok" for r in rows)
        if self.show:
            el = time.perf_counter() - self.t0
            eta = el / self.done * (self.total - self.done) if self.done else math.inf
            print(f"\r  {self.done}/{self.total} evaluations ({self.failed} failed), "
                  f"{el:.0f} s, about {eta:.0f} s left   ", end="", file=sys.stderr,
                  flush=True)

    def close(self) -> None:
        if self.show:
            print(file=sys.stderr)


def run_study(spec: StudySpec, out: str, *, workers: int | None = None,
              scheduler: str | None = None, progress: bool = False,
              log: Callable[[str], None] = print) -> ResultsTable:
    """Run (or resume) ``spec`` into directory ``out``; return its results table."""
    table = ResultsTable(out, spec)
    finished = table.rows()
    if table.other_code and finished:
        log(f"warning: {table.dir}: its {len(finished)} results were computed by another "
            "version of pdeflow's models or numerics (or one that did not record it); "
            "they are kept and only missing evaluations are run: remove the directory "
            "to recompute them all")
    done = {int(r["id"]) for r in finished}
    optimiser = None
    if spec.design == "optimize":
        optimiser = Optimiser(spec)
        optimiser.replay(sorted(finished, key=lambda r: r["id"]))
        total = max(spec.samples - len(done), 0)
        queue: deque = deque()
    else:
        queue = deque((i, p) for i, p in enumerate(design_points(spec)) if i not in done)
        total = len(queue)
    if total == 0:
        log(f"{table.csv}: all {len(done)} evaluations done")
        return table
    log(f"{spec.name}: {total} evaluations to run ({len(done)} already in {table.csv})")
    t_start = time.perf_counter()
    if scheduler is None:  # the local workers share this machine's kernel cache
        prepare(study_steppers(spec))
    client, cluster, n_workers = _client(workers, scheduler)
    log(f"Dask: {n_workers} workers, dashboard {client.dashboard_link}")
    walls: deque[float] = deque(maxlen=200)
    bar = _Progress(total, progress)
    submitted = 0
    futures: Any = None
    t_ready = time.perf_counter()
    try:
        from distributed import as_completed

        client.run(warm, spec)  # every worker loads the kernels once, before the clock
        t_ready = time.perf_counter()

        spec_f = client.scatter(spec, broadcast=True)  # shipped once per worker

        def next_batch() -> list[tuple[int, dict[str, Any]]]:
            nonlocal submitted
            left = total - submitted
            size = 1 if not walls else math.ceil(
                TARGET_BATCH_S / max(statistics.median(walls), 1e-4))
            size = max(1, min(size, left // (2 * n_workers) or 1, left))
            if optimiser is not None:
                # an optimiser generation should not wait on one worker's long batch
                size = min(size, max(1, spec.population // n_workers))
                batch = optimiser.ask(size)
            else:
                batch = [queue.popleft() for _ in range(size)]
            submitted += len(batch)
            return batch

        batches: dict[str, list[tuple[int, dict[str, Any]]]] = {}

        def submit() -> None:
            batch = next_batch()
            fut = client.submit(evaluate_batch, spec_f, batch, pure=False)
            batches[fut.key] = batch
            futures.add(fut)

        futures = as_completed()
        for _ in range(2 * n_workers):
            if submitted < total:
                submit()
        for fut in futures:
            batch = batches.pop(fut.key)
            try:
                rows = fut.result()
            except Exception as err:  # noqa: BLE001 - e.g. KilledWorker after retries
                rows = [{"id": i, "status": "failed", "wall_s": 0.0, **p,
                         "message": f"{type(err).__name__}: {err}"[:300]}
                        for i, p in batch]
            table.append(rows)
            walls.extend(r["wall_s"] for r in rows)
            if optimiser is not None:
                for r in rows:
                    optimiser.tell(r)
            bar.update(rows)
            if submitted < total:
                submit()
    finally:
        bar.close()
        loop_wall = time.perf_counter() - t_ready
        if futures is not None:
            client.cancel(list(futures.futures))
        client.close()
        if cluster is not None:
            cluster.close()
        evals = [r for r in table.rows() if int(r["id"]) not in done]
        busy = sum(float(r["wall_s"]) for r in evals)
        info = {"workers": n_workers, "scheduler": scheduler or "local",
                "evaluations": len(evals), "startup_s": t_ready - t_start,
                "wall_s": loop_wall, "evaluation_s": busy,
                "overhead_per_evaluation_s": ((loop_wall * n_workers - busy) / len(evals)
                                              if evals else None),
                "complete": bar.done == total}
        table.record_execution(info)
    log(f"{len(evals)} evaluations in {loop_wall:.1f} s on {n_workers} workers "
        f"(cluster start {info['startup_s']:.1f} s; busy {busy:.1f} s, "
        f"{bar.failed} failed) -> {table.csv}")
    return table
