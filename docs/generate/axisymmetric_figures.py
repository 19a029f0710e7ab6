"""The figures of docs/axisymmetric.md (written by docs/generate/axisymmetric.py)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from axisymmetric import BREAK, PROFILE_RATIOS, R0, SETS, lube_height, lube_runout  # noqa: E402

from pdeflow.metrics import mass_quantile_position  # noqa: E402
from pdeflow.plotting import log_ticks, save  # noqa: E402

STYLE = {"single layer": ("tab:red", "o"), "two layers, defaults": ("tab:blue", "s"),
         "two layers, planar law set": ("tab:green", "^")}
"""set -> (colour, marker)"""
A_TICKS = (0.5, 1, 2, 5, 10, 20)
LUBE = "Lube et al. 2004 (as remembered, not confirmed)"
ZOOM_FRACTION = 0.95
"""the deposit figure's r axis ends 15 % beyond the radius holding this fraction of the
two-layer deposits' mass (or Lube's R_inf): the deposits the page compares with the
experiments; a deposit reaching farther (the single layer's spreads 90 % of its mass
over 16 R0 at a = 10) runs off the panel, its radius written at the edge"""
ZOOMED_SETS = ("two layers, defaults", "two layers, planar law set")


def deposit_radius(x: np.ndarray, h: np.ndarray, fraction: float = ZOOM_FRACTION) -> float:
    """The radius [units of ``x``] holding ``fraction`` of the mass of a radial deposit of
    depth ``h`` at the uniform cell centres ``x`` (pdeflow's mass quantile)."""
    dr = float(x[1] - x[0])
    faces = np.concatenate([[x[0] - dr / 2], x + dr / 2])
    radius = mass_quantile_position(faces, np.pi * np.diff(faces**2), h, fraction,
                                    radial=True)
    return float(faces[-1]) if radius is None else radius


def _loglog(ax: Any, ylabel: str, yticks: list[float]) -> None:
    log_ticks(ax.xaxis, A_TICKS)
    log_ticks(ax.yaxis, yticks)
    ax.set_xlabel("aspect ratio a = H0/R0")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)


def figure_runout(numbers: dict[str, Any], path: Path) -> Path:
    """r(a) on the finest grid of every set, its fits below and above a = 1.7, Lube's law."""
    fig, ax = plt.subplots(figsize=(6, 4.4))
    aa = np.geomspace(0.5, 20, 200)
    ax.loglog(aa, lube_runout(aa), "k--", lw=1.2, label=f"{LUBE}: 1.24 a, 1.6 a^0.5")
    for name, res in numbers["sets"].items():
        colour, marker = STYLE[name]
        ax.loglog(res["a"], res["r"], marker, color=colour, label=f"{name}, dr = {res['dx']:g} m")
        for part, lo, hi in (("low", 0.5, BREAK), ("high", BREAK, 20.0)):
            p, e = res["fits"][part]
            x = np.geomspace(lo, hi, 20)
            ax.loglog(x, p * x**e, "-", color=colour, lw=0.8)
    ax.axvline(BREAK, color="gray", lw=0.6, ls=":")
    _loglog(ax, "r = (R_inf - R0)/R0", [0.5, 1, 2, 5, 10, 20])
    fig.tight_layout()
    return save(fig, path)


def figure_height(numbers: dict[str, Any], path: Path) -> Path:
    """H_inf/R0 against a, with H_inf = H0 (an undisturbed top) and Lube's law."""
    fig, ax = plt.subplots(figsize=(6, 4.2))
    aa = np.geomspace(0.5, 20, 200)
    ax.loglog(aa, lube_height(aa), "k--", lw=1.2, label=f"{LUBE}: a, 0.88 a^(1/6)")
    ax.loglog(aa, aa, ":", color="gray", lw=1, label="H_inf = H0 (the column's height)")
    for name, res in numbers["sets"].items():
        colour, marker = STYLE[name]
        ax.loglog(res["a"], res["H"], marker + "-", color=colour, lw=0.8, label=name)
    ax.set_ylim(0.3, 3)
    _loglog(ax, "final height H_inf/R0", [0.3, 0.5, 1, 2, 3])
    fig.tight_layout()
    return save(fig, path)


def figure_profiles(numbers: dict[str, Any], profiles: dict[str, Any], path: Path) -> Path:
    """Deposits h/R0 against r/R0 for a = 0.5, 2, 5, 10; the lower layer dotted; the
    straight cone through Lube's final height and run-out as the experiments' outline;
    the initial column's edge (its top, h/R0 = a, named where it is above the panel);
    r zoomed to the deposits (:data:`ZOOM_FRACTION`)."""
    fig, axes = plt.subplots(len(PROFILE_RATIOS), 1, figsize=(6.5, 8.5))
    for ax, a in zip(axes, PROFILE_RATIOS, strict=True):
        H, rr = float(lube_height(np.array([a]))[0]), float(lube_runout(np.array([a]))[0])
        ax.plot([0, 1 + rr], [min(H, a), 0], "k--", lw=1,
                label="cone through Lube's H_inf and R_inf" if a == PROFILE_RATIOS[0] else None)
        ax.plot([0, 1, 1], [a, a, 0], color="gray", lw=0.8,
                label="initial column" if a == PROFILE_RATIOS[0] else None)
        xmax, ymax = 1.0, min(H, a)
        radius: dict[str, float] = {}
        for name in SETS:
            p = profiles[f"{name}|{a:g}"]
            colour = STYLE[name][0]
            x, h = p["x"] / R0, p["h"] / R0
            ax.plot(x, h, color=colour, lw=1.2, label=name if a == PROFILE_RATIOS[0] else None)
            if name != "single layer":
                ax.plot(x, p["h_lower"] / R0, ":", color=colour, lw=1)
            radius[name] = deposit_radius(x, h)
            if name in ZOOMED_SETS:
                xmax = max(xmax, radius[name], 1 + rr)
            ymax = max(ymax, float(h.max()))
        ax.set_xlim(0, 1.15 * xmax)
        ax.set_ylim(0, 1.2 * ymax)
        beyond = [name for name in SETS if radius[name] > 1.15 * xmax]
        for k, name in enumerate(beyond):  # in the set's colour, one line each
            ax.text(1.15 * xmax, (0.55 - 0.12 * k) * ymax, f"{name}: {100 * ZOOM_FRACTION:g}"
                    f" % of its mass within r/R0 = {radius[name]:.1f} \u2192", ha="right",
                    fontsize=7, color=STYLE[name][0])
        if a > 1.2 * ymax:  # the column's top is above the panel: say where
            ax.text(1.02, 1.15 * ymax, f"initial column: r < R0, h/R0 = {a:g}",
                    fontsize=7, va="top", color="gray")
        ax.set_ylabel("h/R0")
        ax.set_title(f"a = {a:g}", fontsize=9, loc="left")
    axes[-1].set_xlabel("r/R0")
    axes[0].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    return save(fig, path)


def figure_fronts(profiles: dict[str, Any], path: Path) -> Path:
    """The front (r_f - R0)/R0 against t/(H0/g)^(1/2) for a = 0.5, 2, 5, 10."""
    fig, axes = plt.subplots(2, 2, figsize=(8, 5.6))
    for ax, a in zip(axes.flat, PROFILE_RATIOS, strict=True):
        scale = math.sqrt(a * R0 / 9.81)
        for name in SETS:
            p = profiles[f"{name}|{a:g}"]
            ax.plot(p["t"] / scale, p["front"], color=STYLE[name][0], lw=1.2, label=name)
        rr = float(lube_runout(np.array([a]))[0])
        ax.axhline(rr, color="k", ls="--", lw=0.8, label="Lube's r_inf (as remembered)")
        ax.axvline(3.0, color="gray", ls=":", lw=0.8, label="t = 3 (H0/g)^(1/2)")
        ax.set_title(f"a = {a:g}", fontsize=9, loc="left")
        ax.set_xlabel("t/(H0/g)^(1/2)")
        ax.set_ylabel("(r_f - R0)/R0")
        ax.grid(alpha=0.3)
    axes.flat[0].legend(fontsize=6)
    fig.tight_layout()
    return save(fig, path)


def figures(rows: list[dict[str, Any]], numbers: dict[str, Any], profiles: dict[str, Any],
            out: Path) -> list[Path]:
    """Write every figure of the page under ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    return [figure_runout(numbers, out / "runout.png"),
            figure_height(numbers, out / "final_height.png"),
            figure_profiles(numbers, profiles, out / "deposits.png"),
            figure_fronts(profiles, out / "fronts.png")]
