"""What a run will cost before it starts, and what its numbers mean after it ends.

Before a run, from the case alone (no arrays are made):

* :func:`run_cost` estimates memory and work: cells, time steps (from the CFL
  condition with the a-priori wave speed 2 sqrt(g_z H) + g_x t, H the largest initial
  depth, over the estimated duration: t_end, or, where Coulomb friction stops the flow,
  the estimated stop time :data:`REST_TIME_FACTOR` sqrt(H/g_z) / (1 - tan(theta) /
  tan(phi_b))), cell updates and a rough wall time;
* :func:`check_memory` refuses a grid that needs more memory than the machine has
  (``Case.validate`` calls it), :func:`cost_warning` describes a long run;
* :func:`solver_warning`: py-pde's method-of-lines solvers do not keep the model's
  set-valued Coulomb friction and never stop at rest;
* :func:`slope_warning`: the models of one case set on different slopes.

After a run, :func:`domain_ends` finds material that reached an end of the domain and
:func:`result_warnings` says what would mislead in the summary: a run still moving at
t_end, a mass that changed, a front at the end of the domain (its run-out is then only a
lower bound). ``run_model`` issues these as :class:`RunWarning`; the command line prints
each as one line ``pdeflow: warning: ...`` and the app shows the same lines on its
page: both collect them with :func:`run_warnings`.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import systems
from .initial_shapes import is_column
from .initial_shapes_2d import SHAPES_2D
from .metrics import total_depth
from .numerics.geometry import COORDINATES

#: cells x steps per second of the compiled fv-split loop on this development machine:
#: 0.9e7 (two layers, test 5.1, dx = 0.05 m) to 1.3e8 over the cases in cases/ (dry
#: cells cost little); the slow end, only used to put the work into words
CELL_UPDATES_PER_S = 1e7
#: a run estimated above this many cell updates (100 s at the rate above) is announced
#: with its estimate, and the command line shows its progress bar
LONG_RUN_CELL_UPDATES = 1e9
#: stop times of the cases in cases/ (two layers and one, 5.2 at a = 2, 10, 30) are
#: 1.7 .. 3.5 sqrt(H/g_z), divided by the slope factor 1 - tan(theta)/tan(phi_b)
REST_TIME_FACTOR = 4.0
#: relative change of the mass above which a run is warned about (fv-split: round-off)
MASS_WARN = 1e-6
SIDES = ("left", "right")


class RunWarning(UserWarning):
    """A run or a result that could mislead (printed by the CLI as one line)."""


WARNING_PREFIX = "pdeflow: warning: "
"""What starts each warning line of the command line and of the app's page."""


@contextmanager
def run_warnings(show: Callable[[str], None]) -> Iterator[None]:
    """Within the block, pass every :class:`RunWarning` to ``show`` as one line
    ``pdeflow: warning: <message>``, each message once (the solver's warning, e.g., is
    issued for every model); other warnings are shown as usual.

    The command line prints the lines to stderr, the app's pages show them; one
    function, so that both say the same.
    """
    original = warnings.showwarning
    shown: set[str] = set()

    def showwarning(message: Any, category: type, *args: Any, **kwargs: Any) -> None:
        if not issubclass(category, RunWarning):
            original(message, category, *args, **kwargs)
        elif str(message) not in shown:
            shown.add(str(message))
            show(f"{WARNING_PREFIX}{message}")

    with warnings.catch_warnings():
        warnings.simplefilter("always", RunWarning)
        warnings.showwarning = showwarning
        yield


@dataclass
class RunCost:
    """Estimated cost of running one model of a case (see :func:`run_cost`)."""

    cells: int
    memory_bytes: float
    """peak memory of the run [bytes]"""
    steps: float
    """time steps (an estimate from above: the wave speed falls as the flow slows)"""
    duration: float
    """simulated time [s]: t_end, or the estimated stop time where friction stops it"""
    cell_updates: float
    """steps x cells"""

    @property
    def seconds(self) -> float:
        """Rough wall time [s] at :data:`CELL_UPDATES_PER_S`."""
        return self.cell_updates / CELL_UPDATES_PER_S

    @property
    def long(self) -> bool:
        """More than :data:`LONG_RUN_CELL_UPDATES` cell updates."""
        return self.cell_updates > LONG_RUN_CELL_UPDATES


def _bytes(n: float) -> str:
    for unit in ("bytes", "kB", "MB", "GB"):
        if n < 1000:
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} TB"


def _duration(s: float) -> str:
    if s < 120:
        return f"{s:.2g} s"
    if s < 7200:
        return f"{s / 60:.2g} min"
    if s < 2 * 86400:
        return f"{s / 3600:.2g} h"
    return f"{s / 86400:.2g} days"


def max_initial_depth(case: Any) -> float:
    """Largest initial total depth [m], from the case's keys (from the file for 'file')."""
    ini = case.initial
    shape = ini.get("shape")
    if is_column(ini) or shape in SHAPES_2D:
        return float(ini["H0"])
    if shape == "dam_break":
        return max(float(ini["h_left"]), float(ini.get("h_right", 0.0)))
    if shape == "heap":
        return float(ini["height"])
    profiles = case.initial_profiles(case.models[0])  # h1, u1, h2, u2 or h, u
    return float(np.max(total_depth(np.stack(list(profiles.values())))))


def memory_bytes(case: Any, model: str) -> float:
    """Peak memory [bytes] of running ``model``: the solver's arrays and the snapshots."""
    system = systems.get(model)
    rows = len(system.field_names)
    frames = len(case.snapshot_times) + case.series_frames  # snapshots, erosion series
    per_cell = system.bytes_per_cell + 8 * (rows + 1) * frames
    if case.is_2d:  # a third row per layer (the discharge across): 1.5 times the 1D
        per_cell = per_cell * 3 // 2
    return float(case.total_cells * per_cell)


def run_cost(case: Any, model: str | None = None) -> RunCost:
    """Memory and work of running ``model`` (default: the case's model with the most
    fields, the costliest)."""
    model = model or max(case.models, key=lambda m: len(systems.get(m).field_names))
    params = case.make_pde(model).parameters
    theta = math.radians(params.theta_deg)
    gz, gx = params.g * math.cos(theta), params.g * math.sin(theta)
    depth = max_initial_depth(case)
    if case.solver != "fv-split":  # py-pde's solvers step with numerics.dt to t_end
        steps = case.t_end / float(case.data.get("numerics", {}).get("dt", 1e-4))
        return RunCost(case.total_cells, memory_bytes(case, model), steps,
                       case.t_end, steps * case.total_cells)
    duration = case.t_end
    if stops_by_friction(params):
        slope = 1 - math.tan(theta) / math.tan(math.radians(params.phi_b_deg))
        duration = min(duration, REST_TIME_FACTOR * math.sqrt(depth / gz) / slope)
    speed = 2 * math.sqrt(gz * depth) + abs(gx) * duration
    # the CFL step of a 2D grid is cfl / (s/dx + s/dy)
    inverse_widths = 1 / case.dx + (1 / case.dy if case.is_2d else 0.0)
    steps = duration * speed * inverse_widths / case.cfl
    return RunCost(case.total_cells, memory_bytes(case, model), steps, duration,
                   steps * case.total_cells)


def stops_by_friction(params: Any) -> bool:
    """A Coulomb mass on a bed flatter than its friction angle comes to rest in finite
    time; frictionless cases (exact solutions, phi_b within 1 deg of the slope) do not."""
    return bool(params.basal_friction_deg > params.theta_deg + 1.0)


def physical_memory() -> int | None:
    """Physical memory of the machine [bytes], None where it cannot be read."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return None


def check_memory(case: Any) -> None:
    """Raise ValueError if the grid needs more memory than the machine has."""
    have = physical_memory()
    need = max(memory_bytes(case, m) for m in case.models)
    if have is None or need <= have:
        return
    cells_max = int(case.total_cells * have / need)
    # the cells scale as dx^-1 in 1D, as dx^-2 in 2D (dy with dx)
    dx_min = case.dx * (need / have) ** 0.5 if case.is_2d else case.length / cells_max
    across = " and grid.dy" if case.is_2d else ""
    raise ValueError(
        f"the grid has {case.total_cells:,} cells, which need about {_bytes(need)} of "
        f"memory, more than this machine has ({_bytes(have)}): use at most about "
        f"{cells_max:,} cells (grid.dx{across} >= {dx_min:.3g} m)")


def cost_warning(case: Any, model: str) -> str | None:
    """A description of the estimated cost if the run is long or needs more than half
    the machine's memory, else None."""
    cost = run_cost(case, model)
    have = physical_memory()
    if not cost.long and (have is None or cost.memory_bytes < have / 2):
        return None
    until = ("t_end" if cost.duration == case.t_end else "the estimated stop time")
    return (f"{case.name}, {model}: {cost.cells:,} cells (dx = {case.dx:.3g} m) and "
            f"about {cost.steps:.2g} time steps to {until}, t = {cost.duration:.3g} s: "
            f"about {cost.cell_updates:.2g} cell updates, roughly "
            f"{_duration(cost.seconds)} at {CELL_UPDATES_PER_S:.0e} per s, and "
            f"{_bytes(cost.memory_bytes)} of memory")


def solver_warning(case: Any) -> str | None:
    """Why a py-pde (method-of-lines) solver misleads here, or None for fv-split."""
    if case.solver == "fv-split":
        return None
    return (f"numerics.solver = {case.solver!r} integrates the method-of-lines rate: it "
            "replaces the set-valued Coulomb friction by a regularised one (mol_eps), so "
            "nothing is held at rest and deposits creep, it never stops at rest (it runs "
            "to t_end), and it clips negative depths (the mass changes); stop times and "
            "run-outs are not the model's. Use numerics.solver = 'fv-split' (the paper's "
            "scheme) for them")


def slope_warning(case: Any) -> str | None:
    """Why the models of ``case`` cannot be compared if they run on different slopes
    (their ``theta_deg``, or in 2D ``slope_azimuth_deg``; e.g. one model's slope set on
    the command line), else None."""
    params = {m: systems.get(m).parameters_class.from_dict(case.data.get(m, {}))
              for m in case.models}
    slopes = {m: p.theta_deg for m, p in params.items()}
    azimuths = {m: p.slope_azimuth_deg for m, p in params.items()}
    if len(set(slopes.values())) < 2 and len(set(azimuths.values())) > 1:
        listed = ", ".join(f"{m}.slope_azimuth_deg = {a:g}" for m, a in azimuths.items())
        return (f"{case.name}: the models' planes are inclined along different directions "
                f"({listed} deg), so their results are not comparable; set them alike")
    if len(set(slopes.values())) < 2:
        return None
    steepest = max(slopes.values())
    listed = ", ".join(f"{m}.theta_deg = {t:g}" for m, t in slopes.items())
    fix = " ".join(f"--set {m}.theta_deg={steepest:g}" for m, t in slopes.items()
                   if t != steepest)
    return (f"{case.name}: the models run on different slopes ({listed} deg), so their "
            f"results are not comparable; set them alike (e.g. {fix})")


def domain_ends(case: Any, initial: np.ndarray, final: np.ndarray,
                mass_change: float, bed: np.ndarray | None = None) -> dict[str, Any]:
    """Where material reached an end of the domain that was clear of it initially.

    An end counts as reached if its outermost cell is deeper than the front threshold
    at the end (for the right end: the front is at the end of the domain), or, at an
    open end, if mass was lost (``mass_change`` < -1e-9, relative) and that cell was
    dry initially. Returns ``sides`` (a list of 'left'/'right'), ``outflow`` (the
    relative mass lost through open ends, 0 if none), ``runout_lower_bound`` (the
    right end was reached, so the material could have gone further) and
    ``open_through_material`` (open ends with material at t = 0, e.g. the reservoir of
    a dam break: mass flows in or out there by design). Depths are measured above the
    initial erodible ``bed`` [m] if given: a bed at rest that reaches an end is no
    material reaching it.
    """
    thr = case.front_threshold
    h0, h1 = total_depth(initial), total_depth(final)
    if bed is not None:
        h0, h1 = h0 - bed, h1 - bed
    lost = -mass_change if mass_change < -1e-9 else 0.0
    sides, reservoirs = [], []
    for (side, i), bc in zip((("left", 0), ("right", -1)), case.bc, strict=True):
        if side == "left" and case.geometry == "axisymmetric":
            continue  # the axis is no end of the domain
        if h0[i] > thr:  # material there from the start: a reservoir cut by the end,
            if bc == "open":  # through which mass flows in or out by design
                reservoirs.append(side)
        elif h1[i] > thr or (lost and bc == "open"):
            sides.append(side)
    outflow = lost if any(case.bc[SIDES.index(s)] == "open" for s in sides) else 0.0
    return {"sides": sides, "outflow": outflow, "runout_lower_bound": "right" in sides,
            "open_through_material": reservoirs}


def mass_through_ends(summary: dict[str, Any]) -> float | None:
    """The relative mass that left (> 0) or entered (< 0) the domain through its open
    ends in a run with ``summary``, where that is what changed the mass: material
    reached an open end and the mass fell, or an open end cuts material from the start
    (a reservoir), by more than :data:`MASS_WARN`. None otherwise: the mass change is
    then the conservation error."""
    ends = summary.get("domain_ends") or {}
    change = summary.get("mass_change", 0.0)
    through = (ends.get("outflow") and change < 0) or ends.get("open_through_material")
    return -change if through and abs(change) > MASS_WARN else None


def _end(case: Any, side: str) -> str:
    """'the open right end (x = 7 m)' or 'the wall at the left end (x = 0 m)' ('r' on an
    axisymmetric grid)."""
    kind = "open" if case.bc[SIDES.index(side)] == "open" else "wall at the"
    x = case.x_start + (case.length if side == "right" else 0.0)
    coordinate = COORDINATES[case.geometry]
    return f"the {kind} {side} end ({coordinate} = {x:g} m)"


def _percent(p: float) -> str:
    """A percentage to two digits ('25', '9.8'), and '100' (not '1e+02')."""
    return f"{p:.2g}" if p < 99.5 else f"{p:.0f}"


def result_warnings(case: Any, model: str, summary: dict[str, Any]) -> list[str]:
    """What in a finished run's ``summary`` could mislead, one sentence each."""
    out = []
    name = f"{case.name}, {model}"
    ends = summary.get("domain_ends") or {}
    if ends.get("sides"):
        where = " and ".join(_end(case, s) for s in ends["sides"])
        left = (f", and {_percent(100 * ends['outflow'])} % of the mass left the domain"
                if ends["outflow"] else "")
        front = summary.get("front_position")
        # no front when every cell is dry: all the material has left the domain
        shown = f" ({front:.4g} m)" if front is not None else " (none left)"
        bound = (f": the front{shown} and the run-out are lower bounds, lengthen the "
                 "domain (grid.length)" if ends.get("runout_lower_bound") else "")
        out.append(f"{name}: material reached {where}{left}{bound}")
    change = summary.get("mass_change", 0.0)
    if abs(change) > MASS_WARN and mass_through_ends(summary) is None:
        why = (" (py-pde's solvers clip negative depths)" if case.solver != "fv-split"
               else "")
        out.append(f"{name}: the mass changed by {100 * change:+.3g} % during the "
                   f"run{why}")
    if not summary.get("at_rest") and stops_by_friction(case.make_pde(model).parameters):
        mol = (" (method-of-lines solvers never stop at rest)"
               if case.solver != "fv-split" else "; raise case.t_end")
        out.append(f"{name}: still moving at the end of the run (t = "
                   f"{summary['t_final']:.4g} s): the stop times are unknown and the "
                   f"deposit is not final{mol}")
    return out
