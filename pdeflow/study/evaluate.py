"""One evaluation of a study: the runs its point needs, and its row of the results.

Runs on a Dask worker. Only what the quantities read is run: the models named in them
(the other model of the case is skipped) and the 5.2 sweep only for ``sweep.*``
quantities. An evaluation that fails (a blow-up, a combination the case rejects) gives a
row with status ``failed`` and the error's message, never an exception: one bad point
must not end a study of thousands.
"""

from __future__ import annotations

import importlib
import json
import math
import time
import warnings
from dataclasses import dataclass
from typing import Any

from ..checks import RunWarning
from ..numerics.warmup import prepare
from ..simulate import case_steppers, run_model
from .spec import SWEEP_KEYS, StudySpec


def _silence_run_warnings() -> None:
    """A run's warnings are in its summary (quantity ``<model>.warnings``); thousands of
    evaluations printing them would bury the study's own output (worker processes only)."""
    warnings.simplefilter("ignore", RunWarning)


def _quantities(spec: StudySpec, point: dict[str, Any]) -> dict[str, Any]:
    if spec.function is not None:
        module, name = spec.function.split(":", 1)
        out = getattr(importlib.import_module(module), name)(**point)
        missing = [q for q in spec.quantities if q not in out]
        if missing:
            raise KeyError(f"{spec.function} returned no {missing[0]!r}")
        return {q: out[q] for q in spec.quantities}
    from ..analysis.sweep import run_sweep

    _silence_run_warnings()
    values: dict[str, Any] = {}
    models = spec.models()
    if models:
        assert spec.case is not None
        case = spec.case_for(spec.case, point, models)
        for model in models:
            summary = run_model(case, model).summary
            values.update({f"{model}.{k}": v for k, v in summary.items()})
    sweep_models = spec.sweep_models()
    if sweep_models:
        assert spec.sweep_case is not None
        case = spec.case_for(spec.sweep_case, point, sweep_models)
        fits = run_sweep(case, models=sweep_models)["models"]
        for model, fit in fits.items():
            values.update({f"sweep.{model}.{k}": fit[k] for k in SWEEP_KEYS})
    return {q: values.get(q) for q in spec.quantities}


def _number(v: Any) -> Any:
    """Plain Python scalars for the table (bools as 0/1, None stays missing, tables and
    lists as JSON text)."""
    if isinstance(v, bool):
        return int(v)
    if v is None or isinstance(v, (int, float, str)):
        return v
    if isinstance(v, (dict, list, tuple)):
        return json.dumps(v)
    return float(v)


@dataclass
class DesignPoint:
    """A point of a study file's design: its row id and its parameter values."""

    id: int
    values: dict[str, Any]

    @property
    def labels(self) -> dict[str, Any]:
        """The first columns of its row: the id and the values."""
        return {"id": self.id, **self.values}


def evaluate(spec: StudySpec, point: DesignPoint) -> dict[str, Any]:
    """The results of one point (its row without the labels): status, message, wall
    time [s], quantities, derived values and objectives."""
    row: dict[str, Any] = {"status": "ok", "message": ""}
    wall0 = time.perf_counter()
    try:
        values = {k: _number(v) for k, v in _quantities(spec, point.values).items()}
    except Exception as err:  # noqa: BLE001 - recorded in the row, see module docstring
        row.update(status="failed", message=_message(err))
        values = {}
    row["wall_s"] = time.perf_counter() - wall0
    for name, expr in (*spec.derived.items(), *spec.objectives.items()):
        v = expr(values)  # derived first: objectives may read them
        values[name] = None if math.isnan(v) else v
    row.update({k: values.get(k) for k in spec.columns()})
    return row


def failed_row(point: DesignPoint, err: Exception) -> dict[str, Any]:
    """The results of a point whose task failed as a whole (e.g. KilledWorker after
    Dask's retries): failed, with the error."""
    return {"status": "failed", "wall_s": 0.0,
            "message": f"{type(err).__name__}: {err}"[:300]}


def _message(err: Exception) -> str:
    """An error in one line of at most 300 characters: its type and first line."""
    first = str(err).strip().splitlines()[0] if str(err).strip() else ""
    return f"{type(err).__name__}: {first}"[:300]


def warm(spec: StudySpec) -> float:
    """Load what the study's evaluations use into this worker process: the modules and
    the numba kernels (from the disk cache; compiled if absent), by a run of each needed
    model on a 16-cell grid for a few steps. Returns the time it took [s]. Run once per
    worker when the cluster starts, so that the loop's timing holds only evaluations."""
    t0 = time.perf_counter()
    _silence_run_warnings()
    if spec.function is not None:
        importlib.import_module(spec.function.split(":", 1)[0])
    prepare(study_steppers(spec))
    for base, models in _bases(spec):
        tiny = base.copy()
        grid = tiny.data.setdefault("grid", {})
        grid.pop("dx", None)
        grid["cells"] = 16
        if tiny.is_2d:  # 16 x 16 cells
            grid.pop("dy", None)
            grid["cells_y"] = 16
        tiny.data.setdefault("case", {})["t_end"] = 0.01
        tiny.data.pop("sweep", None)
        for model in models:
            try:
                run_model(spec.case_for(tiny, {}, [model]), model)
            except Exception:  # noqa: BLE001, S112 - warming only; evaluations report errors
                continue
    return time.perf_counter() - t0


def study_steppers(spec: StudySpec) -> list[Any]:
    """The compiled steppers of every model the study's evaluations run, for
    :func:`pdeflow.numerics.warmup.prepare` to compile or load all at once (a cold cache
    is filled on two cores). A case that cannot be built is left out: its evaluations
    report the error. A parameter chosen among names (a basal friction law, a closure)
    may select other kernels: the case with each of its choices is warmed too."""
    points: list[dict[str, Any]] = [{}]
    points += [{p.key: v} for p in spec.parameters
               if p.kind == "choice" and all(isinstance(x, str) for x in p.values)
               for v in p.values]
    steppers = []
    for base, models in _bases(spec):
        for point in points:
            try:
                steppers += case_steppers(spec.case_for(base, point, models))
            except Exception:  # noqa: BLE001, S112 - warming only; evaluations report errors
                continue
    return steppers


def _bases(spec: StudySpec) -> list[tuple[Any, list[str]]]:
    """(base case, models it runs) of the study's evaluations: its case and its sweep."""
    return [(base, models) for base, models in ((spec.case, spec.models()),
                                                (spec.sweep_case, spec.sweep_models()))
            if base is not None and models]

