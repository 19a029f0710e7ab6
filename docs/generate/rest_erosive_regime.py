"""Regenerate docs/rest_erosive_regime.md and its figure: test 5.1 in the erosive regime.

    python docs/generate/rest_erosive_regime.py          # about a minute on 2 cores

Runs test 5.1 over the (phi_B, k, c) sets of an independent code's table (issue "The
two-layer run-out law, decided", part A), the splitting-error check (the same set at
smaller CFL numbers) and the phi_B = 46 deg set at a smaller CFL and dx, and draws the
cells that still move in that set at 5 s, while its surges run, with the forces on their
upper layer. Uses the public
API only (case files, ``run_model``).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from pdeflow.cases import load_case  # noqa: E402
from pdeflow.io import write_text  # noqa: E402
from pdeflow.plotting import save  # noqa: E402
from pdeflow.simulate import RunResult, run_model  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "cases" / "paper_5_1_dam_break.toml"

# (phi_B, k, c) -> lower / upper practical rest [s], front [m] of the independent code,
# and what pdeflow gave before the exchange was upwinded (the table)
INDEPENDENT = [
    ((41, 0.65, 0.03), "0.79 / 1.36 s, 3.40 m", "0.79 / 1.36 s, 3.50 m"),
    ((30, 0.3, 0.3), "1.22 / 1.45 s, 4.75 m", "1.23 / 1.44 s, 4.80 m"),
    ((30, 0.3, 3.0), "1.39 / 1.49 s, 4.05 m", "lower until 9.6 s, upper never, 4.30 m"),
    ((30, 0.5, 3.0), "1.38 / 1.51 s, 4.00 m", "not at rest by 5 s"),
    ((30, 0.65, 3.0), "1.39 / 1.60 s, 3.95 m", "9.7 s / never, 4.20 m"),
    ((35, 0.3, 3.0), "1.07 / 8.69 s, 3.25 m", "9.3 s / never, 3.60 m"),
    ((35, 0.65, 3.0), "1.01 / 4.41 s, 3.15 m", "9.8 s / never, 3.40 m"),
    ((46, 0.65, 3.0), "7.10 / 9.46 s, 2.80 m", "never / never, 3.40 m"),
]


def run(phi_b: float, k: float, c: float, *extra: str, t_end: float = 10.0) -> RunResult:
    case = load_case(CASE, [f"two_layer.phi_b_deg={phi_b}", f"two_layer.k={k}",
                            f"two_layer.c={c}", f"case.t_end={t_end}",
                            "case.models=['two_layer']", "output.snapshot_times=[]",
                            *extra])
    return run_model(case, "two_layer")


def _t(v: float | None) -> str:
    return "moving" if v is None else f"{v:.2f}"


def _row(s: dict) -> str:
    return (f"{_t(s['lower_slow_time'])} / {_t(s['upper_slow_time'])} s, "
            f"{s['front_position']:.2f} m")


def forces_figure(res: RunResult, path: Path) -> None:
    """Moving cells of a run that has not come to rest, with the accelerations on their
    upper layer: the surface slope's pull g_z dH/dx against the interface friction."""
    p = res.case.make_pde("two_layer").parameters
    x = res.x
    h1, m1, h2, m2 = res.state.data
    dry = p.dry_tolerance
    u1 = np.where(h1 > dry, m1 / np.where(h1 > dry, h1, 1.0), 0.0)
    u2 = np.where(h2 > dry, m2 / np.where(h2 > dry, h2, 1.0), 0.0)
    H = h1 + h2
    g = p.g * math.cos(math.radians(p.theta_deg))
    tan_int = math.tan(math.radians(p.phi_int_deg))
    pull = -g * np.gradient(H, x)  # down-slope acceleration from the surface slope
    du = u1 - u2
    drag = np.where(h1 > 1e-3, p.k * g * tan_int
                    + p.c * du * du / (p.density_ratio * np.maximum(h1, 1e-3)), np.nan)
    moving = (m1 != 0) | (m2 != 0)
    wet = np.nonzero(H > 1e-3)[0]
    lo, hi = wet[0], wet[-1] + 2
    fig, ax = plt.subplots(3, 1, figsize=(8, 8.5), sharex=True)
    ax[0].fill_between(x[lo:hi], 0, h2[lo:hi], color="0.6", label="lower layer h2")
    ax[0].fill_between(x[lo:hi], h2[lo:hi], H[lo:hi], color="tab:orange",
                       label="upper layer h1")
    ax[0].plot(x[lo:hi][moving[lo:hi]], H[lo:hi][moving[lo:hi]], "k.", ms=4,
               label="cells still moving")
    ax[0].set_ylabel("depth [m]")
    ax[0].legend(loc="upper right", fontsize=8)
    ax[1].plot(x[lo:hi], u1[lo:hi], color="tab:orange", label="u1")
    ax[1].plot(x[lo:hi], u2[lo:hi], color="0.3", label="u2")
    ax[1].set_ylabel("velocity [m/s]")
    ax[1].legend(loc="upper right", fontsize=8)
    ax[2].plot(x[lo:hi], pull[lo:hi], color="tab:blue",
               label=r"pull of the surface slope $-g_z\,\partial_x H$")
    ax[2].plot(x[lo:hi], drag[lo:hi], color="tab:red",
               label=r"interface stress (22) $t_1/(\rho_1 h_1)$ on the upper layer")
    ax[2].axhline(g * tan_int, color="k", ls="--", lw=1,
                  label=r"$g_z \tan\varphi_{int}$: above it an equilibrium film erodes")
    ax[2].axhline(g * p.k * tan_int, color="k", ls=":", lw=1,
                  label=r"$k\, g_z \tan\varphi_{int}$: above it no film can rest")
    ax[2].axhline(g * math.tan(math.radians(p.phi_b_deg)), color="0.5", ls="-.", lw=1,
                  label=r"$g_z \tan\varphi_B$: steepest deposit the bed holds")
    ax[2].set_ylim(-5, 20)
    ax[2].set_ylabel(r"acceleration [m/s$^2$]")
    ax[2].set_xlabel("x [m]")
    ax[2].legend(loc="upper right", fontsize=7)
    ax[0].set_title(f"test 5.1, phi_B = {p.phi_b_deg:g} deg, k = {p.k:g}, c = {p.c:g}: "
                    f"t = {res.t_final:.1f} s, dx = {res.case.dx:g} m")
    fig.tight_layout()
    save(fig, path)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--docs", type=Path, default=ROOT / "docs", help="docs directory")
    args = ap.parse_args(argv)
    lines = [
        "# Test 5.1 in the erosive regime (large c): coming to rest",
        "",
        "Generated by `python docs/generate/rest_erosive_regime.py`; the mechanism is "
        "explained in [model.md](model.md#coming-to-rest-when-the-upper-layer-erodes). "
        "Test 5.1 at dx = 0.05 m, CFL 0.3, t_end = 10 s, paper closure, first-order HLL. "
        "Stop times are practical (|u| < 1 cm/s wherever h > 1 mm, `*_slow_time`) as in "
        "the independent code's table; exact stops (u = 0) in the last column; front = "
        "downstream face of the last cell with h1 + h2 > 1 mm.",
        "",
        "| phi_B | k | c | independent code: lower / upper at rest, front | pdeflow before "
        "| pdeflow now | exact stop lower / upper [s] | max F_extra/rho1 [m^2/s^2] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for (pb, k, c), indep, before in INDEPENDENT:
        s = run(pb, k, c).summary
        lines.append(f"| {pb} | {k} | {c} | {indep} | {before} | {_row(s)} | "
                     f"{_t(s['lower_stop_time'])} / {_t(s['upper_stop_time'])} | "
                     f"{s['max_fextra_over_rho1']:.2f} |")
    lines += [
        "",
        "## Splitting error: the same set at smaller time steps",
        "",
        "Both the old and the new exchange are first-order splittings of the same "
        "equations; as CFL -> 0 they meet. How far CFL 0.3 is from that limit measures the "
        "splitting error (set phi_B = 30, k = 0.5, c = 3; dx = 0.05 m).",
        "",
        "| CFL | lower / upper at rest, front | upper-layer volume at 0.25 s [m^2] |",
        "|---|---|---|",
    ]
    for cfl in (0.3, 0.1, 0.03):
        res = run(30, 0.5, 3.0, f"numerics.cfl={cfl}", "output.snapshot_times=[0.25]")
        v1 = float(np.sum(res.snapshots[0.25][0][0]) * res.case.dx)
        lines.append(f"| {cfl} | {_row(res.summary)} | {v1:.3f} |")
    lines += [
        "",
        "## phi_B = 46 deg: surges on a steep deposit",
        "",
        "| run | lower / upper at rest, front | exact stop lower / upper [s] |",
        "|---|---|---|",
    ]
    for label, extra in (("dx = 0.05 m, CFL 0.3", ()),
                         ("dx = 0.05 m, CFL 0.1", ("numerics.cfl=0.1",)),
                         ("dx = 0.025 m, CFL 0.3", ("grid.dx=0.025",)),
                         ("dx = 0.025 m, CFL 0.1", ("grid.dx=0.025", "numerics.cfl=0.1")),
                         ("dx = 0.0125 m, CFL 0.3", ("grid.dx=0.0125",)),
                         ("dx = 0.0125 m, CFL 0.1", ("grid.dx=0.0125", "numerics.cfl=0.1")),
                         ("dx = 0.05 m, CFL 0.3, MUSCL", ("numerics.reconstruction='muscl'",)),
                         ("dx = 0.05 m, CFL 0.3, Rusanov", ("numerics.flux='rusanov'",)),
                         ("dx = 0.05 m, CFL 0.3, IFCP", ("numerics.flux='ifcp'",))):
        s = run(46, 0.65, 3.0, *extra, t_end=30.0).summary
        lines.append(f"| {label}, t_end = 30 s | {_row(s)} | "
                     f"{_t(s['lower_stop_time'])} / {_t(s['upper_stop_time'])} |")
    fig = args.docs / "figures" / "rest_erosive_phi_b_46.png"
    forces_figure(run(46, 0.65, 3.0, t_end=5.0), fig)
    lines += ["", f"![moving cells and forces at t = 5 s](figures/{fig.name})", ""]
    out = args.docs / "rest_erosive_regime.md"
    write_text(out, "\n".join(lines))
    print(f"wrote {out} and {fig}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
