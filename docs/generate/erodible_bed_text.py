"""The prose of docs/erodible_bed.md around the computed answer and tables
(:func:`render`); every number is taken from the numbers of erodible_bed_page."""

from __future__ import annotations

from typing import Any

from erodible_bed import (
    BEDS,
    COARSE,
    DU_REG,
    H0,
    KEY_THETAS,
    LAW_KEY_THETAS,
    LAW_REFINE,
    LAW_SETS,
    NEAR,
    REFINE,
    THETAS,
)

SOURCES = """## Sources, and what could be confirmed

Neither primary paper (Mangeney et al. 2010, JGR 115, F03040; Farin, Mangeney & Roche
2014, JGR Earth Surf. 119) is in the corpus this project can search; what could be
checked is listed with its status.

Confirmed, from a secondary source (Fernandez-Nieto, Garres-Diaz, Mangeney &
Narbona-Reina 2016, JFM, "A multilayer shallow model for dry granular flows with the
mu(I)-rheology: application to granular collapse on erodible beds", introduction and
abstract, arXiv 1507.06546):

* run-out **and flow duration** increase with the erodible bed's thickness in the
  experiments on glass beads, **only on slopes above a critical angle of about 16 deg**;
* a multilayer model with a mu(I) rheology reproduces the increase; with a **constant
  friction coefficient** it gives **the opposite** trend.

Not confirmed (recalled, or read only in a code comment of an unnamed repository), and
therefore used only as the set-up, never as a target:

* the column H0 = 0.14 m, L0 = 0.20 m (a = 0.7), glass beads of 0.6-0.7 mm, repose angle
  23.5 deg, avalanche angle 25.5 deg, packing 0.62;
* the slopes tested (0 to ~23 deg), bed thicknesses e_i up to ~5 mm, a channel ~10 cm
  wide;
* the run-out increase near the repose angle "by up to ~40 %", and a critical range of
  "10-16 deg";
* erosion waves running ahead of the front, erosion starting behind the front;
* whether the erodible layer lay under the column too (here it starts at the gate, x = L0);
* any table of run-out against (theta, e_i), eroded volumes or erosion depths.

Mangeney et al. (2007, GRL 34, L22401) is a numerical study (partial fluidization), not an
experiment (its abstract, confirmed). Edwards et al. (2017, 2021, JFM) reproduce
erosion-deposition waves on erodible layers with a *hysteretic* basal friction law
(abstracts, confirmed; their numbers not seen)."""


def _runs(n: dict[str, Any]) -> str:
    phi = n["phi_b"]
    return (f"**The runs.** `cases/erodible_bed.toml`: a column H0 = {H0:g} m, L0 = 0.2 m "
            "against the wall, released at t = 0 onto a bed of thickness e_i at rest from "
            "the gate (x = L0) to the end of the channel; the two-layer model's lower layer "
            "holds the bed, the single layer (phi_B = "
            f"{phi['single layer']:g} deg) runs on the rigid bed. Slopes theta = "
            + ", ".join(f"{t:g}" for t in THETAS) + " deg, and 4, 2 and 1 deg below each "
            "set's phi_B; e_i = " + ", ".join(f"{e * 1e3:g}" for e in BEDS)
            + " mm. Two shipped two-layer sets ([parameters.md](parameters.md)): the "
            f"defaults calibrated on test 5.1 (phi_B {phi['two layers, defaults']:g} deg, "
            "k 0.65, c 0.03, 60 deg wedge) and the planar law set of "
            "`cases/paper_5_2_two_layer_law.toml` (phi_B "
            f"{phi['two layers, planar law set']:g} deg, k 0.8, c 1, 75 deg wedge), each "
            f"with three closures: the paper's (25), the same bounded by du_reg = {DU_REG:g} "
            "m/s, and the relaxed one (tau_star = 1). "
            + _law_sets(n)
            + " First-order HLL, CFL 0.3, each run "
            f"to rest; coarse grid dx = {COARSE * 1e3:g} mm for the whole sweep. Run-out = "
            "front - L0, the front being the downstream face of the last cell deeper than "
            "1 mm above the initial bed; flow duration = the first time from which the "
            "front no longer moves (frames every 10 ms; `pdeflow.erosion`). "
            f"{n['points']} runs, {n['wall_s']:.0f} s of run time; "
            f"{n['domain_end_runs']} of them let material (at least a thin film) out of the "
            "channel's open end, and their run-outs are lower bounds (marked ≥); the "
            f"others conserve mass to {n['max_mass_error']:.1e}.")


def _law_sets(n: dict[str, Any]) -> str:
    """The rate-dependent sets and what their phi_B means."""
    phi = n["phi_b"]
    from erodible_bed import static_angle

    names = [k for k in phi if k in LAW_SETS]
    if not names:
        return ""
    thin = min(e for e in BEDS if e > 0)
    lo, hi = min(phi[k] for k in names), max(phi[k] for k in names)
    return ("The defaults with a rate-dependent law for the lower layer's bed friction "
            "(`two_layer.friction_law`, glass-bead constants, docs/rheology.md), the same "
            "three closures: " + ", ".join(
                f"{k.replace('two layers, ', '')} (phi_B {phi[k]:g} deg)" for k in names)
            + ". Their static angle depends on the depth the law sees (pouliquen: "
            "tan d1 + (tan d2 - tan d1)/(1 + h/L), the inverse of h_stop; mu_i: tan d1 at "
            "any depth); their phi_B is the angle at which the thickest bed, e_i = "
            f"{max(BEDS) * 1e3:g} mm, stands on its own"
            + "".join(f" ({k.replace('two layers, ', '')}: thinner beds stand steeper, "
                      f"the {thin * 1e3:g} mm bed to {static_angle(k, thin):.1f} deg)"
                      for k in names if static_angle(k, thin) > phi[k] + 0.05)
            + ". Their sweep has no slopes near phi_B: it lies between "
            f"{max(t for t in THETAS if t < lo):g} and {min(t for t in THETAS if t > hi):g} "
            "deg of the sweep (and their near runs would need the 8 m channel).")


def _depths(n: dict[str, Any], name: str) -> str:
    """The deepest erosion over e_i of the set ``name``, per closure."""
    return ", ".join(f"{n['trend'][f'{name}|{c}']['depth_ratio']:.2f} ({c})"
                     for c in ("paper", "du_reg", "relaxed"))


def _span(n: dict[str, Any], name: str) -> str:
    """The range of the run-out changes at e_i = H0/10 over 0-25 deg of the set."""
    v = [d for c in ("paper", "du_reg", "relaxed")
         for d in n["trend"][f"{name}|{c}"]["dr_small"] + n["trend"][f"{name}|{c}"]["dr_steep"]]
    return f"{-100 * max(v):.0f}-{-100 * min(v):.0f} %"


def _why(n: dict[str, Any]) -> str:
    v = n["view"]
    s = v["stress"]
    return (
        "## Why the model does not reproduce the trend\n\n"
        "Three things in the model's stress balance decide it (formulas in "
        "`pdeflow.analysis.bed_stresses`, taken from `pdeflow/models/two_layer/exchange.py`):\n\n"
        "* **The bed never fails as a whole below phi_B.** A lower layer at rest is driven "
        "by gravity along the slope and the interface stress it receives, "
        "g_x h2 + r g_z h1 tan(phi_int), and resists with g_z (r h1 + h2) tan(phi_B). With "
        "theta < phi_B and phi_int = 30 deg <= phi_B the resistance always wins (the "
        "pressure gradients aside): on every slope of the experiments the shipped beds "
        "(phi_B 32 and 41 deg) are far from failing, where the beads' bed (repose ~23.5 deg, "
        "not confirmed) is at the edge of failure near 22-25 deg.\n"
        "* **Erosion is set by the closure alone, and it brakes.** The bed is eroded from "
        "its top where c du² > (1 - k) r g_z h1 tan(phi_int) (t1 > t2): a criterion with "
        "no slope in it and no reference to how close the bed is to failing. The eroded "
        "grains join the upper layer at the lower layer's velocity (zero) and must be "
        "accelerated by the flow: momentum is conserved, so the flow slows.\n"
        "* **Deposition into a bed at rest brakes too, and more.** The defaults erode "
        f"almost nothing (deepest erosion {_depths(n, 'two layers, defaults')} of e_i) and "
        f"lose {_span(n, 'two layers, defaults')} of their run-out at e_i = H0/10, the "
        f"law set {_span(n, 'two layers, planar law set')}. Material the closure deposits "
        "carries its velocity u1 into the lower layer "
        "(`pdeflow/models/two_layer/sources.py`: the lower layer takes the rest of the "
        "momentum). On the rigid bed that new lower layer "
        "moves at u1 and slides on; on a bed at rest its momentum is shared with the "
        "bed's grains in the cell, and basal friction holds the mixture. The more bed "
        "mass per cell, the more momentum is lost: the run-out falls steadily with e_i, "
        "most between 0 and 2 mm.\n\n"
        f"The figure shows the run of the side views at t = {s['t']:.2f} s, when its net "
        f"eroded volume grows fastest (front at x = {s['front']:.3f} m): the criterion "
        f"holds over {s['erodes_length']:.3f} m behind the front (where a surge of the "
        "upper layer runs over the deposit); without the pressure gradients the basal "
        "resistance exceeds the drive on the lower layer everywhere, by at least "
        f"{s['margin_no_pressure']:.3g} m²/s² (per rho2), and with them "
        + (f"the drive wins in cells totalling {s['fails_length'] * 1e3:.1f} mm between "
           f"x = {s['fails_x'][0]:.3f} and {s['fails_x'][1]:.3f} m, where the surge and the "
           "front of the deposit steepen the surfaces (largest volume of the lower layer "
           f"moving over the bed region in this run: {v['bed_moving_volume_max'] * 1e4:.2f} "
           "cm²)" if s["fails_x"] else "nowhere either") + ".\n\n"
        "![stresses at the erosion front](erodible_bed/stresses.png)\n\n"
        "A model that reproduces the experiments' trend must let the flow lower the bed's "
        "resistance near failure: a rate-dependent or hysteretic basal law (mu(I), as "
        "Fernandez-Nieto et al. 2016; hysteresis, as Edwards et al. 2021) for the lower "
        "layer with phi_B near the beads' angles, or an erosion criterion that involves the "
        "bed's own stress balance. The two-layer model has such laws for its lower layer "
        "(`two_layer.friction_law`, [model.md](model.md)); the sets with pouliquen's and "
        "mu_i's law above (the answer) put its bed's static angle near the beads' "
        "angles.")


def _distance(n: dict[str, Any]) -> str:
    """The distance to the two confirmed statements, from the sweep's numbers."""
    from erodible_bed_page import near_growth

    tr = {k: t for k, t in n["trend"].items() if k.split("|")[0] not in LAW_SETS}
    grows = sorted({(k, th) for k, t in tr.items() for th, dr in
                    zip([x for x in THETAS if x >= 16], t["dr_steep"], strict=False)
                    if dr > 0})
    near = near_growth(n)
    where = ("; ".join(f"{k.split('|')[0].replace('two layers, ', '')}, {k.split('|')[1]}: "
                       f"{n['phi_b'][k.split('|')[0]] - d:g} deg" for k, d, _, _ in near)
             or "nowhere")
    dts = [v for t in tr.values() for v in t["dt_steep"]]
    return ("**Distance to the numbers that could be confirmed** (Coulomb's sets; the "
            "rate-dependent laws in the answer). (1) The critical slope "
            "(~16 deg) above which the run-out grows with e_i: "
            + ("the model has none in 0-25 deg, its run-out never grows with e_i there"
               if not grows else f"the model's run-out grows at {grows}")
            + f"; on the coarse grid a thicker bed lengthens it only near phi_B ({where}), "
            "well above 16 deg, and that growth does not survive refinement where it was "
            "refined (the answer). "
            "(2) The duration grows with e_i above the critical slope: in the model it "
            f"changes by {min(dts) * 100:+.0f} % to {max(dts) * 100:+.0f} % at e_i = "
            f"{max(BEDS) * 1e3:g} mm on 16-25 deg. No measured run-out, duration or erosion "
            "depth could be confirmed, so no absolute distance is given.")


def _lead(n: dict[str, Any]) -> str:
    from erodible_bed_page import erosion_lead

    lead = erosion_lead(n)
    if lead is None:
        return "Nothing was eroded in any run."
    if lead <= 0:
        return (f"In every run of the sweep the erosion front stays behind the flow front "
                f"(at best {-lead * 1e3:.1f} mm behind it): the exchange needs an upper "
                "layer, so no erosion wave runs ahead of the front.")
    return (f"The erosion front gets up to {lead * 1e3:.1f} mm ahead of the flow front "
            "(front measured 1 mm above the bed) in some runs.")


def render(n: dict[str, Any], answer: list[str], trend: list[str],
           convergence: list[str]) -> str:
    """The page."""
    v = n["view"]
    top = max(BEDS) * 1e3
    single = ", ".join(f"{k} deg: {'≥' if lb else ''}{r:.3g} m"
                       for k, (r, lb) in n["single"].items() if r is not None)
    parts = [
        "# Collapses over erodible beds: the two-layer model against the sloping-bed "
        "experiments\n",
        "Generated by `python docs/generate/erodible_bed.py` (every number and figure; "
        f"{n['points']} runs cached in docs/erodible_bed/sweep.csv, the page "
        f"{n['generator_wall_s']:.0f} s from a full cache; `--rerun` recomputes the cache, "
        "`--no-runs` renders from it as it is).\n",
        "## The question\n",
        "Columns of glass beads released on a channel inclined at theta = 0-25 deg over an "
        "erodible layer of the same beads, of thickness e_i (Mangeney et al. 2010; Farin, "
        "Mangeney & Roche 2014): on small slopes the layer changes the run-out little; above "
        "a critical slope the run-out and the flow's duration grow with e_i. The two-layer "
        "model's static lower layer laid along the slope *is* an erodible bed, eroded when "
        "the collisional stress wins (closure (25)). Does the model reproduce the trend, "
        "with which closure and parameters, on which grids?\n",
        "## The answer\n",
        " ".join(answer) + "\n",
        "![run-out against e_i](erodible_bed/runout.png)\n",
        "## How we know\n",
        _runs(n) + "\n",
        f"**Run-out and duration, e_i = 0 → {top:g} mm** (coarse grid; ≥: the run reached "
        "the domain's end, a lower bound):\n",
        "\n".join(trend) + "\n",
        f"The single layer on the rigid bed (no e_i dependence by construction): {single}.\n",
        "![flow duration against e_i](erodible_bed/duration.png)\n",
        "Near each Coulomb set's basal friction angle (du_reg closure):\n",
        "![near phi_B](erodible_bed/near_phi_b.png)\n",
        "**Convergence** (key points at "
        + ", ".join(f"{t:g}" for t in KEY_THETAS)
        + f" deg on dx = {COARSE * 1e3:g} mm and {', '.join(f'{d * 1e3:g}' for d in REFINE)}"
        " mm; 2 deg below phi_B on two halvings; the rate-dependent laws at "
        + ", ".join(f"{t:g}" for t in LAW_KEY_THETAS)
        + " deg, e_i = 0 and " + f"{max(BEDS) * 1e3:g}" + " mm, on dx = "
        + ", ".join(f"{d * 1e3:g}" for d in (COARSE, *LAW_REFINE)) + " mm):\n",
        "\n".join(convergence) + "\n",
        _distance(n) + "\n",
        "**The side view** (planar law set, du_reg, theta 22 deg, e_i 5 mm, dx 1.25 mm): "
        f"run-out {v['runout']:.3f} m, flow duration {v['flow_duration']:.2f} s, the bed "
        f"eroded to {v['bed_max_erosion_depth'] * 1e3:.2f} mm of its 5 mm, at most "
        f"{v['bed_eroded_volume_max'] * 1e4:.2f} cm² (per unit width) missing below the "
        f"original surface at once, {v['eroded_volume'] * 1e4:.2f} cm² booked as eroded by "
        f"the exchange over the run (gross, the column's wedge included) against "
        f"{v['deposited_volume'] * 1e4:.2f} cm² deposited. "
        + _lead(n) + "\n",
        "![side views and the bed's change](erodible_bed/side_views.png)\n",
        _why(n) + "\n",
        SOURCES + "\n",
        "## Reproduce\n",
        "```bash\npython docs/generate/erodible_bed.py              # the page (runs what "
        "the cache lacks)\npdeflow run cases/erodible_bed.toml               # one case: "
        "summary, figures incl. bed_<model>.png\npdeflow run cases/erodible_bed.toml "
        "--set two_layer.theta_deg=22 --set single_layer.theta_deg=22 --set "
        "initial.bed_thickness=0.014\n```\n",
        f"Slopes 1-{max(NEAR):g} deg below phi_B run on an 8 m channel for up to 30 s; "
        "the others on 3 m for up to 10 s.\n",
    ]
    return "\n".join(parts)
