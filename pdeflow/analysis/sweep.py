"""Aspect-ratio sweeps of column collapses and the run-out scaling law (paper test 5.2).

A sweep case is an ordinary case file with a ``[sweep]`` section::

    [sweep]
    aspect_ratios = [2, 3, 4, 6, 8, 10, 14, 18, 24, 30]   # a = H0 / L0

For every a the column height is set to H0 = a L0 and every model of the case is run to
rest; the normalised run-out r = (R - L0)/L0 uses the front position R (downstream face
of the last cell with total depth above ``output.front_threshold``), and
r_mass = (R_mass - L0)/L0 the mass-quantile front R_mass (the distance from the rear
wall, or the axis, that holds ``output.runout_mass_fraction`` of the mass, 99 % by
default; :func:`pdeflow.metrics.mass_quantile_position`), which converges with the grid
where R follows a thin tail. A power law r = p a^e is fitted by least squares on log r
against log a, for each measure (``prefactor``, ``exponent``; ``prefactor_mass``,
``exponent_mass``). A 2D case (``grid.width``) sweeps its release in the same way
(:mod:`pdeflow.analysis.sweep_2d`: L0 its extent along x, the 2D summary's numbers per
row, no paper's law to compare). The paper reports
r = 2.25 a^1.06 (single layer, phi_B = 30 deg) and r = 1.61 a^0.84 (two layers); the DEM
of Lacaze et al. (2008) gives the exponent 0.83 +- 0.03.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from .. import systems
from ..cases import PAPER_MODEL, Case, CaseError, load_case
from ..numerics.warmup import prepare
from ..simulate import case_steppers
from ..study.core import Executor, Study, serial
from .points import Point, with_sets
from .sweep_2d import release_length, row_2d, runs_table

DEM_EXPONENT = 0.83

PUBLISHED_LAWS = {"Lube et al. 2005": (1.8, 2.8), "Lajeunesse et al. 2005": (2.3, 2.3)}
"""Planar-collapse experiments (Lube, Huppert, Sparks & Freundt 2005, "Collapses of
two-dimensional granular columns", Phys. Rev. E 72, 041301; Lajeunesse, Monnier & Homsy
2005, "Granular slumping on a horizontal surface", Phys. Fluids 17, 103302): r = 1.2 a
below the first a given, r = 1.9 a^(2/3) above the second; in between a transition that
neither law describes."""
PUBLISHED_EXPONENTS = {"Balmforth & Kerswell 2005 (wide)": (0.9, 0.1),
                       "Balmforth & Kerswell 2005 (narrow)": (0.65, None),
                       "Lacaze et al. 2008 (DEM)": (DEM_EXPONENT, 0.03)}
"""Laws given as an exponent only, r ~ a^e: name -> (e, its uncertainty or None).
Balmforth & Kerswell 2005, Granular collapse in two dimensions, J. Fluid Mech. 538,
399-428; Lacaze, Phillips & Kerswell 2008, Planar collapse of a granular column:
experiments and discrete element simulations, Phys. Fluids 20, 063302."""


def published_law(name: str, a: np.ndarray, bridge: bool = False) -> np.ndarray:
    """r(a) of the law ``name`` of :data:`PUBLISHED_LAWS`: NaN in its transition, or
    with ``bridge`` the large-a branch there too (one curve to compare a run with)."""
    a = np.asarray(a, dtype=float)
    low, high = PUBLISHED_LAWS[name]
    r = np.where(a < low, 1.2 * a, 1.9 * a ** (2 / 3))
    return r if bridge else np.where((a >= low) & (a <= high) & (low < high), np.nan, r)


def fit_power_law(a: np.ndarray, r: np.ndarray) -> tuple[float, float]:
    """Least-squares fit of log r = log p + e log a; returns (p, e)."""
    a = np.asarray(a, dtype=float)
    r = np.asarray(r, dtype=float)
    ok = (a > 0) & (r > 0)
    if ok.sum() < 2:
        raise ValueError("a power-law fit needs at least two positive run-outs")
    e, logp = np.polyfit(np.log(a[ok]), np.log(r[ok]), 1)
    return float(np.exp(logp)), float(e)


def sweep_length(case: Case) -> float | None:
    """The length L0 [m] that H0 = a L0 scales: ``initial.L0`` (the column's), on a 2D
    grid the release's extent along x (:func:`~pdeflow.analysis.sweep_2d.release_length`);
    None for a 1D case without a column."""
    return release_length(case) if case.is_2d else case.L0


def sweep_ratios(case: Case) -> list[float]:
    """The case's ``sweep.aspect_ratios``; CaseError if it has none or no column."""
    ratios = case.data.get("sweep", {}).get("aspect_ratios", [])
    if not ratios:
        raise CaseError(f"{case.source}: a sweep needs a [sweep] section with "
                        "aspect_ratios = [a, ...] (a = H0/L0 > 0), as in "
                        "cases/collapse_sweep.toml, or --set 'sweep.aspect_ratios=[2, 4]'")
    if any(isinstance(a, bool) or not isinstance(a, (int, float)) or not a > 0
           for a in ratios):
        raise CaseError(f"{case.source}: sweep.aspect_ratios must be numbers > 0, got "
                        f"{ratios!r}")
    if sweep_length(case) is None:
        raise CaseError(f"{case.source}: a sweep needs initial.L0 (shape = 'column')")
    return [float(a) for a in ratios]


def _runout_numbers(s: dict[str, Any], L0: float) -> dict[str, Any]:
    """The run-out numbers of one run's summary ``s`` (L0 [m]: column length or radius)."""
    r = None if s["runout"] is None else s["runout"] / L0
    q = s["runout_mass_quantile"]
    return {"r": r, "runout": s["runout"], "r_mass": None if q is None else q / L0,
            "runout_mass": q, "stop_time": s["stop_time"],
            "at_rest": s["at_rest"], "steps": s["steps"], "wall_time_s": s["wall_time_s"],
            "mass_relative_error": s["mass_relative_error"]}


def runout_row(point: Point) -> dict[str, Any]:
    """Measure of :func:`run_sweep`: the run-out of one column run to rest."""
    return _runout_numbers(point.run().execute().summary, point.case.L0)


def deposit_numbers(x: np.ndarray, depth: np.ndarray, L0: float, H0: float,
                    stop_time: float | None, g: float = 9.81) -> dict[str, Any]:
    """The deposit of a column of length (radius) L0 [m] and height H0 [m] at rest:
    its final height H_inf = max total depth [m] (``depth`` per cell at cell centres
    ``x`` [m]), H_inf/L0, H_inf/H0, the radius of its undisturbed top (where the depth
    is still H0 to 1e-9 m) over L0, and the arrest time over (H0/g)^(1/2)."""
    h_inf = float(np.max(depth))
    top = np.nonzero(np.abs(depth - H0) <= 1e-9)[0]
    dx = float(x[1] - x[0]) if x.size > 1 else 0.0
    return {"final_height": h_inf, "H_inf_over_L0": h_inf / L0, "H_inf_over_H0": h_inf / H0,
            "top_radius_over_L0": float(x[top[-1]] + dx / 2) / L0 if top.size else 0.0,
            "arrest_time_scaled": (None if stop_time is None
                                   else stop_time / float(np.sqrt(H0 / g)))}


def deposit_row(point: Point) -> dict[str, Any]:
    """Measure of :func:`run_sweep` on an axisymmetric case: :func:`runout_row` and the
    deposit's :func:`deposit_numbers` (final height, undisturbed top, arrest time)."""
    res = point.run().execute()
    case = point.case
    row = _runout_numbers(res.summary, case.L0)
    g = float(getattr(res.pde.parameters, "g", 9.81))
    row.update(deposit_numbers(res.x, res.state.data[::2].sum(axis=0), case.L0,
                               float(case.initial["H0"]), res.summary["stop_time"], g))
    return row


def _fit(rows: list[dict[str, Any]], key: str) -> tuple[float | None, float | None]:
    """(p, e) of r = p a^e over the ``rows`` at rest with a run-out ``key`` ('r' or
    'r_mass'), or (None, None) with fewer than two."""
    good = [(row["a"], row[key]) for row in rows if row[key] and row["at_rest"]]
    return fit_power_law(*zip(*good, strict=True)) if len(good) >= 2 else (None, None)


def run_sweep(case: Case, aspect_ratios: list[float] | None = None,
              models: list[str] | None = None,
              executor: Executor = serial, progress: bool = False) -> dict[str, Any]:
    """Run every model at every aspect ratio; return the sweep summary (``progress``: a
    bar over the runs on stderr).

    A :class:`~pdeflow.study.core.Study`: one point per model and aspect ratio a
    (the case with H0 = a L0, no snapshots), measured by :func:`runout_row` (on an
    axisymmetric case by :func:`deposit_row`: the final height and arrest time too; on
    a 2D case by :func:`~pdeflow.analysis.sweep_2d.row_2d`: the 2D summary's numbers).
    """
    ratios = aspect_ratios or sweep_ratios(case)
    L0 = sweep_length(case)
    if L0 is None:
        raise CaseError(f"{case.source}: a sweep needs initial.L0 (shape = 'column')")
    models = models or case.models
    out: dict[str, Any] = {"case": case.name, "L0": L0, "dx": case.dx,
                           **({"dy": case.dy} if case.is_2d else {}),
                           "front_threshold": case.front_threshold,
                           "runout_mass_fraction": case.runout_mass_fraction, "models": {}}
    points = [Point(with_sets(case, [f"initial.H0={float(a) * L0!r}",
                                     "output.snapshot_times=[]"]), model,
                    labels={"model": model, "a": float(a)})
              for model in models for a in ratios]
    wall0 = time.perf_counter()
    measure = (row_2d if case.is_2d else
               deposit_row if case.geometry == "axisymmetric" else runout_row)
    table = Study(points, measure).execute(executor, "sweep" if progress else None)
    for model in models:
        rows = [{k: v for k, v in row.items() if k != "model"} for row in table
                if row["model"] == model]
        p, e = _fit(rows, "r")
        p_mass, e_mass = _fit(rows, "r_mass")
        paper = systems.get(model).paper_runout_law or (None, None)
        out["models"][model] = {
            "points": [[row["a"], row["r"]] for row in rows],
            "points_mass": [[row["a"], row["r_mass"]] for row in rows],
            "runs": rows,
            "prefactor": p,
            "exponent": e,
            "prefactor_mass": p_mass,
            "exponent_mass": e_mass,
            # the paper's laws are planar (1D); a 2D release has none to compare
            "paper_prefactor": None if case.is_2d else paper[0],
            "paper_exponent": None if case.is_2d else paper[1],
            "all_at_rest": all(row["at_rest"] for row in rows),
        }
    out["wall_time_s"] = time.perf_counter() - wall0
    return out


def sweep_figure(summary: dict[str, Any], path: str | Path) -> Path:
    """Log-log plot of r against a with the fits, the paper's fits and the DEM slope; the
    mass-quantile run-outs r_mass hollow (summaries without them: left out)."""
    import matplotlib.pyplot as plt

    from ..plotting import ASPECT_TICKS, log_ticks, save

    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    from ..plotting import LAYER_STYLES

    markers = ("s", "o", "^", "v", "D")  # by registration: two layers, single layer, ...
    amin, amax = np.inf, 0.0
    rs: list[float] = []
    for model, res in summary["models"].items():
        system = systems.get(model)
        color = LAYER_STYLES[system.layers[0].style][2]
        marker = markers[systems.names().index(model) % len(markers)]
        label = system.label
        pts = np.array([p for p in res["points"] if p[1]], dtype=float)
        if pts.size == 0:
            continue
        amin, amax = min(amin, pts[:, 0].min()), max(amax, pts[:, 0].max())
        rs.extend(pts[:, 1])
        ax.loglog(pts[:, 0], pts[:, 1], marker, color=color, label=f"{label}")
        mass_pts = np.array([p for p in res.get("points_mass", []) if p[1]], dtype=float)
        if mass_pts.size:  # the mass-quantile run-outs: hollow, the same colour
            rs.extend(mass_pts[:, 1])
            fit = (f", fit {res['prefactor_mass']:.2f} a^{res['exponent_mass']:.2f}"
                   if res.get("prefactor_mass") else "")
            ax.loglog(mass_pts[:, 0], mass_pts[:, 1], marker, color=color, mfc="none",
                      label=f"{label}, {100 * summary['runout_mass_fraction']:.4g}% of "
                            f"the mass{fit}")
        aa = np.geomspace(pts[:, 0].min(), pts[:, 0].max(), 50)
        if res["prefactor"]:
            ax.loglog(aa, res["prefactor"] * aa ** res["exponent"], "-", color=color,
                      lw=1, label=f"fit {res['prefactor']:.2f} a^{res['exponent']:.2f}")
        p, e = res["paper_prefactor"], res["paper_exponent"]
        if p is not None:
            ax.loglog(aa, p * aa**e, ":", color=color, lw=1, label=f"paper {p} a^{e}")
    if amax > 0:
        aa = np.geomspace(amin, amax, 50)
        two = summary["models"].get(PAPER_MODEL, {})
        anchor = (two.get("prefactor") or 1.0) * amin ** (two.get("exponent") or DEM_EXPONENT)
        ax.loglog(aa, anchor * (aa / amin) ** DEM_EXPONENT, "--", color="gray", lw=1,
                  label=f"DEM slope a^{DEM_EXPONENT} (Lacaze et al.)")
    if amax > 0:
        log_ticks(ax.xaxis, [a for a in ASPECT_TICKS if amin <= a <= amax] or [amin, amax])
        decades = 10.0 ** np.arange(np.floor(np.log10(min(rs))), np.log10(max(rs)) + 1)
        log_ticks(ax.yaxis, [m * d for d in decades for m in (1, 2, 5)])
    ax.set_xlabel("aspect ratio a = H0/L0")
    ax.set_ylabel("normalised run-out r = (R - L0)/L0")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    return save(fig, path)


def add_arguments(ap: Any) -> None:
    """The options of ``pdeflow sweep``."""
    ap.add_argument("case", help="sweep case file (a column case, or a 2D release, with a "
                    "[sweep] section)")
    ap.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                    help="override a case value (repeatable)")
    ap.add_argument("--summary", metavar="OUT.json", help="write the sweep summary here")
    ap.add_argument("--plot", metavar="OUT.png", help="write the r(a) figure here")
    ap.add_argument("-q", "--quiet", action="store_true", help="print nothing")


def cmd_sweep(args: Any) -> int:
    """``pdeflow sweep``: run the sweep described by parsed ``args``; print the fits."""
    from .. import io
    from ..outpaths import FIGURE_SUFFIXES, check_file

    check_file(args.summary, "--summary", (".json",))
    check_file(args.plot, "--plot", FIGURE_SUFFIXES)
    case = load_case(args.case, args.set)
    sweep_ratios(case)  # before any run
    prepare(case_steppers(case), log=None if args.quiet else sys.stderr)
    summary = run_sweep(case, progress=not args.quiet and sys.stderr.isatty())
    written = []
    if args.summary:
        written.append(io.write_json(args.summary, summary))
    if args.plot:
        written.append(sweep_figure(summary, args.plot))
    if not args.quiet:
        for model, res in summary["models"].items():
            pts = ", ".join(f"{a:g}:{r:.3g}" if r else f"{a:g}:-" for a, r in res["points"])
            fit = (f"r = {res['prefactor']:.3g} a^{res['exponent']:.3f}"
                   if res["prefactor"] else "no fit")
            paper = ("" if case.is_2d else f"   (paper {res['paper_prefactor']} "
                     f"a^{res['paper_exponent']})")
            print(f"{model:13} {fit}{paper}   a:r {pts}")
            _print_mass_fit(model, res, summary["runout_mass_fraction"],
                            "radius about the centre" if case.is_2d else "front")
            if res["runs"] and "H_inf_over_L0" in res["runs"][0]:  # axisymmetric
                print(f"{'':13} a:H_inf/R0 " + ", ".join(
                    f"{row['a']:g}:{row['H_inf_over_L0']:.3g}" for row in res["runs"])
                    + "   a:t_stop/(H0/g)^(1/2) " + ", ".join(
                    f"{row['a']:g}:{row['arrest_time_scaled']:.3g}" if row["arrest_time_scaled"]
                    else f"{row['a']:g}:-" for row in res["runs"]))
            if case.is_2d:
                print(runs_table(res["runs"]))
        print(f"wall time {summary['wall_time_s']:.2f} s")
        for path in written:
            print(f"wrote {path}")
    return 0


def _print_mass_fit(model: str, res: dict[str, Any], fraction: float,
                    what: str = "front") -> None:
    """The line of the mass-quantile run-outs of one model's sweep (``what``: the
    measure holding the mass, a 1D front or a 2D radius)."""
    pts = ", ".join(f"{a:g}:{r:.3g}" if r else f"{a:g}:-" for a, r in res["points_mass"])
    fit = (f"r_mass = {res['prefactor_mass']:.3g} a^{res['exponent_mass']:.3f}"
           if res["prefactor_mass"] else "r_mass: no fit")
    print(f"{'':13} {fit}   ({what} holding {100 * fraction:.4g}% of the mass)   "
          f"a:r_mass {pts}")
