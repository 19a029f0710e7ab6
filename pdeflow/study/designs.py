"""The points of a study: full grid, Latin hypercube (scipy), Sobol/Saltelli (SALib), or
the trials of a multi-objective optimiser (optuna's NSGA-II).

Sampled designs draw u in the unit cube and map it onto each parameter
(:meth:`Parameter.from_unit`: linear or log ranges, integers, choices), so a log range
is sampled uniformly in its logarithm and the Sobol indices refer to that measure.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np

from .spec import Parameter, StudySpec


def unit_problem(parameters: list[Parameter]) -> dict[str, Any]:
    """SALib's problem over the unit cube of the parameters."""
    return {"num_vars": len(parameters), "names": [p.key for p in parameters],
            "bounds": [[0.0, 1.0]] * len(parameters)}


def design_points(spec: StudySpec) -> list[dict[str, Any]]:
    """Every point of a grid, Latin-hypercube or Sobol design, in a fixed order.

    The order (and for sampled designs, the seed) makes a point's index its identity,
    which is what resuming relies on.
    """
    params = spec.parameters
    if spec.design == "grid":
        return [dict(zip(spec.keys, values, strict=True))
                for values in itertools.product(*(p.grid_values() for p in params))]
    if spec.design == "lhs":
        from scipy.stats import qmc

        u = qmc.LatinHypercube(d=len(params), seed=spec.seed).random(spec.samples)
    elif spec.design == "sobol":
        from SALib.sample import sobol

        u = sobol.sample(unit_problem(params), spec.samples, calc_second_order=False,
                         seed=spec.seed)
    else:
        raise ValueError(f"{spec.design} has no fixed points (trials come from the "
                         "optimiser)")
    return [{p.key: p.from_unit(x) for p, x in zip(params, row, strict=True)}
            for row in np.asarray(u)]


def sobol_indices(spec: StudySpec, y: np.ndarray) -> dict[str, np.ndarray]:
    """First and total-order Sobol indices with 95 % confidence half-widths (SALib)."""
    from SALib.analyze import sobol

    res = sobol.analyze(unit_problem(spec.parameters), np.asarray(y, dtype=float),
                        calc_second_order=False, seed=spec.seed)
    return {k: np.asarray(res[k]) for k in ("S1", "S1_conf", "ST", "ST_conf")}


class Optimiser:
    """optuna's NSGA-II over the study's parameters, minimising its objectives.

    Trials are asked a generation (``spec.population``) at a time so that a batch of
    them runs in parallel; finished rows of an earlier, interrupted study are told back
    first (:meth:`replay`), so a rerun resumes the search instead of restarting it.
    """

    def __init__(self, spec: StudySpec) -> None:
        import optuna

        optuna.logging.set_verbosity(optuna.logging.WARNING)
        self.spec = spec
        self._optuna = optuna
        self.distributions = {p.key: self._distribution(p) for p in spec.parameters}
        sampler = optuna.samplers.NSGAIISampler(population_size=spec.population,
                                                seed=spec.seed)
        self.study = optuna.create_study(directions=["minimize"] * len(spec.objectives),
                                         sampler=sampler)
        self._pending: dict[int, Any] = {}
        self._next_id = 0

    def _distribution(self, p: Parameter) -> Any:
        d = self._optuna.distributions
        if p.kind == "choice":
            return d.CategoricalDistribution(list(p.values))
        if p.kind == "int":
            return d.IntDistribution(int(p.low), int(p.high), log=p.scale == "log")
        return d.FloatDistribution(p.low, p.high, log=p.scale == "log")

    def replay(self, rows: list[dict[str, Any]]) -> None:
        """Tell the optimiser the trials already in the results table."""
        state = self._optuna.trial.TrialState
        for row in rows:
            self._next_id = max(self._next_id, int(row["id"]) + 1)
            values = [row.get(k) for k in self.spec.objectives]
            ok = row.get("status") == "ok" and all(
                v is not None and np.isfinite(v) for v in values)
            self.study.add_trial(self._optuna.trial.create_trial(
                params={k: row[k] for k in self.spec.keys},
                distributions=self.distributions,
                values=[float(v) for v in values] if ok else None,
                state=state.COMPLETE if ok else state.FAIL))

    def ask(self, n: int) -> list[tuple[int, dict[str, Any]]]:
        """``n`` new trials as (row id, point); ids continue after the table's (trials
        lost in flight leave gaps, so they are not optuna's trial numbers)."""
        out = []
        for _ in range(n):
            trial = self.study.ask(self.distributions)
            self._pending[self._next_id] = trial
            out.append((self._next_id, dict(trial.params)))
            self._next_id += 1
        return out

    def tell(self, row: dict[str, Any]) -> None:
        """Report a finished trial (its row carries the objectives)."""
        trial = self._pending.pop(int(row["id"]))
        values = [row.get(k) for k in self.spec.objectives]
        if row.get("status") == "ok" and all(v is not None and np.isfinite(v)
                                             for v in values):
            self.study.tell(trial, [float(v) for v in values])
        else:
            self.study.tell(trial, state=self._optuna.trial.TrialState.FAIL)
