"""A study file run as a :class:`~.core.Study` on Dask: a local cluster or a scheduler.

The study's points are the points of its design not yet in the results table (or the
optimiser's trials, :class:`_Trials`), its measure is one evaluation
(:func:`.evaluate.evaluate`), its set-up loads the kernels on every worker, and every
batch's rows are appended to the results table as they arrive (:mod:`.results`), so
rerunning the same command computes only what is missing. The Study sends the points in
batches sized to the time an evaluation takes (:mod:`.core`).
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

from ..numerics.warmup import prepare
from .core import Execution, Study, dask_cluster
from .designs import Optimiser, design_points
from .evaluate import DesignPoint, evaluate, failed_row, study_steppers, warm
from .results import ResultsTable
from .spec import StudySpec


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


@dataclass
class _Trials:
    """The optimiser's trials as the study's points, proposed a generation at a time."""

    optimiser: Optimiser
    total: int
    generation: int

    def ask(self, n: int) -> list[DesignPoint]:
        """``n`` new trials of the optimiser."""
        return [DesignPoint(i, p) for i, p in self.optimiser.ask(n)]

    def tell(self, rows: list[dict[str, Any]]) -> None:
        """Report finished trials (their rows carry the objectives)."""
        for row in rows:
            self.optimiser.tell(row)


def _points(spec: StudySpec, finished: list[dict[str, Any]]) -> list[DesignPoint] | _Trials:
    """What is left to run: the design's points not in the table, or the optimiser's
    trials (told the finished ones first, so that the search resumes)."""
    done = {int(r["id"]) for r in finished}
    if spec.design == "optimize":
        optimiser = Optimiser(spec)
        optimiser.replay(sorted(finished, key=lambda r: r["id"]))
        return _Trials(optimiser, max(spec.samples - len(done), 0), spec.population)
    return [DesignPoint(i, p) for i, p in enumerate(design_points(spec)) if i not in done]


def _open(spec: StudySpec, out: str, log: Callable[[str], None]
          ) -> tuple[ResultsTable, list[dict[str, Any]]]:
    """The study's results table in ``out`` and its finished rows (a warning if other
    models or numerics computed them)."""
    table = ResultsTable(out, spec)
    finished = table.rows()
    if table.other_code and finished:
        log(f"warning: {table.dir}: its {len(finished)} results were computed by another "
            "version of pdeflow's models or numerics (or one that did not record it); "
            "they are kept and only missing evaluations are run: remove the directory "
            "to recompute them all")
    return table, finished


def _record(table: ResultsTable, done: set[int], run: Execution, startup_s: float,
            workers: int, scheduler: str | None) -> dict[str, Any]:
    """Record the execution's timing in the table's metadata (the report shows it)."""
    evals = [r for r in table.rows() if int(r["id"]) not in done]
    busy = sum(float(r["wall_s"]) for r in evals)
    info = {"workers": workers, "scheduler": scheduler or "local",
            "evaluations": len(evals), "startup_s": startup_s, "wall_s": run.wall_s,
            "evaluation_s": busy,
            "overhead_per_evaluation_s": ((run.wall_s * workers - busy) / len(evals)
                                          if evals else None),
            "complete": run.complete}
    table.record_execution(info)
    return info


def run_study(spec: StudySpec, out: str, *, workers: int | None = None,
              scheduler: str | None = None, progress: bool = False,
              log: Callable[[str], None] = print) -> ResultsTable:
    """Run (or resume) ``spec`` into directory ``out``; return its results table."""
    table, finished = _open(spec, out, log)
    done = {int(r["id"]) for r in finished}
    points = _points(spec, finished)
    total = len(points) if isinstance(points, list) else points.total
    if total == 0:
        log(f"{table.csv}: all {len(done)} evaluations done")
        return table
    log(f"{spec.name}: {total} evaluations to run ({len(done)} already in {table.csv})")
    t_start = time.perf_counter()
    if scheduler is None:  # the local workers share this machine's kernel cache
        prepare(study_steppers(spec))
    study = Study(points, partial(evaluate, spec), setup=partial(warm, spec),
                  failed=failed_row)
    bar = _Progress(total, progress)
    info: dict[str, Any] = {}
    with dask_cluster(workers, scheduler) as executor:
        log(f"Dask: {executor.workers} workers, dashboard {executor.dashboard}")
        t_cluster = time.perf_counter()

        def end(run: Execution) -> None:
            bar.close()
            info.update(_record(table, done, run, t_cluster - t_start + run.setup_s,
                                executor.workers, scheduler))

        run = study.run(executor, on_rows=lambda rows: (table.append(rows),
                                                        bar.update(rows)), on_end=end)
    log(f"{info['evaluations']} evaluations in {run.wall_s:.1f} s on {executor.workers} "
        f"workers (cluster start {info['startup_s']:.1f} s; busy "
        f"{info['evaluation_s']:.1f} s, {bar.failed} failed) -> {table.csv}")
    return table
