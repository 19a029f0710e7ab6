"""Regenerate docs/stability.md's generated sections and its figures: the stability study.

    python docs/generate/stability.py               # CFL search and map (~40 min on 2 cores)
    python docs/generate/stability.py --extremes    # also the heavy extreme runs (~2 min)

Runs the largest-stable-CFL search and the stability map of every variant
(:mod:`pdeflow.analysis.stability`; problems in :mod:`pdeflow.analysis.stability_problems`)
and rewrites the sections of ``OUT/stability.md`` between ``<!-- BEGIN stability:NAME``
and ``<!-- END stability:NAME -->`` (the rest of the file is left alone) and the figures
``stability_map.png`` and ``stability_cfl.png``. ``--extremes`` adds the table of heavy
runs of the paper's scheme (10^5 cells for 0.1 s, aspect ratio 100 on a fine grid, a
deposit left for 100 s, a column just below / above its friction angle): the slow tests
of tests/test_stress.py check the same runs pass or fail; this table records their
numbers (steps, rest times, fronts, mass errors). ``--quick`` is a smoke test, not for
the docs.
"""

from __future__ import annotations

import argparse
import math
import re
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from pde import CartesianGrid  # noqa: E402

from pdeflow import FVSplitSolver  # noqa: E402
from pdeflow.analysis import stability as S  # noqa: E402
from pdeflow.analysis.stability_problems import (  # noqa: E402
    H1,
    H2,
    G,
    cfl_problems,
    reference_speed,
    shear_band,
)
from pdeflow.io import atomic_path  # noqa: E402
from pdeflow.metrics import mass, total_depth  # noqa: E402
from pdeflow.models import SingleLayerGranular, TwoLayerGranular  # noqa: E402
from pdeflow.models.two_layer.hyperbolicity import lower_bound_fl, upper_bound_fr  # noqa: E402
from pdeflow.variant import Variant  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
COMMAND = "python docs/generate/stability.py"
STATUS_STYLE = {"stable": ("o", "tab:green"), "growth": ("^", "tab:orange"),
                "blow-up": ("x", "tab:red")}


# --- figures ---------------------------------------------------------------------------

def map_figure(maps: dict[str, dict[tuple, S.Outcome]], path: Path, cfl: float,
               cells: int = 400, t_end: float = 4.0) -> Path:
    """One panel per variant: outcome over (r, du/sqrt(gH)) with the band edges."""
    names = list(maps)
    cols = min(3, len(names))
    rows = math.ceil(len(names) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), sharex=True,
                             sharey=True, squeeze=False)
    rs = np.linspace(0.02, 0.995, 120)
    c = math.sqrt(G * (H1 + H2))
    edges = np.array([shear_band(r) for r in rs]) / c
    fl = np.array([lower_bound_fl(H1, H2, G, r) for r in rs]) / c
    fr = np.array([upper_bound_fr(H1, H2, G, r) for r in rs]) / c
    for ax, name in zip(axes.flat, names, strict=False):
        ax.fill_between(rs, edges[:, 0], edges[:, 1], color="0.85")
        ax.plot(rs, fl, "k--", lw=0.8)
        ax.plot(rs, fr, "k--", lw=0.8)
        for status, (marker, colour) in STATUS_STYLE.items():
            pts = [(r, d) for (r, d), o in maps[name].items() if o.status == status]
            if pts:
                a = np.array(pts)
                ax.scatter(a[:, 0], a[:, 1], marker=marker, c=colour, s=22)
        ax.set_title(name, fontsize=10)
        ax.set_ylim(0, max(d for _, d in maps[name]) * 1.05)
    for ax in axes[-1]:
        ax.set_xlabel("rho1/rho2")
    for ax in axes[:, 0]:
        ax.set_ylabel("|u1 - u2| / sqrt(g H)")
    for ax in axes.flat[len(names):]:
        ax.axis("off")
    handles = [Patch(color="0.85", label="non-hyperbolic (exact)"),
               Line2D([], [], color="k", ls="--", lw=0.8, label="bounds F_L, F_R")]
    handles += [Line2D([], [], ls="", marker=m, color=c, label=s)
                for s, (m, c) in STATUS_STYLE.items()]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8)
    fig.suptitle(f"shear flow h1 = {H1} m over h2 = {H2} m, {cells} cells, {t_end:g} s, "
                 f"CFL {cfl}", fontsize=11)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    return _save(fig, path)


def cfl_figure(search: dict[str, dict[str, dict]], path: Path) -> Path:
    """Outcome per variant (rows) and CFL number (columns), one panel per problem."""
    names = list(search)
    problems = list(next(iter(search.values())))
    cfls = sorted({c for v in search.values() for p in v.values() for c in p})
    code = {"stable": 0, "growth": 1, "blow-up": 2}
    cmap = ListedColormap(["tab:green", "tab:orange", "tab:red", "white"])
    fig, axes = plt.subplots(1, len(problems), figsize=(5.2 * len(problems),
                                                        0.42 * len(names) + 1.6),
                             squeeze=False)
    for ax, prob in zip(axes[0], problems, strict=True):
        img = np.full((len(names), len(cfls)), 3)
        for i, name in enumerate(names):
            for j, c in enumerate(cfls):
                o = search[name][prob].get(c)
                if o is not None:
                    img[i, j] = code[o.status]
        ax.imshow(img, cmap=cmap, vmin=0, vmax=3, aspect="auto")
        ax.set_xticks(range(len(cfls)), [f"{c:g}" for c in cfls], rotation=90, fontsize=7)
        ax.set_yticks(range(len(names)), names, fontsize=8)
        ax.axvline(cfls.index(1.0) + 0.5 if 1.0 in cfls else -1, color="k", lw=1)
        ax.set_xlabel("CFL number")
        ax.set_title(prob, fontsize=10)
    fig.suptitle("green stable, orange perturbation growth, red blow-up, white not run "
                 "(scan stops after two failures); fv-split validates CFL <= 1 (line)",
                 fontsize=9)
    fig.tight_layout()
    return _save(fig, path)


def _save(fig: Any, path: Path) -> Path:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return path


# --- tables ----------------------------------------------------------------------------

def _fmt_cfl(res: dict[float, S.Outcome]) -> str:
    best = S.largest_stable(res)
    first = next((c for c in sorted(res) if res[c].status != "stable"), None)
    s = "none" if best is None else f"{best:g}"
    if first is None:
        return f"{s} (all tested stable)"
    return f"{s} (first failure at {first:g}: {res[first].status})"


def cfl_table(search: dict[str, dict[str, dict]]) -> str:
    """Markdown table: largest stable CFL per variant and problem."""
    problems = list(next(iter(search.values())))
    lines = ["| variant | " + " | ".join(problems) + " |",
             "|---|" + "---|" * len(problems)]
    for name, res in search.items():
        lines.append(f"| `{name}` | " + " | ".join(_fmt_cfl(res[p]) for p in problems)
                     + " |")
    return "\n".join(lines)


def map_table(maps: dict[str, dict[tuple, S.Outcome]]) -> str:
    """Markdown table: per variant and density ratio, the du/sqrt(gH) values that are
    not stable."""
    ratios = sorted({r for m in maps.values() for r, _ in m})
    lines = ["| variant | stable points | unstable du/sqrt(gH) per rho1/rho2 |", "|---|---|---|"]
    for name, m in maps.items():
        n_ok = sum(o.status == "stable" for o in m.values())
        parts = []
        for r in ratios:
            bad = [d for (rr, d), o in sorted(m.items()) if rr == r and o.status != "stable"]
            if bad:
                kinds = {m[(r, d)].status for d in bad}
                rng = f"{min(bad):g}-{max(bad):g}" if len(bad) > 1 else f"{bad[0]:g}"
                parts.append(f"{r:g}: {rng} ({', '.join(sorted(kinds))})")
        lines.append(f"| `{name}` | {n_ok}/{len(m)} | " + ("; ".join(parts) or "-") + " |")
    return "\n".join(lines)


def band_table(ratios: Sequence[float]) -> str:
    """Markdown table of the band edges of the shear problem, in units of sqrt(g H)."""
    lines = ["| rho1/rho2 | F_L | F_c1 | F_c2 | F_R |", "|---|---|---|---|---|"]
    s = math.sqrt(G * (H1 + H2))
    for r in ratios:
        lo, hi = shear_band(r)
        lines.append(f"| {r:g} | {lower_bound_fl(H1, H2, G, r) / s:.3f} | {lo / s:.3f} "
                     f"| {hi / s:.3f} | {upper_bound_fr(H1, H2, G, r) / s:.3f} |")
    return "\n".join(lines)


def extremes_table(rows: list[dict[str, Any]]) -> str:
    lines = ["| case | cells | steps | at rest at [s] | front [m] | mass error | finite, "
             "h >= 0 | wall time [s] | note |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        rest = "-" if r["rest_time"] is None else f"{r['rest_time']:.3f}"
        front = "-" if r["front"] is None else f"{r['front']:.3f}"
        steps = "-" if not r["steps"] else str(r["steps"])
        lines.append(f"| {r['case']} | {r['cells']} | {steps} | {rest} | {front} | "
                     f"{r['mass_error']:.1e} | {'yes' if r['finite_nonneg'] else 'NO'} | "
                     f"{r['wall']:.2f} | {r['note']} |")
    return "\n".join(lines)


# --- extremes (the numbers of the slow tests in tests/test_stress.py) -------------------

def _column(n: int, length: float, L0: float, H0: float, two: bool, x0: float = 0.0,
            **params: Any):
    """A column of L0 x H0 [m] at x0 between walls (5.1's wedge split for two layers)."""
    g = CartesianGrid([[0.0, length]], n)
    x = g.axes_coords[0]
    inside = (x >= x0) & (x < x0 + L0)
    if not two:
        eq = SingleLayerGranular(bc=("wall", "wall"), **params)
        return eq, eq.make_state(g, h=np.where(inside, H0, 0.0))
    eq = TwoLayerGranular(bc=("wall", "wall"), **params)
    h2 = np.where(inside, np.minimum(H0, (x0 + L0 - x) * math.tan(math.radians(60))), 0.0)
    return eq, eq.make_state(g, h1=np.where(inside, H0 - h2, 0.0), h2=h2)


def _mass(eq: Any, q: np.ndarray) -> float:
    return mass(q, 1.0, eq.system.densities(eq.parameters))


def extremes(log: Callable[[str], None] = print) -> list[dict[str, Any]]:
    """Run the heavy extreme cases with fv-split (the paper's scheme); one row each."""
    rows: list[dict[str, Any]] = []

    def record(name, eq, st0, t_end, note=""):
        t0 = time.perf_counter()
        final, info = eq.solve(st0, t_range=t_end, solver="fv-split", cfl=0.3,
                               tracker=None, ret_info=True)
        wall = time.perf_counter() - t0
        q = final.data
        x = final.grid.axes_coords[0]
        H = total_depth(q)
        wet = np.nonzero(H > 1e-3)[0]
        m0 = _mass(eq, st0.data)
        row = {"case": name, "cells": q.shape[1], "steps": int(info["solver"]["steps"]),
               "rest_time": info["solver"].get("rest_time"),
               "front": float(x[wet[-1]] + 0.5 * (x[1] - x[0])) if wet.size else None,
               "mass_error": abs(_mass(eq, q) - m0) / m0,
               "finite_nonneg": bool(np.all(np.isfinite(q)) and np.all(q[::2] >= 0)),
               "wall": wall, "note": note}
        rows.append(row)
        log(f"  {name}: {row}")
        return final, info

    record("5.1 column, 10^5 cells (dx = 7e-5 m), first 0.1 s",
           *_column(100_000, 7.0, 1.0, 2.0, True), 0.1,
           "front at 0.1 s; 1.75 m with dx = 0.05 m")
    for two in (True, False):
        model = "two layers" if two else "one layer"
        record(f"aspect ratio 100 (L0 = 0.1 m, H0 = 10 m), {model}, dx = 2 mm",
               *_column(20_000, 40.0, 0.1, 10.0, two), 30.0)
        record(f"aspect ratio 0.01 (L0 = 2 m, H0 = 2 cm), {model}, dx = 2 mm",
               *_column(2_000, 4.0, 2.0, 0.02, two), 30.0)
    eq, st0 = _column(140, 7.0, 1.0, 2.0, True)
    rest, info = record("5.1 column, dx = 0.05 m, to rest", eq, st0, 10.0)
    t_rest = info["solver"]["rest_time"]
    later = rest.copy()
    t0 = time.perf_counter()
    solver = FVSplitSolver(eq, cfl=0.3, stop_at_rest=False)
    solver.make_stepper(later)(later, t_rest, t_rest + 100.0)
    same = np.array_equal(later.data, rest.data)
    rows.append({"case": "... then left for 100 s (stop_at_rest off)", "cells": 140,
                 "steps": int(solver.info["steps"]), "rest_time": t_rest,
                 "front": rows[-1]["front"],
                 "mass_error": abs(_mass(eq, later.data) - _mass(eq, rest.data))
                 / _mass(eq, rest.data),
                 "finite_nonneg": same, "wall": time.perf_counter() - t0,
                 "note": "deposit bitwise unchanged" if same else "deposit CHANGED"})
    log(f"  {rows[-1]}")
    for d in (-1.0, 1.0):
        record(f"column 1 m x 0.5 m on a slope phi_B {d:+g} deg (phi_B = 30), dx = 2 cm",
               *_column(2500, 50.0, 1.0, 0.5, False, x0=1.0, theta_deg=30.0 + d,
                        phi_b_deg=30.0), 40.0 if d < 0 else 10.0)
    return rows


# --- the document ----------------------------------------------------------------------

def replace_section(text: str, name: str, content: str) -> str:
    """Replace (or append) the generated section ``name`` of a markdown text."""
    begin = f"<!-- BEGIN stability:{name} (generated by {COMMAND}; do not edit) -->"
    end = f"<!-- END stability:{name} -->"
    block = f"{begin}\n{content.rstrip()}\n{end}"
    pattern = re.compile(re.escape(begin.split(" (")[0]) + r".*?" + re.escape(end), re.S)
    if pattern.search(text):
        return pattern.sub(lambda _: block, text)
    return text.rstrip() + "\n\n" + block + "\n"


def map_section(names: Sequence[str], quick: bool, out: Path,
                command: str) -> tuple[str, list[Path]]:
    """The map section's text (CFL search, map, band edges) and the figures written."""
    cfl_map = 0.3
    if quick:
        ratios, dus, cells, t_end = (0.3, 0.67, 0.95), (0.3, 1.0, 2.0), 100, 1.0
        cfls: Sequence[float] = (0.3, 0.9, 1.4)
    else:
        ratios, dus, cells, t_end = S.DEFAULT_RATIOS, S.DEFAULT_DU, 400, 4.0
        cfls = S.DEFAULT_CFLS
    t0 = time.perf_counter()
    print("largest stable CFL:")
    problems = cfl_problems(quick)
    for p in problems:
        reference_speed(p)
    search = S.cfl_search(names, problems, cfls)
    print(f"stability map at CFL {cfl_map}:")
    maps = S.stability_map(names, ratios, dus, cfl_map, cells, t_end)
    map_png = map_figure(maps, out / "stability_map.png", cfl_map, cells, t_end)
    cfl_png = cfl_figure(search, out / "stability_cfl.png")
    elapsed = time.perf_counter() - t0
    refs = ", ".join(f"{p.name}: {p.s_ref:.3g} m/s" for p in problems)
    variants_md = "\n".join(f"* `{n}`: {Variant.parse(n).description}" for n in names)
    text = (
        f"Command: `{command}` ({'--quick, ' if quick else ''}{elapsed:.0f} s on this "
        f"machine).\n\nVariants:\n\n{variants_md}\n\n"
        f"Reference wave speeds s_ref (the method of lines' dt = CFL dx / s_ref): "
        f"{refs}.\n\n"
        f"### Largest stable CFL\n\n{cfl_table(search)}\n\n"
        f"![largest stable CFL](stability_cfl.png)\n\n"
        f"`{cfl_png.name}`: outcome per variant and CFL number for each problem "
        f"(`{command}`).\n\n"
        f"### Stable region in (rho1/rho2, relative velocity) at CFL {cfl_map}\n\n"
        f"{map_table(maps)}\n\n"
        f"![stability map](stability_map.png)\n\n"
        f"`{map_png.name}`: outcome of the shear problem per variant; grey: the exact "
        f"non-hyperbolic band, dashed: the bounds F_L, F_R (`{command}`).\n\n"
        f"Band edges for h1 = {H1} m, h2 = {H2} m, in units of sqrt(g H):\n\n"
        f"{band_table(ratios)}\n")
    return text, [map_png, cfl_png]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog=COMMAND, description=__doc__.split("\n")[0])
    parser.add_argument("--out", default=str(ROOT / "docs"),
                        help="directory of stability.md and its figures (default: docs)")
    parser.add_argument("--variants", default=",".join(S.VARIANTS),
                        help="comma-separated variant names (default: the study's)")
    parser.add_argument("--quick", action="store_true",
                        help="coarse map and short runs (a smoke test, not for the docs)")
    parser.add_argument("--extremes", action="store_true",
                        help="also run the heavy extreme cases (about two minutes)")
    args = parser.parse_args(argv)
    names = [Variant.parse(v).name for v in args.variants.split(",") if v]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    default_out = out.resolve() == (ROOT / "docs").resolve()
    command = COMMAND + ("" if default_out else f" --out {args.out}")
    md = out / "stability.md"
    text = md.read_text() if md.exists() else "# Stability\n"
    section, pngs = map_section(names, args.quick, out, command)
    text = replace_section(text, "map", section)
    if args.extremes:
        print("extremes:")
        text = replace_section(
            text, "extremes", f"Command: `{command} --extremes` (fv-split, the paper's "
            f"scheme, CFL 0.3).\n\n{extremes_table(extremes())}\n")
    with atomic_path(md) as tmp:
        tmp.write_text(text)
    print(f"wrote {md}, {', '.join(str(p) for p in pngs)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
