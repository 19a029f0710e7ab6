"""Figures of runs: stacked layers, velocities and F_extra (as the paper's Figs. 3-7)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from .io import atomic_path

DRY = 1e-9


def _velocity(h: np.ndarray, m: np.ndarray) -> np.ndarray:
    return np.where(h > DRY, m / np.where(h > DRY, h, 1.0), np.nan)


def plot_depths(ax, x: np.ndarray, two: np.ndarray | None,
                single: np.ndarray | None) -> None:
    """Lower layer filled from the bed, upper layer stacked on it, single layer as a line."""
    if two is not None:
        h1, h2 = two[0], two[2]
        ax.fill_between(x, 0, h2, color="tab:brown", alpha=0.6, lw=0,
                        label="lower layer $h_2$")
        ax.fill_between(x, h2, h1 + h2, color="tab:orange", alpha=0.5, lw=0,
                        label="upper layer $h_1$")
        ax.plot(x, h1 + h2, color="tab:orange", lw=1)
    if single is not None:
        ax.plot(x, single[0], color="k", lw=1.2, label="single layer")
    ax.set_ylabel("depth [m]")


def plot_velocities(ax, x: np.ndarray, two: np.ndarray | None,
                    single: np.ndarray | None) -> None:
    """Velocities where a layer is present (gaps where it is dry)."""
    if two is not None:
        ax.plot(x, _velocity(two[0], two[1]), color="tab:orange", label="$u_1$ (upper)")
        ax.plot(x, _velocity(two[2], two[3]), color="tab:brown", label="$u_2$ (lower)")
    if single is not None:
        ax.plot(x, _velocity(single[0], single[1]), color="k", lw=1.2,
                label="single layer")
    ax.set_ylabel("velocity [m/s]")


def snapshot_figure(x: np.ndarray, t: float, two: np.ndarray | None,
                    single: np.ndarray | None, fextra: np.ndarray | None,
                    title: str = "") -> Any:
    """Three stacked panels at time t, like the paper's Figs. 3-6."""
    fig, axes = plt.subplots(3, 1, figsize=(7, 7.5), sharex=True)
    plot_depths(axes[0], x, two, single)
    plot_velocities(axes[1], x, two, single)
    axes[2].plot(x, fextra if fextra is not None else np.zeros_like(x), color="tab:red")
    axes[2].set_ylabel(r"$F_{extra}/\rho_1$ [m$^2$/s$^2$]")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[1].legend(loc="upper right", fontsize=8)
    axes[2].set_xlabel("x [m]")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(f"{title} t = {t:g} s".strip())
    fig.tight_layout()
    return fig


def deposit_figure(x: np.ndarray, two: np.ndarray | None, single: np.ndarray | None,
                   title: str = "", times: str = "") -> Any:
    """Final deposits of both models (paper's Fig. 7)."""
    fig, ax = plt.subplots(figsize=(7, 3.2))
    plot_depths(ax, x, two, single)
    ax.legend(loc="upper right", fontsize=8)
    ax.set_xlabel("x [m]")
    ax.grid(alpha=0.3)
    ax.set_title(f"{title}: final deposits\n{times}".strip(), fontsize=10)
    fig.tight_layout()
    return fig


def save(fig: Any, path: str | Path) -> Path:
    """Save a figure atomically (complete file or none) and close it."""
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format=path.suffix.lstrip(".") or "png")
    plt.close(fig)
    return path


def case_figures(results: dict[str, Any], outdir: str | Path,
                 prefix: str = "") -> list[Path]:
    """Snapshot figures at every stored time and the final-deposit figure."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    two = results.get("two_layer")
    one = results.get("single_layer")
    any_res = two or one
    x = any_res.x
    times = sorted(set(two.snapshots if two else {}) | set(one.snapshots if one else {}))
    paths = []
    for t in times:
        s2 = two.snapshots.get(t) if two else None
        s1 = one.snapshots.get(t) if one else None
        fig = snapshot_figure(x, t, s2[0] if s2 else None, s1[0] if s1 else None,
                              s2[1] if s2 else None, any_res.case.name)
        paths.append(save(fig, outdir / f"{prefix}snapshot_t{t:g}.png"))
    stop = []
    for res in (two, one):
        if res is not None:
            st = res.summary.get("stop_time")
            stop.append(f"{res.model}: t={st:.2f} s" if st else f"{res.model}: moving")
    fig = deposit_figure(x, two.state.data if two else None,
                         one.state.data if one else None, any_res.case.name,
                         "(" + ", ".join(stop) + ")")
    paths.append(save(fig, outdir / f"{prefix}final_deposits.png"))
    return paths
