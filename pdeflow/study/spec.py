"""The study file: what to vary, how to sample it, what to measure.

A study file is TOML, read and checked once; every error names the key (exit 2)::

    [study]
    name = "smoke"                    # optional; default: the file name
    case = "paper_5_1_dam_break.toml" # base case, relative to this file ([base_case]
                                      # holds one inline instead; or function = "mod:f")
    set = ["grid.dx=0.05"]            # fixed overrides of the base (and sweep) case
    sweep_case = "collapse_sweep.toml"  # only for sweep.* quantities (paper 5.2 fit)
    design = "lhs"                    # grid | lhs | sobol | optimize
    samples = 32                      # lhs: points; sobol: N (N (D + 2) runs);
                                      # optimize: trials (population: generation size)
    seed = 1
    quantities = ["two_layer.runout"] # <model>.<summary key>, sweep.<model>.exponent|
                                      # prefactor|exponent_mass|prefactor_mass|
                                      # all_at_rest; or the function's outputs
    [parameters]                      # any case key "section.key"
    "two_layer.c" = { range = [0.01, 3], scale = "log", points = 4 }
    "two_layer.k" = { values = [0.3, 0.5, 0.8] }
    "two_layer.exchange_closure" = { choices = ["paper", "relaxed"] }
    [derived]                         # expressions of quantities, e.g.
    runout_ratio = "two_layer.runout / single_layer.runout"
    [objectives]                      # expressions to minimise (Pareto front)
    exponent = "abs(sweep.two_layer.exponent - 0.84)"

Expressions are arithmetic (+ - * / ** and unary minus) over numbers, quantities,
derived names and the functions abs, min, max, sqrt, log, log10, exp and
``fill(x, default)`` (``default`` where x is missing, e.g. a layer that never stopped).
Quantities used in an expression are computed even if not listed.
"""

from __future__ import annotations

import hashlib
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from .. import systems
from ..cases import Case, CaseError, load_case, read_text, set_key
from ..simulate import summary_keys
from .expressions import Expression, StudyError

DESIGNS = ("grid", "lhs", "sobol", "optimize")
SWEEP_KEYS = ("prefactor", "exponent", "prefactor_mass", "exponent_mass", "all_at_rest")
"""a sweep's numbers a study can ask for (sweep.<model>.<key>): the fits of the threshold
run-out and of the mass-quantile run-out (:func:`pdeflow.analysis.sweep.run_sweep`)"""
STUDY_KEYS = {"name", "description", "case", "set", "sweep_case", "function", "design",
              "samples", "seed", "population", "batch", "quantities"}
SECTIONS = {"study", "base_case", "parameters", "derived", "objectives"}
PARAMETER_KEYS = {"range", "values", "choices", "scale", "type", "points"}


# --- parameters -----------------------------------------------------------------------------
@dataclass(frozen=True)
class Parameter:
    """One varied key: a range (linear or log, float or int), values, or choices."""

    key: str
    low: float | None = None
    high: float | None = None
    scale: str = "linear"
    kind: str = "float"
    """'float', 'int' or 'choice' (values and choices are both 'choice')"""
    values: tuple[Any, ...] = ()
    points: int | None = None

    @classmethod
    def parse(cls, key: str, spec: Any) -> Parameter:
        where = f"parameters.{key!r}"
        if not isinstance(spec, dict):
            raise StudyError(f"{where} must be a table such as {{ range = [0, 1] }}")
        unknown = set(spec) - PARAMETER_KEYS
        if unknown:
            raise StudyError(f"{where}: unknown key {sorted(unknown)[0]!r}; allowed: "
                             f"{sorted(PARAMETER_KEYS)}")
        given = [k for k in ("range", "values", "choices") if k in spec]
        if len(given) != 1:
            raise StudyError(f"{where} needs exactly one of range, values, choices")
        if given[0] in ("values", "choices"):
            vals = spec[given[0]]
            if not isinstance(vals, list) or not vals:
                raise StudyError(f"{where}.{given[0]} must be a non-empty list")
            return cls(key, kind="choice", values=tuple(vals))
        rng = spec["range"]
        if (not isinstance(rng, list) or len(rng) != 2
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                           and math.isfinite(v) for v in rng)):
            raise StudyError(f"{where}.range must be [low, high] (two finite numbers), "
                             f"got {rng!r}")
        low, high = float(rng[0]), float(rng[1])
        if not low < high:
            raise StudyError(f"{where}.range is empty: low {rng[0]} must be below high "
                             f"{rng[1]}")
        scale = spec.get("scale", "linear")
        if scale not in ("linear", "log"):
            raise StudyError(f"{where}.scale must be 'linear' or 'log', got {scale!r}")
        if scale == "log" and low <= 0:
            raise StudyError(f"{where}: a log range must lie above 0, got {rng!r}")
        kind = spec.get("type", "float")
        if kind not in ("float", "int"):
            raise StudyError(f"{where}.type must be 'float' or 'int', got {kind!r}")
        points = spec.get("points")
        if points is not None and (not isinstance(points, int) or isinstance(points, bool)
                                   or points < 2):
            raise StudyError(f"{where}.points must be an integer >= 2, got {points!r}")
        return cls(key, low, high, scale, kind, (), points)

    def grid_values(self) -> list[Any]:
        """The values of a full-grid design."""
        if self.kind == "choice":
            return list(self.values)
        if self.points is None:
            raise StudyError(f"parameters.{self.key!r}.points is needed by the grid "
                             "design (or give values = [...])")
        u = [i / (self.points - 1) for i in range(self.points)]
        return list(dict.fromkeys(self.from_unit(x, endpoint=True) for x in u))

    def from_unit(self, u: float, endpoint: bool = False) -> Any:
        """Map u in [0, 1) (or [0, 1] with ``endpoint``) onto the parameter's values."""
        u = min(max(float(u), 0.0), 1.0)
        if self.kind == "choice":
            n = len(self.values)
            return self.values[min(int(u * n), n - 1)]
        assert self.low is not None and self.high is not None
        if self.kind == "int" and not endpoint:
            # equal cells for every integer, both ends included
            return int(min(math.floor(self.low + u * (self.high - self.low + 1)),
                           self.high))
        if self.scale == "log":
            x = math.exp(math.log(self.low) + u * (math.log(self.high) - math.log(self.low)))
        else:
            x = self.low + u * (self.high - self.low)
        return int(round(x)) if self.kind == "int" else float(x)

    def middle(self) -> Any:
        return self.from_unit(0.5)


# --- the study ------------------------------------------------------------------------------
@dataclass
class StudySpec:
    """A checked study file (see the module docstring)."""

    path: Path
    text: str
    name: str
    design: str
    parameters: list[Parameter]
    quantities: tuple[str, ...]
    derived: dict[str, Expression] = field(default_factory=dict)
    objectives: dict[str, Expression] = field(default_factory=dict)
    case: Case | None = None
    case_path: Path | None = None
    """the base case file (None for an inline [base_case] or a function)"""
    overrides: list[str] = field(default_factory=list)
    """study.set: fixed overrides of the base and sweep case"""
    sweep_case: Case | None = None
    function: str | None = None
    samples: int = 0
    seed: int = 0
    population: int = 16
    batch: int = 0
    description: str = ""
    fingerprint: str = ""
    """sha256 of the study file and the case files it reads"""

    @property
    def keys(self) -> list[str]:
        return [p.key for p in self.parameters]

    def models(self) -> list[str]:
        """Models whose summaries a point needs (only those are run)."""
        return [m for m in systems.names() if any(q.startswith(m + ".")
                                                  for q in self.quantities)]

    def sweep_models(self) -> list[str]:
        return [m for m in systems.names() if any(q.startswith(f"sweep.{m}.")
                                                  for q in self.quantities)]

    def columns(self) -> list[str]:
        """Quantity columns of the results table: measured, derived, objectives."""
        return [*self.quantities, *self.derived, *self.objectives]

    def case_for(self, base: Case, point: dict[str, Any], models: list[str]) -> Case:
        """``base`` with the point's values set, only ``models`` run, no snapshots."""
        case = base.copy()
        for key, value in point.items():
            try:
                set_key(case.data, key, value)  # a sub-table's too: terrain.topography.z0
            except ValueError as err:
                raise CaseError(f"{case.source}: {key}: {err}") from None
        case.data.setdefault("case", {})["models"] = list(models)
        case.data.setdefault("output", {})["snapshot_times"] = []
        case.validate()
        return case


def _study_err(path: Path, msg: str) -> StudyError:
    return StudyError(f"{path}: {msg}")


def _case(path: Path, raw: Any, overrides: list[str], key: str) -> Case:
    if not isinstance(raw, str):
        raise StudyError(f"study.{key} must be a case file name, got {raw!r}")
    try:
        return load_case(path.parent / raw, overrides)
    except CaseError as err:
        raise StudyError(f"study.{key}: {err}") from None


def _check_quantity(q: str, function: str | None, two_d: bool = False) -> None:
    """A quantity the runs give (``two_d``: the base case is 2D, its runs have the 2D
    summary's keys), else a StudyError naming the keys there are."""
    if function is not None:
        return
    parts = q.split(".")
    if parts[0] == "sweep":
        if len(parts) == 3 and parts[1] in systems.names() and parts[2] in SWEEP_KEYS:
            return
        raise StudyError(f"unknown quantity {q!r}: a sweep quantity is "
                         f"sweep.<{'|'.join(systems.names())}>.<{'|'.join(SWEEP_KEYS)}>")
    if len(parts) == 2 and parts[0] in systems.names():
        keys = summary_keys(parts[0], series=True, two_d=two_d)
        if parts[1] in keys:
            return
        raise StudyError(f"unknown quantity {q!r}: {parts[0]}'s run summary"
                         f"{' (2D)' if two_d else ''} has {', '.join(keys)}")
    raise StudyError(f"unknown quantity {q!r}: use <model>.<summary key> with model "
                     f"{' or '.join(systems.names())}, or sweep.<model>.exponent")


def load_study(path: str | Path) -> StudySpec:
    """Read and check a study file; raise :class:`StudyError` naming the key."""
    path = Path(path)
    text = read_text(path, "study file", StudyError)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise _study_err(path, f"not valid TOML: {err}") from None
    try:
        return _build(path, text, data)
    except StudyError as err:
        raise _study_err(path, str(err)) from None


def _build(path: Path, text: str, data: dict[str, Any]) -> StudySpec:
    """The checked study of a parsed study file: its keys, its design, what it runs,
    its parameters and expressions, its quantities; then every parameter's range is
    tried on the cases."""
    st = _study_table(data)
    design, ints = _design(st)
    overrides = st.get("set", [])
    if not isinstance(overrides, list) or not all(isinstance(s, str) for s in overrides):
        raise StudyError("study.set must be a list of 'section.key=value' strings")
    case, sweep_case, files = _sources(path, text, data, st, overrides)
    function = st.get("function")
    params_raw = data.get("parameters", {})
    if not params_raw:
        raise StudyError("[parameters] must name at least one parameter")
    parameters = [Parameter.parse(k, v) for k, v in params_raw.items()]
    derived = {k: Expression.parse(f"derived.{k}", v)
               for k, v in data.get("derived", {}).items()}
    objectives = {k: Expression.parse(f"objectives.{k}", v)
                  for k, v in data.get("objectives", {}).items()}
    if design == "optimize" and not objectives:
        raise StudyError("the optimize design needs [objectives] (expressions to minimise)")
    quantities = _quantity_names(st, derived, objectives, function,
                                 case is not None and case.is_2d)
    spec = StudySpec(
        path=path, text=text, name=str(st.get("name", path.stem)), design=design,
        parameters=parameters, quantities=tuple(quantities), derived=derived,
        objectives=objectives, case=case, sweep_case=sweep_case, function=function,
        case_path=path.parent / st["case"] if "case" in st else None, overrides=overrides,
        description=str(st.get("description", "")),
        fingerprint=hashlib.sha256("\0".join(files).encode()).hexdigest(), **ints)
    if any(q.startswith("sweep.") for q in quantities) and sweep_case is None:
        raise StudyError("sweep.* quantities need study.sweep_case (a case with [sweep])")
    _probe_ranges(spec)
    return spec


def _study_table(data: dict[str, Any]) -> dict[str, Any]:
    """The [study] table, once every section and study key is known."""
    for section in data:
        if section not in SECTIONS:
            raise StudyError(f"unknown section [{section}]; allowed: {sorted(SECTIONS)}")
    st = data.get("study", {})
    for key in st:
        if key not in STUDY_KEYS:
            raise StudyError(f"unknown key study.{key}; allowed: {sorted(STUDY_KEYS)}")
    return st


def _design(st: dict[str, Any]) -> tuple[str, dict[str, int]]:
    """study.design and its integers (samples, seed, population, batch), checked."""
    design = st.get("design", "grid")
    if design not in DESIGNS:
        raise StudyError(f"study.design must be one of {', '.join(DESIGNS)}; got "
                         f"{design!r}")
    ints = {}
    for key, default, low in (("samples", 0, 1), ("seed", 0, 0), ("population", 16, 2),
                              ("batch", 0, 0)):
        v = st.get(key, default)
        if not isinstance(v, int) or isinstance(v, bool) or (v < low and key in st):
            raise StudyError(f"study.{key} must be an integer >= {low}, got {v!r}")
        ints[key] = v
    if design != "grid" and ints["samples"] < 1:
        raise StudyError(f"study.samples (>= 1) is needed by the {design} design")
    if design == "sobol" and ints["samples"] & (ints["samples"] - 1):
        raise StudyError(f"study.samples must be a power of 2 for the sobol design "
                         f"(Saltelli/Sobol' sequence), got {ints['samples']}")
    return design, ints


def _sources(path: Path, text: str, data: dict[str, Any], st: dict[str, Any],
             overrides: list[str]) -> tuple[Case | None, Case | None, list[str]]:
    """What the study runs: (base case, sweep case, the texts of the files read); the
    base case is a file, an inline [base_case] or none (a study.function)."""
    function = st.get("function")
    sources = [k for k in ("case", "function") if k in st] + (
        ["base_case"] if "base_case" in data else [])
    if len(sources) != 1:
        raise StudyError("give exactly one of study.case, [base_case] or study.function")
    files = [text]
    case = sweep_case = None
    if "case" in st:
        case = _case(path, st["case"], overrides, "case")
        files.append((path.parent / st["case"]).read_text())
    elif "base_case" in data:
        try:
            case = Case(dict(data["base_case"]), f"{path} [base_case]",
                        path.resolve().parent)
            for item in overrides:
                case.set(item)
            case.validate()
        except CaseError as err:
            raise StudyError(str(err)) from None
    elif not (isinstance(function, str) and ":" in function):
        raise StudyError(f"study.function must be 'module:callable', got {function!r}")
    if "sweep_case" in st:
        sweep_case = _case(path, st["sweep_case"], overrides, "sweep_case")
        files.append((path.parent / st["sweep_case"]).read_text())
    return case, sweep_case, files


def _quantity_names(st: dict[str, Any], derived: dict[str, Expression],
                    objectives: dict[str, Expression], function: str | None,
                    two_d: bool = False) -> list[str]:
    """study.quantities and every quantity an expression reads, each checked (against
    a 2D run's summary if ``two_d``)."""
    listed = st.get("quantities", [])
    if not isinstance(listed, list) or not all(isinstance(q, str) for q in listed):
        raise StudyError("study.quantities must be a list of names")
    quantities = list(dict.fromkeys(listed))
    for exprs in (derived, objectives):
        for expr in exprs.values():
            for n in expr.names:
                if n in derived or n in quantities:
                    continue
                if "." not in n and function is None:
                    raise StudyError(f"{expr.name}: unknown name {n!r} (not a quantity or "
                                     f"a name in [derived])")
                quantities.append(n)
    for q in quantities:
        try:
            _check_quantity(q, function, two_d)
        except StudyError as err:
            raise StudyError(f"study.quantities: {err}") from None
    if not quantities:
        raise StudyError("study.quantities is empty (and no expression reads a quantity)")
    return quantities


def _probe_ranges(spec: StudySpec) -> None:
    """Every parameter must be a case key that takes every value of its range: try
    its ends (or each of its values) on the base and the sweep case."""
    bases = [b for b in (spec.case, spec.sweep_case) if b is not None]
    if not bases:
        return
    for p in spec.parameters:
        probes = p.values if p.kind == "choice" else (p.from_unit(0.0), p.from_unit(1.0))
        for value in probes:
            for base in bases:
                if "." not in p.key:
                    raise StudyError(f"parameters.{p.key!r}: a case key is "
                                     "'section.key', e.g. 'two_layer.c'")
                try:
                    spec.case_for(base, {p.key: value}, base.models)
                except CaseError as err:
                    raise StudyError(f"parameters.{p.key!r} = {value!r}: {err}") from None
