"""Numbers, figures and text of docs/erodible_bed.md from the rows of
docs/generate/erodible_bed.py (:func:`page_numbers`, :func:`figures`, :func:`render_page`).

The text is a function of the numbers (docs/erodible_bed/numbers.json): every number on
the page, and every "grows" or "shrinks", is computed from the cached runs.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from erodible_bed import (
    BEDS,
    CLOSURES,
    COARSE,
    DU_REG,
    H0,
    KEY_BEDS,
    KEY_THETAS,
    LAW_KEY_THETAS,
    LAW_SETS,
    NEAR,
    REFINE,
    REFINE_NEAR,
    SETS,
    THETAS,
    phi_b,
    point_case,
)

from pdeflow.simulate import run_model

TWO = [n for n, (m, _) in SETS.items() if m == "two_layer"]
COULOMB = [n for n in TWO if n not in LAW_SETS]
"""the two-layer sets with Coulomb's bed friction (the shipped ones)"""
LAWS = [n for n in TWO if n in LAW_SETS]
"""the two-layer sets with a rate-dependent bed law"""
SMALL = 16.0
"""the critical slope [deg] of the experiments on glass beads (Fernandez-Nieto et al.
2016, introduction: the erodible bed matters only above ~16 deg)"""
VIEW = ("two layers, planar law set", "du_reg", 22.0, 0.005, 0.00125)
"""the run drawn as side views and whose stresses are plotted (set, closure, theta,
e_i, dx): the set that erodes, near the beads' repose angle as remembered (23.5 deg)"""


def _pick(rows: list[dict], name: str, closure: str, theta: float, e_i: float,
          dx: float) -> dict | None:
    for r in rows:
        if (r["set"], r["closure"]) == (name, closure) and math.isclose(r["theta"], theta) \
                and math.isclose(r["e_i"], e_i) and math.isclose(r["dx"], dx):
            return r
    return None


def _closures(name: str) -> list[str]:
    return list(CLOSURES) if SETS[name][0] == "two_layer" else ["-"]


def _change(rows: list[dict], name: str, closure: str, theta: float, e_i: float,
            key: str, dx: float = COARSE) -> float | None:
    """Relative change of ``key`` from e_i = 0 to ``e_i`` [-]."""
    a, b = (_pick(rows, name, closure, theta, e, dx) for e in (0.0, e_i))
    if a is None or b is None or not a[key] or b[key] is None:
        return None
    return b[key] / a[key] - 1.0


def sweep_numbers(rows: list[dict]) -> dict[str, Any]:
    """Per set and closure on the coarse grid: run-out, duration and erosion per theta
    and e_i, their changes with e_i, and which runs reached the domain's end."""
    out: dict[str, Any] = {}
    for name in SETS:
        thetas = [*THETAS, *(phi_b(name) - d for d in NEAR)]
        for closure in _closures(name):
            table = {}
            for th in thetas:
                for e in BEDS:
                    r = _pick(rows, name, closure, th, e, COARSE)
                    if r is None:
                        continue
                    table[f"{th:g}|{e:g}"] = {k: r[k] for k in (
                        "runout", "flow_duration", "stop_time", "runout_lower_bound",
                        "bed_eroded_volume_max", "bed_max_erosion_depth",
                        "bed_moving_volume_max", "booked_eroded", "erosion_lead",
                        "front_velocity_max", "at_rest")}
                    for key, short in (("runout", "dr"), ("flow_duration", "dt")):
                        table[f"{th:g}|{e:g}"][short] = _change(rows, name, closure, th, e,
                                                                key)
            out[f"{name}|{closure}"] = table
    return out


def trend_numbers(sweep: dict[str, Any]) -> dict[str, Any]:
    """Per two-layer set and closure: the change of run-out and duration at e_i = H0/10
    below and above the critical slope, the largest change at any slope of the sweep,
    and near phi_B. A slope where either run of the pair reached the domain's end
    compares lower bounds and is left out of the changes (listed in ``domain_end``)."""
    out = {}
    top = max(BEDS)
    for name in TWO:
        for closure in CLOSURES:
            t = sweep[f"{name}|{closure}"]
            at = {th: t.get(f"{th:g}|{top:g}", {}) for th in THETAS}
            base = {th: t.get(f"{th:g}|0", {}) for th in THETAS}
            cut = [th for th in THETAS if at[th].get("runout_lower_bound")
                   or base[th].get("runout_lower_bound")]
            ok = [th for th in THETAS if th not in cut and at[th].get("dr") is not None]
            small = [at[th]["dr"] for th in ok if th < SMALL]
            steep = [at[th]["dr"] for th in ok if th >= SMALL]
            near = {f"{d:g}": (t.get(f"{phi_b(name) - d:g}|{top:g}", {}),
                               t.get(f"{phi_b(name) - d:g}|0", {})) for d in NEAR}
            out[f"{name}|{closure}"] = {
                "dr_small": small, "dr_steep": steep,
                "steep_thetas": [th for th in ok if th >= SMALL],
                "domain_end": cut,
                "dt_steep": [at[th]["dt"] for th in ok if th >= SMALL
                             and at[th].get("dt") is not None],
                "dr_max": max(small + steep, default=None),
                "dr_min": min(small + steep, default=None),
                "near": {d: {"theta": phi_b(name) - float(d), "dr": v.get("dr"),
                             "dt": v.get("dt"), "lower_bound": v.get("runout_lower_bound"),
                             "base_lower_bound": v0.get("runout_lower_bound")}
                         for d, (v, v0) in near.items()},
                "depth_ratio": max((v["bed_max_erosion_depth"] or 0) / e
                                   for k, v in t.items() for e in [float(k.split("|")[1])]
                                   if e > 0),
                "lead": max((v["erosion_lead"] for v in t.values()
                             if v["erosion_lead"] is not None), default=None)}
    return out


def convergence_numbers(rows: list[dict]) -> list[dict[str, Any]]:
    """The key points on every grid: run-out, duration and the trend dr(e_i) per dx, and
    the relative change of the run-out per halving of dx."""
    out = []
    for name in SETS:
        near = phi_b(name) - 2.0
        thetas = LAW_KEY_THETAS if name in LAW_SETS else KEY_THETAS
        for closure in _closures(name):
            for th, grids in [*((t, (COARSE, *REFINE)) for t in thetas),
                              (near, (COARSE, *REFINE_NEAR))]:
                for e in KEY_BEDS if SETS[name][0] == "two_layer" else (0.0,):
                    have = [(dx, _pick(rows, name, closure, th, e, dx)) for dx in grids]
                    have = [(dx, r) for dx, r in have if r is not None]
                    if len(have) < 2:
                        continue
                    r = [x["runout"] for _, x in have]
                    out.append({"set": name, "closure": closure, "theta": th, "e_i": e,
                                "dx": [dx for dx, _ in have], "runout": r,
                                "duration": [x["flow_duration"] for _, x in have],
                                "at_rest": [bool(x["at_rest"]) for _, x in have],
                                "lower_bound": any(x["runout_lower_bound"] for _, x in have),
                                "dr": [_change(rows, name, closure, th, e, "runout", dx)
                                       for dx, _ in have],
                                "halving": [abs(b - a) / abs(b) if abs(b) > 1e-9 else None
                                            for a, b in zip(r[:-1], r[1:], strict=True)]})
    return out


def page_numbers(rows: list[dict]) -> dict[str, Any]:
    """Every number the page quotes (JSON-ready)."""
    sweep = sweep_numbers(rows)
    single = {}
    for th in (*THETAS, *(phi_b("single layer") - d for d in NEAR)):
        r = _pick(rows, "single layer", "-", th, 0.0, COARSE) or {}
        single[f"{th:g}"] = (r.get("runout"), bool(r.get("runout_lower_bound")))
    return {"sweep": sweep, "trend": trend_numbers(sweep),
            "convergence": convergence_numbers(rows), "single": single,
            "phi_b": {n: phi_b(n) for n in SETS}, "H0": H0, "du_reg": DU_REG,
            "max_mass_error": max((r["mass_relative_error"] or 0.0 for r in rows
                                   if not r["runout_lower_bound"]), default=0.0),
            "domain_end_runs": sum(bool(r["runout_lower_bound"]) for r in rows),
            "wall_s": sum(r["wall_time_s"] or 0.0 for r in rows)}


# --- figures -------------------------------------------------------------------------------

def _against_bed(rows: list[dict], key: str, label: str, path: Path) -> Path:
    """``key`` against e_i at each slope, one panel per two-layer set and closure."""
    fig, axes = plt.subplots(len(TWO), len(CLOSURES), figsize=(11, 2.6 * len(TWO)),
                             sharex=True,
                             sharey="row", squeeze=False)
    colours = plt.cm.viridis(np.linspace(0, 0.9, len(THETAS)))
    for i, name in enumerate(TWO):
        for j, closure in enumerate(CLOSURES):
            ax = axes[i, j]
            for th, col in zip(THETAS, colours, strict=True):
                pts = [(e * 1e3, r[key], r["runout_lower_bound"]) for e in BEDS
                       if (r := _pick(rows, name, closure, th, e, COARSE)) and r[key] is not None
                       and not (r["runout_lower_bound"] and r["runout"] <= 1e-9)]
                if pts:
                    ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color=col, ms=3,
                            label=f"{th:g} deg")
                    low = [p for p in pts if p[2]]
                    ax.plot([p[0] for p in low], [p[1] for p in low], "^", color=col, ms=7,
                            mfc="none")
            ax.set_title(f"{name.replace('two layers, ', '')}, {closure}", fontsize=9)
            ax.grid(alpha=0.3)
            if i == len(TWO) - 1:
                ax.set_xlabel("bed thickness e_i [mm]")
            if j == 0:
                ax.set_ylabel(label)
    axes[0, 0].legend(fontsize=7, title="theta", title_fontsize=7)
    fig.suptitle(f"two layers, dx = {COARSE * 1e3:g} mm: {label} against the bed's "
                 "thickness\n(open triangles: the run reached the domain's end; runs whose "
                 "bed slid out whole, leaving no front, not drawn)", fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _near_figure(rows: list[dict], path: Path) -> Path:
    """Run-out relative to e_i = 0 near each set's phi_B (the du_reg closure)."""
    fig, axes = plt.subplots(1, len(COULOMB), figsize=(10, 3.6), squeeze=False)
    for ax, name in zip(axes[0], COULOMB, strict=True):
        for d in (*NEAR, phi_b(name) - 25.0):
            th = phi_b(name) - d
            base = _pick(rows, name, "du_reg", th, 0.0, COARSE)
            pts = [(e * 1e3, r["runout"] / base["runout"], r["runout_lower_bound"])
                   for e in BEDS if base and (r := _pick(rows, name, "du_reg", th, e, COARSE))]
            if not pts:
                continue
            line, = ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", ms=3,
                            label=f"theta = {th:g} deg (phi_B - {d:g})")
            low = [p for p in pts if p[2]]
            ax.plot([p[0] for p in low], [p[1] for p in low], "^", color=line.get_color(),
                    ms=7, mfc="none")
        ax.axhline(1.0, color="0.5", lw=0.8)
        ax.set_title(f"{name}, du_reg (phi_B = {phi_b(name):g} deg)", fontsize=9)
        ax.set_xlabel("bed thickness e_i [mm]")
        ax.set_ylabel("run-out / run-out at e_i = 0")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("near the basal friction angle (open triangles: the run reached the "
                 "domain's end, a lower bound)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _view_run() -> Any:
    case = point_case(*VIEW)
    return case, run_model(case, case.models[0])


def _stress_frame(res: Any) -> int:
    """The frame at which the net eroded volume grows fastest (the front erodes)."""
    s = res.series
    rate = np.gradient(s.eroded, s.t)
    return int(np.argmax(rate))


def _stress_figure(case: Any, res: Any, path: Path) -> dict[str, Any]:
    """Depths and the bed's stresses (pdeflow.analysis.bed_stresses) along x at the
    frame of :func:`_stress_frame`; returns that frame's numbers."""
    from pdeflow.analysis.bed_stresses import bed_stresses
    from pdeflow.numerics.state import velocity_profile

    k = _stress_frame(res)
    t, frames = res.frames
    d = frames[k]
    p = res.pde.parameters
    u1 = velocity_profile(d[0], d[1], p.dry_tolerance)
    u2 = velocity_profile(d[2], d[3], p.dry_tolerance)
    s = bed_stresses(d[0], u1, d[2], u2, case.dx, p)
    x = res.x
    front = res.series.front[k]
    keep = (x > 0.1) & (x < front + 0.1)
    bed0 = case.bed(res.model, x - case.x_start)
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    axes[0].fill_between(x[keep], 0, d[2][keep], color="tab:brown", alpha=0.6, label="h2")
    axes[0].fill_between(x[keep], d[2][keep], (d[0] + d[2])[keep], color="tab:orange",
                         alpha=0.5, label="h1")
    axes[0].plot(x[keep], bed0[keep], "k--", lw=0.8, label="original bed surface")
    axes[0].set_ylabel("depth [m]")
    axes[1].plot(x[keep], s["t1"][keep], label="t1 (interface, upper side)")
    axes[1].plot(x[keep], s["t2"][keep], label="t2 (interface, lower side)")
    axes[1].plot(x[keep], s["t_b_max"][keep], label="t_B max (basal resistance)")
    axes[1].plot(x[keep], s["drive"][keep], label="driving stress on the bed")
    axes[1].set_ylabel("stress / rho2 [m2/s2]")
    axes[2].plot(x[keep], s["M"][keep], color="k")
    axes[2].fill_between(x[keep], 0, s["M"][keep], where=s["erodes"][keep],
                         color="tab:red", alpha=0.4, label="erodes (t1 > t2)")
    axes[2].axhline(0, color="0.5", lw=0.8)
    axes[2].set_ylabel("M / rho2 [m/s]")
    axes[2].set_xlabel("x [m]")
    for ax in axes:
        ax.axvline(front, color="tab:orange", lw=0.8, ls=":")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
    axes[0].set_title(f"{VIEW[0]}, {VIEW[1]}, theta {VIEW[2]:g} deg, e_i "
                      f"{VIEW[3] * 1e3:g} mm, dx {VIEW[4] * 1e3:g} mm, t = {t[k]:.2f} s "
                      "(dotted: the flow front)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    wet = keep & (d[2] > p.dry_tolerance)
    fails = wet & (s["drive"] > s["t_b_max"])
    return {"t": float(t[k]), "front": float(front),
            "margin_no_pressure": float(np.min((s["t_b_max"] - s["drive_no_pressure"])[wet])),
            "fails_length": float(np.sum(fails) * case.dx),
            "fails_x": [float(x[fails].min()), float(x[fails].max())] if fails.any() else None,
            "erodes_length": float(np.sum(s["erodes"] & keep) * case.dx)}


def figures(rows: list[dict], numbers: dict[str, Any], out: Path) -> dict[str, Any]:
    """Write the page's figures into ``out``; returns the numbers they show."""
    from pdeflow.bed_figures import bed_figure
    from pdeflow.plotting import save

    out.mkdir(parents=True, exist_ok=True)
    _against_bed(rows, "runout", "run-out [m]", out / "runout.png")
    _against_bed(rows, "flow_duration", "flow duration [s]", out / "duration.png")
    _near_figure(rows, out / "near_phi_b.png")
    case, res = _view_run()
    xs = res.x - case.x_start
    t, frames = res.frames
    save(bed_figure(res.x, t, frames, res.model, case.bed(res.model, xs), res.series,
                    "erodible bed", res.summary["flow_duration"], case.bed_region(xs)),
         out / "side_views.png")
    view = {k: res.summary[k] for k in ("runout", "flow_duration", "bed_eroded_volume_max",
                                        "bed_max_erosion_depth", "bed_moving_volume_max",
                                        "eroded_volume", "deposited_volume")}
    view["stress"] = _stress_figure(case, res, out / "stresses.png")
    return {"view": view}


# --- text ----------------------------------------------------------------------------------

def _pct(v: float | None) -> str:
    return "-" if v is None else f"{100 * v:+.0f} %"


def _range(vals: list[float]) -> str:
    return f"{_pct(min(vals))} to {_pct(max(vals))}" if vals else "-"


def _short(name: str) -> str:
    return name.replace("two layers, ", "")


def _answer(n: dict[str, Any]) -> list[str]:
    """The answer paragraph: the sign of the trend per set and closure (Coulomb's sets,
    then the rate-dependent laws'), near phi_B, the erosion, and its convergence."""
    tr = n["trend"]
    ctr = {k: t for k, t in tr.items() if k.split("|")[0] not in LAW_SETS}
    steep = [v for t in ctr.values() for v in t["dr_steep"]]
    small = [v for t in ctr.values() for v in t["dr_small"]]
    grows = [k for k, t in tr.items() if max(t["dr_steep"], default=-1) > 0]
    grows_c = [k for k in grows if k in ctr]
    dts = [v for t in ctr.values() for v in t["dt_steep"]]
    top = max(BEDS) * 1e3
    verdict = ("**No.**" if not grows else
               "**Only in part.**" if len(grows) < len(tr) else "**Yes.**")
    lead = ""
    if grows and not grows_c:
        below = all(th < n["phi_b"][k.split("|")[0]] for k in grows
                    for th, dr in zip(tr[k]["steep_thetas"], tr[k]["dr_steep"], strict=True)
                    if dr > 0)
        lead = ("The run-out grows with e_i above ~16 deg only with a rate-dependent law "
                "for the bed (" + ", ".join(sorted({_short(k.split("|")[0]) for k in grows}))
                + "; last sentences)"
                + (", on the slopes of the sweep below the law's static angle (above it "
                   "the flows leave the channel)" if below else "") + ". ")
    lines = [f"{verdict} {lead}With Coulomb's basal friction, over slopes of 0-25 deg, a bed of "
             f"e_i = {top:g} mm (H0/10) changes the two-layer run-out by {_range(steep)} at "
             f"theta >= {SMALL:g} deg and by {_range(small)} below, over both shipped "
             "parameter sets and all three closures (paper, du_reg = "
             f"{n['du_reg']:g} m/s, relaxed; dx = {COARSE * 1e3:g} mm). The flow duration "
             f"changes by {_range(dts)} at theta >= {SMALL:g} deg."]
    longer = sum(v > 0 for v in dts)
    if not grows_c:
        lines.append("The run-out shrinks as the bed thickens, at small slopes as near the "
                     f"beads' repose angle, and the flow lasts longer in only {longer} of "
                     f"the {len(dts)} (set, closure, slope >= {SMALL:g} deg) cases: the "
                     "run-out's trend is the one a constant-friction multilayer model "
                     "gives, the opposite of the experiments' (Fernandez-Nieto et al. "
                     "2016, introduction and abstract).")
    else:
        lines.append("The run-out grows with e_i at theta >= 16 deg for: "
                     + ", ".join(grows_c) + ".")
    ero = [f"{_short(k.split('|')[0])}/{k.split('|')[1]}: {t['depth_ratio']:.2f}"
           for k, t in ctr.items()]
    lines.append("The bed is eroded where the closure's criterion holds (deepest erosion "
                 "over e_i, largest over the sweep: " + ", ".join(ero) + "); "
                 "the grains it erodes join the flow at rest and must be accelerated, so "
                 "erosion brakes the flow, while the bed, held by phi_B, never slides as a "
                 "whole below phi_B (see *Why*).")
    up = near_growth(n)
    if up:
        lines.append("On the coarse grid a thicker bed lengthens the run-out only close to "
                     "the model's own basal friction angle phi_B (41 deg for the defaults, "
                     "32 deg for the law set, far above the beads' repose angle): "
                     + "; ".join(f"{_short(k.split('|')[0])}/{k.split('|')[1]} at phi_B - "
                                 f"{d:g} deg {_pct(dr)}{' (at least: a lower bound)' if lb else ''}"
                                 + _refined(n, k, d) for k, d, dr, lb in up) + ".")
    lines.append(_convergence_sentence(n))
    for name in LAWS:
        lines += _law_answer(n, name)
    return lines


def _spread(vals: list[float]) -> str:
    """'+3 %' or '+3 to +5 %' (over the closures)."""
    if not vals:
        return "-"
    lo, hi = _pct(min(vals)), _pct(max(vals))
    return lo if lo == hi else f"{lo[:-2]} to {hi}"


def law_numbers(n: dict[str, Any], name: str) -> dict[str, Any]:
    """The rate-dependent set ``name``: per slope of the sweep measured (no run of the
    pair at the domain's end), the run-out and duration changes at e_i = H0/10 over the
    closures, coarse and on the finest refined grid; the slopes that reached the domain's
    end; the runs whose bed left the channel as a whole (no front left: run-out <= 0)."""
    top = max(BEDS)
    keys = [f"{name}|{c}" for c in CLOSURES]
    thetas = sorted({th for k in keys for th in n["trend"][k]["steep_thetas"]})
    small = [v for k in keys for v in n["trend"][k]["dr_small"]]
    per = {}
    for th in thetas:
        cells = [n["sweep"][k].get(f"{th:g}|{top:g}", {}) for k in keys]
        fine = [c for c in n["convergence"] if c["set"] == name and c["e_i"] == top
                and math.isclose(c["theta"], th) and not c["lower_bound"]]
        per[f"{th:g}"] = {
            "dr": [c["dr"] for c in cells if c.get("dr") is not None],
            "dt": [c["dt"] for c in cells if c.get("dt") is not None],
            "dr_fine": [c["dr"][-1] for c in fine if c["dr"][-1] is not None],
            "dr_all_grids": [d for c in fine for d in c["dr"] if d is not None],
            "dx_fine": min((c["dx"][-1] for c in fine), default=None),
            "dt_unsettled": _unsettled(n, name, th)}
    halving = [c["halving"][-1] for c in n["convergence"] if c["set"] == name
               and not c["lower_bound"] and c["halving"]]
    cut = sorted({th for k in keys for th in n["trend"][k]["domain_end"]})
    drained = sorted({(float(key.split("|")[0]), float(key.split("|")[1]))
                      for k in keys for key, v in n["sweep"][k].items()
                      if v["runout_lower_bound"] and v["runout"] <= 1e-9})
    return {"thetas": thetas, "per": per, "small": small, "halving": halving,
            "domain_end": cut, "drained": drained}


def _unsettled(n: dict[str, Any], name: str, theta: float) -> list[dict[str, Any]]:
    """The refined points of ``name`` at ``theta`` whose flow duration is not settled:
    a run still moving at t_end, or a duration changing by more than 10 % in the last
    halving (a front creeping for seconds)."""
    out = []
    for c in n["convergence"]:
        if c["set"] != name or not math.isclose(c["theta"], theta) or c["lower_bound"]:
            continue
        d = c["duration"]
        moved = None not in d[-2:] and abs(d[-1] - d[-2]) > 0.1 * abs(d[-1])
        if moved or not all(c["at_rest"]):
            out.append({"e_i": c["e_i"], "duration": d, "at_rest": c["at_rest"][-1],
                        "closure": c["closure"]})
    return out


def _law_answer(n: dict[str, Any], name: str) -> list[str]:
    """The answer's sentences for the rate-dependent set ``name``."""
    law = _short(name)
    ln = law_numbers(n, name)
    top = max(BEDS) * 1e3
    if not ln["thetas"]:
        return [f"With {law}'s law no slope >= {SMALL:g} deg was measured yet."]
    per = ln["per"]
    meas = ", ".join(f"{th} deg {_spread(v['dr'])}" for th, v in per.items())
    durs = ", ".join(f"{th} deg {_spread(v['dt'])}"
                     + (" (not settled, below)" if v["dt_unsettled"] else "")
                     for th, v in per.items())
    fine = [(th, v) for th, v in per.items() if v["dr_fine"]]
    out = [f"**With {law}'s rate-dependent law for the bed** (the defaults otherwise; its "
           f"static angle is {n['phi_b'][name]:g} deg for a bed of {top:g} mm, "
           "docs/rheology.md): at e_i = "
           f"{top:g} mm the run-out changes by {meas} (over the three closures, dx = "
           f"{COARSE * 1e3:g} mm) and the flow duration by {durs}; below {SMALL:g} deg by "
           f"{_range(ln['small'])}."]
    if fine:
        out.append(f"On dx = {fine[0][1]['dx_fine'] * 1e3:g} mm (two halvings): "
                   + ", ".join(f"{th} deg {_spread(v['dr_fine'])}" for th, v in fine)
                   + "; the run-outs of these points change by at most "
                   f"{100 * max(ln['halving']):.1f} % in the last halving"
                   + (", and the sign of the change with e_i is the same on every grid."
                      if all((d > 0) == (v["dr_all_grids"][0] > 0) for _, v in fine
                             for d in v["dr_all_grids"]) else
                      ", but the sign of the change with e_i is not the same on every "
                      "grid."))
    if ln["domain_end"]:
        msg = (f"At {', '.join(f'{t:g}' for t in ln['domain_end'])} deg, above the law's "
               "static angle, flows leave the 3 m channel (of each pair e_i = 0 and "
               f"{top:g} mm at least one run, on every grid: lower bounds, so no trend "
               "measured there)")
        if ln["drained"]:
            where = sorted({th for th, _ in ln["drained"]})
            beds = sorted({e for _, e in ln["drained"]})
            msg += (f"; at {', '.join(f'{t:g}' for t in where)} deg beds of "
                    f"{min(beds) * 1e3:g} mm and thicker, steeper than their own static "
                    "angle, slide out of the channel as a whole and leave no front")
        out.append(msg + ".")
    for th, v in per.items():
        u = v["dt_unsettled"]
        if u:
            beds = sorted({x["e_i"] * 1e3 for x in u})
            span = [f"{x['duration'][0]:.2f} → {x['duration'][-1]:.2f} s" for x in u]
            moving = sum(not x["at_rest"] for x in u)
            out.append(f"The flow durations at {th} deg are not settled on refinement: at "
                       "e_i = " + ", ".join(f"{b:g}" for b in beds) + " mm the slowing "
                       f"front keeps creeping, {span[0]} to {span[-1]} from dx = "
                       f"{COARSE * 1e3:g} mm to the finest grid (over the closures)"
                       + (f", {moving} of these runs still moving at the end (10 s)"
                          if moving else "")
                       + "; the duration change there is not a result (the run-out's is).")
    grow = [th for th, v in per.items() if v["dr"] and min(v["dr"]) > 0]
    longer = [th for th, v in per.items() if v["dt"] and min(v["dt"]) > 0
              and not v["dt_unsettled"]]
    if grow:
        out.append(f"So with {law}'s law the run-out grows with e_i at "
                   f"{', '.join(grow)} deg (on every grid) and the flow lasts measurably "
                   f"longer at {', '.join(longer) + ' deg' if longer else 'none of them'}: "
                   + ("the experiments' trend, on the slopes where it could be measured, "
                      "where Coulomb's friction gives the opposite."
                      if grow == list(per) and longer == list(per) else
                      "the experiments' trend only in part."))
    else:
        out.append(f"So with {law}'s law the run-out does not grow with e_i on the slopes "
                   f">= {SMALL:g} deg measured: not the experiments' trend either.")
    return out


def _refined(n: dict[str, Any], key: str, below: float) -> str:
    """', on dx = ... mm: ...' : the run-out change with e_i = H0/10 of that near-phi_B
    point on the refined grids, if it was refined."""
    name, closure = key.split("|")
    for c in n["convergence"]:
        if (c["set"], c["closure"]) == (name, closure) and c["e_i"] == max(BEDS) \
                and math.isclose(c["theta"], n["phi_b"][name] - below):
            last = c["dr"][-1]
            gone = last is not None and last <= 0
            return (", on dx = " + ", ".join(f"{d * 1e3:g}" for d in c["dx"]) + " mm: "
                    + ", ".join(_pct(d) for d in c["dr"])
                    + (" (the growth does not survive refinement)" if gone else ""))
    return " (not refined)"


def near_growth(n: dict[str, Any]) -> list[tuple[str, float, float, bool]]:
    """(set|closure, degrees below phi_B, run-out change, a lower bound) where a thicker
    bed lengthens the run-out near phi_B; a pair whose run without a bed reached the
    domain's end compares nothing and is left out."""
    out = []
    for k, t in n["trend"].items():
        for d, v in t["near"].items():
            if v["dr"] is not None and v["dr"] > 0 and not v["base_lower_bound"]:
                out.append((k, float(d), v["dr"], bool(v["lower_bound"])))
    return out


def erosion_lead(n: dict[str, Any]) -> float | None:
    """The farthest [m] the erosion front got ahead of the flow front in any run."""
    leads = [t["lead"] for t in n["trend"].values() if t["lead"] is not None]
    return max(leads) if leads else None


def _convergence_sentence(n: dict[str, Any]) -> str:
    conv = [c for c in n["convergence"] if c["set"] in COULOMB
            and c["theta"] in KEY_THETAS]
    last = [c["halving"][-1] for c in conv if c["halving"]]
    signs = [all(d is None or d <= 0 for d in c["dr"]) for c in conv if c["e_i"] > 0]
    if not last:
        return "The key points have not been refined yet (run the generator again)."
    return (f"On refinement to dx = {min(REFINE) * 1e3:g} mm (three halvings) the Coulomb key "
            f"points at {', '.join(f'{t:g}' for t in KEY_THETAS)} deg change their run-out "
            f"by at most {100 * max(last):.1f} % in the last halving (median "
            f"{100 * float(np.median(last)):.1f} %), and the sign of the change with e_i is "
            f"{'the same on every grid' if all(signs) else 'not the same on every grid'}.")


def _trend_table(n: dict[str, Any]) -> list[str]:
    top = max(BEDS)
    head = ["| set | closure | " + " | ".join(f"{th:g} deg" for th in THETAS)
            + " | " + " | ".join(f"phi_B - {d:g}" for d in NEAR) + " |",
            "|---|---|" + "---|" * (len(THETAS) + len(NEAR))]
    for name in TWO:
        for closure in CLOSURES:
            t = n["sweep"][f"{name}|{closure}"]
            cells = []
            for th in (*THETAS, *(n["phi_b"][name] - d for d in NEAR)):
                e0, e1 = t.get(f"{th:g}|0"), t.get(f"{th:g}|{top:g}")
                if not e0 or not e1:
                    cells.append("-")
                    continue
                lb = "≥" if e1["runout_lower_bound"] or e0["runout_lower_bound"] else ""
                cells.append(f"{e0['runout']:.3g} → {lb}{e1['runout']:.3g} "
                             f"({_pct(e1['dr'])}); {e0['flow_duration']:.2f} → "
                             f"{e1['flow_duration']:.2f} s")
            head.append(f"| {_short(name)} | {closure} | " + " | ".join(cells) + " |")
    return head


def _convergence_table(n: dict[str, Any]) -> list[str]:
    out = ["| set | closure | theta [deg] | e_i [mm] | dx [mm] | run-out [m] | change per "
           "halving | run-out change from e_i = 0 | flow duration [s] |",
           "|---|---|---|---|---|---|---|---|---|"]
    for c in n["convergence"]:
        out.append(
            f"| {_short(c['set'])} | {c['closure']} | {c['theta']:g} | {c['e_i'] * 1e3:g} | "
            + ", ".join(f"{d * 1e3:g}" for d in c["dx"]) + " | "
            + ", ".join(f"{r:.4g}" for r in c["runout"])
            + (" (≥: domain end)" if c["lower_bound"] else "") + " | "
            + ", ".join("-" if h is None else f"{100 * h:.1f} %" for h in c["halving"])
            + " | "
            + ", ".join(_pct(d) for d in c["dr"]) + " | "
            + ", ".join("-" if d is None else f"{d:.2f}" for d in c["duration"]) + " |")
    return out


def render_page(n: dict[str, Any]) -> str:
    """The page (markdown) from the numbers of :func:`page_numbers` and :func:`figures`."""
    import erodible_bed_text as text

    return text.render(n, _answer(n), _trend_table(n), _convergence_table(n))
