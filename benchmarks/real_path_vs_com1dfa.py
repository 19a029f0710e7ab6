"""pdeflow and AvaFrame's com1DFA side by side on a real avalanche path (issue 37):
AvaFrame's avaHit DEM and release, one invocation, one markdown table.

    python benchmarks/real_path_vs_com1dfa.py --avaframe PATH [--path avaHit]
        [--avaframe-python /tmp/ava_venv/bin/python] [--phi 20] [--threads 2]

PATH is a checkout of AvaFrame's repository (nothing of it is copied here).

- **com1DFA**: ``benchmarks/avaframe_paths.py --inputs`` in AvaFrame's interpreter on
  a temporary copy of ``avaframe/data/<path>/Inputs`` without its entrainment,
  resistance and secondary release; Coulomb tan(``--phi``), ``curvAccInFriction`` 0,
  release thickness 1 m slope-normal (the shapefile's), its defaults otherwise (dt 0.1
  s, 5 m mesh = the DEM's cell, ``stopCrit`` 0.01). Wall time com1DFAMain's, one core.
- **pdeflow**: ``benchmarks/real_path.py``'s :func:`measure_path` (the same DEM and
  release, fv-split on ``--threads`` threads, stopped as com1DFA by the kinetic energy
  below 1 % of its peak). Wall time the solve's (kernels compiled before).

Measured the same way for both: thickness **normal to the slope** (pdeflow's vertical
peak depth times cos(theta) of the cell's steepest slope); the affected area (cells,
horizontal, whose peak thickness exceeds ``THRESHOLD``) and how much of it the two
share; the largest peak thickness, speed and pressure; the mass centre's travel angle
(drop over horizontal travel, start to end); the **run-out**: the affected cell
horizontally farthest from the release's highest point (the highest DEM cell centre in
the release), its distance and its travel angle seen from that point; and, if the
path has AvaFrame's ``LINES/path_aimec.shp``, how far along that line (each cell
projected to its nearest point on it, the line prolonged straight beyond its ends) the
affected cells reach.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from real_path import measure_path  # noqa: E402
from terrain_vs_com1dfa import avaframe_python  # noqa: E402

from pdeflow.terrain import read_raster, release_mask, shapefile_polygons  # noqa: E402
from pdeflow.terrain.thickness import cos_slope  # noqa: E402

THRESHOLD = 0.1  #: peak thickness (slope-normal) counted as affected [m]
DENSITY = 200.0  #: com1DFA's rho [kg/m^3]: its released mass over it is a volume
NO_AVAFRAME = "AvaFrame is not available (give its python with --avaframe-python)"


def release_top(inputs: Path) -> tuple[float, float, float]:
    """(x, y, z) [m] of the highest DEM cell centre inside the release shapefiles."""
    dem = read_raster(next(inputs.glob("*.asc")))
    polygons = [p for f in sorted((inputs / "REL").glob("*.shp"))
                for p in shapefile_polygons(f)]
    xs, ys = dem.x_centres, dem.y_centres[::-1]
    z = np.where(dem.nodata, np.nan, dem.values)[::-1].T  # (x, y), y up
    mask = release_mask(polygons, xs, ys, dem) & np.isfinite(z)
    i, j = np.unravel_index(np.argmax(np.where(mask, z, -np.inf)), z.shape)
    return float(xs[i]), float(ys[j]), float(z[i, j])


def com1dfa_fields(exe: str, inputs: Path, phi: float) -> dict[str, Any]:
    """com1DFA's run (``avaframe_paths.py --inputs``): fields (x, y) on its cell centres,
    the DEM's z there, mass centre, particles, times."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp, "com1dfa.npz")
        proc = subprocess.run([exe, str(ROOT / "benchmarks" / "avaframe_paths.py"),
                               str(inputs), str(out), "--inputs", "--rel-th", "1.0",
                               "--mu", repr(math.tan(math.radians(phi))),
                               "--t-end", "400"], capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"com1DFA's run failed:\n{proc.stderr[-2000:]}")
        d = {k: v for k, v in np.load(out).items()}
    cs, x0, y0 = float(d["cellsize"]), float(d["xllcenter"]), float(d["yllcenter"])
    rows, cols = d["pft"].shape
    dem = read_raster(next(inputs.glob("*.asc")))
    z = np.where(dem.nodata, np.nan, dem.values)[::-1].T
    assert z.shape == (cols, rows), (z.shape, cols, rows)
    drop = float(d["z0"] - d["z1"])
    travel = math.hypot(float(d["x1"] - d["x0"]), float(d["y1"] - d["y0"]))
    return {"code": "com1DFA", "what": f"{int(d['n_part'])} particles, {cs:.2f} m mesh, "
                                       "1 core",
            "x": x0 + cs * np.arange(cols), "y": y0 + cs * np.arange(rows), "dx": cs,
            "z": z, **{k: d[k].T for k in ("pft", "pfv", "ppr")},
            "centre_angle": math.degrees(math.atan2(drop, travel)),
            "t_end": float(d["t_end"]), "wall": float(d["wall"]),
            "volume": float(d["mass0"]) / DENSITY,
            "lost": 1.0 - float(d["mass1"]) / float(d["mass0"])}


def pdeflow_fields(root: Path, path: str, phi: float, threads: int) -> dict[str, Any]:
    """pdeflow's run (``measure_path``) in the form of :func:`com1dfa_fields`."""
    r = measure_path(root, path, phi, threads=threads)
    xc, yc, dx, dy, beds, peak, _ = r["_arrays"]
    cells = f"{r['cells'][0]} x {r['cells'][1]} cells of {dx:.2f} m"
    return {"code": "pdeflow", "what": f"{cells}, {threads} threads", "x": xc, "y": yc,
            "dx": dx, "z": beds, "pft": peak[0] * cos_slope(beds, dx, dy),
            "pfv": peak[1], "ppr": peak[2], "centre_angle": r["travel_angle_deg"],
            "t_end": r["t_end_s"], "wall": r["wall_s"], "ended": r["ended"],
            "volume": r["volume_m3"], "lost": 0.0}


def measures(run: dict[str, Any], top: tuple[float, float, float]) -> dict[str, Any]:
    """A table row: affected area [ha], peaks, mass centre angle, run-out distance
    [m] and angle [deg] from the release's top, times [s]."""
    hit = run["pft"] > THRESHOLD
    x = run["x"][:, None] * np.ones(hit.shape)
    y = run["y"][None, :] * np.ones(hit.shape)
    dist = np.where(hit, np.hypot(x - top[0], y - top[1]), -1.0)
    k = np.unravel_index(np.argmax(dist), dist.shape)
    return {**run, "hit": hit, "area": float(hit.sum() * run["dx"] ** 2 / 1e4),
            "runout": float(dist[k]),
            "runout_angle": math.degrees(math.atan2(top[2] - run["z"][k], dist[k])),
            "runout_xy": (float(x[k]), float(y[k]))}


def along(line: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The distance [m] along the polyline ``line`` (k, 2) of each point's nearest point
    on it, its first and last segments prolonged beyond its ends (negative before its
    start, beyond its length after its end; the points' x, y arrays of one shape)."""
    px, py = np.ravel(x)[:, None], np.ravel(y)[:, None]
    a, b = line[:-1], line[1:]
    seg = b - a
    length = np.hypot(seg[:, 0], seg[:, 1])
    lo, hi = np.zeros(len(seg)), np.ones(len(seg))
    lo[0], hi[-1] = -np.inf, np.inf
    t = np.clip(((px - a[:, 0]) * seg[:, 0] + (py - a[:, 1]) * seg[:, 1]) / length ** 2,
                lo, hi)
    dist = np.hypot(a[:, 0] + t * seg[:, 0] - px, a[:, 1] + t * seg[:, 1] - py)
    k = np.argmin(dist, axis=1)
    start = np.concatenate([[0.0], np.cumsum(length)[:-1]])
    rows = np.arange(k.size)
    return (start[k] + t[rows, k] * length[k]).reshape(np.shape(x))


def path_line(inputs: Path) -> np.ndarray | None:
    """The vertices (k, 2) [m] of AvaFrame's ``LINES/path_aimec.shp`` (its first
    shape), or None without it or pyshp."""
    try:
        import shapefile
    except ImportError:
        return None
    file = inputs / "LINES" / "path_aimec.shp"
    if not file.exists():
        return None
    with shapefile.Reader(str(file)) as r:
        return np.asarray(r.shapes()[0].points, dtype=float)[:, :2]


def shared(a: dict[str, Any], b: dict[str, Any]) -> tuple[float, float, float]:
    """(both, only a, only b) [ha]: a's affected cells matched to b's nearest cell
    centre (the grids are offset by half a cell), areas in a's cells."""
    i = np.clip(np.rint((a["x"] - b["x"][0]) / b["dx"]).astype(int), 0, b["x"].size - 1)
    j = np.clip(np.rint((a["y"] - b["y"][0]) / b["dx"]).astype(int), 0, b["y"].size - 1)
    other = b["hit"][np.ix_(i, j)]
    cell = a["dx"] ** 2 / 1e4
    return (float((a["hit"] & other).sum() * cell), float((a["hit"] & ~other).sum() * cell),
            float((~a["hit"] & other).sum() * cell))


def table(rows: list[dict[str, Any]]) -> list[str]:
    """The markdown table of the rows."""
    out = ["| code | resolution | affected area [ha] | max pft [m] | max pfv [m/s] | "
           "max ppr [kPa] | mass centre angle [deg] | run-out [m] | run-out angle [deg] "
           "| t end [s] | wall [s] |", "|---|---|" + "---:|" * 9]
    for r in rows:
        out.append(f"| {r['code']} | {r['what']} | {r['area']:.1f} | {r['pft']:.2f} | "
                   f"{r['pfv']:.1f} | {r['ppr']:.0f} | {r['centre_angle']:.2f} | "
                   f"{r['runout']:.0f} | {r['runout_angle']:.2f} | {r['t_end']:.1f} | "
                   f"{r['wall']:.1f} |")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--avaframe", type=Path, required=True,
                    help="a checkout of AvaFrame's repository")
    ap.add_argument("--path", default="avaHit", help="AvaFrame's path (avaHit)")
    ap.add_argument("--avaframe-python", default=None)
    ap.add_argument("--phi", type=float, default=20.0, help="friction angle [deg]")
    ap.add_argument("--threads", type=int, default=2, help="pdeflow's threads")
    args = ap.parse_args(argv)
    inputs = args.avaframe / "avaframe" / "data" / args.path / "Inputs"
    top = release_top(inputs)
    print(f"{args.path}: Coulomb {args.phi:g} deg, release 1 m slope-normal, no "
          f"entrainment; affected: peak thickness (slope-normal) > {THRESHOLD:g} m; "
          f"release top ({top[0]:.0f}, {top[1]:.0f}), z {top[2]:.0f} m")
    print(f"load before: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    runs = []
    exe = avaframe_python(args.avaframe_python)
    if exe is None:
        print(NO_AVAFRAME)
    else:
        runs.append(com1dfa_fields(exe, inputs, args.phi))
    print(f"load between: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    runs.append(pdeflow_fields(args.avaframe, args.path, args.phi, args.threads))
    rows = [measures(r, top) for r in runs]
    for r in rows:
        r.update(pft=float(r["pft"].max()), pfv=float(r["pfv"].max()),
                 ppr=float(r["ppr"].max()))
    print("\n".join(table(rows)))
    for r in rows:
        print(f"{r['code']}: released {r['volume']:.0f} m^3, {r['lost']:.2%} of it left "
              f"the domain; farthest affected cell ({r['runout_xy'][0]:.0f}, "
              f"{r['runout_xy'][1]:.0f})" + (f"; ended: {r['ended']}" if "ended" in r
                                             else ""))
    line = path_line(inputs)
    if line is not None:
        s_top = float(along(line, np.array(top[0]), np.array(top[1])))
        for r in rows:
            x = r["x"][:, None] * np.ones(r["hit"].shape)
            y = r["y"][None, :] * np.ones(r["hit"].shape)
            reach = float(along(line, x[r["hit"]], y[r["hit"]]).max())
            print(f"{r['code']}: along path_aimec.shp the affected cells reach s = "
                  f"{reach:.0f} m, {reach - s_top:.0f} m beyond the release top's "
                  f"{s_top:.0f} m")
    if len(rows) == 2:
        both, only_p, only_c = shared(rows[1], rows[0])
        print(f"affected by both {both:.1f} ha, by pdeflow only {only_p:.1f} ha, by "
              f"com1DFA only {only_c:.1f} ha (pdeflow's cells)")
    print(f"load after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
