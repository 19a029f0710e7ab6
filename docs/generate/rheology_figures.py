"""The figures of docs/rheology.md, from its numbers (docs/generate/rheology_numbers.py)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from axisymmetric import lube_runout  # noqa: E402

from pdeflow.analysis.sweep import published_law  # noqa: E402

REFERENCE = {"planar": ("Lube et al. 2005", lambda a: published_law("Lube et al. 2005", a)),
             "axisymmetric": ("Lube et al. 2004 (as remembered)", lube_runout)}


def runout_figure(numbers: dict[str, Any], geometry: str, path: Path) -> Path:
    """r against a, one panel per model, each law set on its finest complete grid, with
    the experiments' law."""
    models = numbers[geometry]
    fig, axes = plt.subplots(1, len(models), figsize=(5 * len(models), 4), sharey=True,
                             squeeze=False)
    name, law_of = REFERENCE[geometry]
    for ax, (model, m) in zip(axes[0], models.items(), strict=True):
        fine = repr(m["grids"][-1])
        a_all = np.array(m["per_grid"][m["laws"][0]][fine]["a"])
        a = np.geomspace(a_all.min(), a_all.max(), 200)
        ax.loglog(a, law_of(a), "k--", label=name)
        for law in m["laws"]:
            p = m["per_grid"][law][fine]
            ax.loglog(p["a"], p["r"], "o-", ms=3, label=law)
        ax.set(title=f"{geometry}, {model} (dx = {m['grids'][-1]:g} m)",
               xlabel="a = H0/L0", ylabel="r = (R - L0)/L0")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def convergence_figure(numbers: dict[str, Any], path: Path) -> Path:
    """The largest change of r(a) per grid halving against the finer grid's dx, per
    geometry, model and law set, with the 1 % line."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for ax, geometry in zip(axes, ("planar", "axisymmetric"), strict=True):
        for model, m in numbers[geometry].items():
            style = "-" if model == "single_layer" else "--"
            for k, law in enumerate(m["laws"]):
                ch = m["convergence"][law]["changes"]
                if ch:
                    ax.loglog(m["grids"][1:len(ch) + 1], ch, "o" + style, ms=3,
                              color=f"C{k}", label=f"{model} {law}")
        ax.axhline(numbers["converged_threshold"], color="k", lw=0.8)
        ax.invert_xaxis()
        ax.set(title=geometry, xlabel="finer dx of the halving [m]",
               ylabel="max over a of |r_fine/r_coarse - 1|")
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def figures(numbers: dict[str, Any], out: Path) -> dict[str, str]:
    """Write every figure into ``out``/figures; return their paths relative to ``out``."""
    d = out / "figures"
    d.mkdir(parents=True, exist_ok=True)
    paths = {"planar": runout_figure(numbers, "planar", d / "rheology_runout.png"),
             "axisymmetric": runout_figure(numbers, "axisymmetric",
                                           d / "rheology_axisymmetric.png"),
             "convergence": convergence_figure(numbers, d / "rheology_convergence.png")}
    return {k: f"figures/{p.name}" for k, p in paths.items()}
