"""What numba's private hooks (``pdeflow.numerics.numba_hooks``) and the compile helper
buy: test 5.1 on the hooks against the public path (``PDEFLOW_NUMBA_FALLBACK=1``).

Not part of ``run_benchmarks.py`` (nothing is stored or rendered); each measurement is
run in turn for the sides it compares (A B A B ...), each process with an empty
``NUMBA_CACHE_DIR`` of its own, and prints one JSON line per run with the machine's
1-minute load average, then the medians:

* ``cold``: ``python -m pdeflow run cases/paper_5_1_dam_break.toml`` with an empty
  cache, then ``-q`` again with the cache it left (warm), wall and CPU [s] of the
  processes (helpers included), for this tree with the hooks, this tree on the public
  path and ``--tree`` (e.g. the main checkout) with its own;
* ``compile``: ``warmup.prepare`` of 5.1's steppers in one process (no helper), CPU [s]:
  what compiling with the hooks costs against compiling plain ``numba.njit`` kernels;
* ``interpreter``: the same with another thread running (a server's process, where the
  helper is a new interpreter), helper on and off, wall [s];
* ``pointers``: one call of the stepping loop (one tiny step) with its kernels passed
  as function pointers or as dispatchers (the public path), [us] per call.

Usage: ``python benchmarks/compile_paths.py cold --repeats 3 --tree /path/to/main``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from cold_start import CASE, ROOT, _child

_PREPARE = r"""
import json, sys, threading, time
if sys.argv[1] == "thread":
    threading.Thread(target=threading.Event().wait, daemon=True).start()
from pdeflow.cases import load_case
from pdeflow.numerics.warmup import prepare
from pdeflow.simulate import case_steppers
steppers = case_steppers(load_case("cases/paper_5_1_dam_break.toml"))
c0, t0 = time.process_time(), time.perf_counter()
prepare(steppers, parallel=sys.argv[2] == "helper")
print(json.dumps({"cpu_s": time.process_time() - c0, "wall_s": time.perf_counter() - t0}))
"""

_POINTERS = r"""
import json, time
import numpy as np
import pdeflow
from pdeflow.numerics import layout as L
from pdeflow.models.single_layer.kernels import KERNELS as SINGLE_LAYER
from pdeflow.numerics.splitting import scheme_stepper
st = scheme_stepper(SINGLE_LAYER, L.FLUX_HLL, 1, L.LIMITER_MINMOD, False,
                    L.GEOMETRY_PLANAR).ready()
eq = pdeflow.SingleLayerGranular()
q = np.array([[1.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])
args = (q, 0.0, 1e-9, 0.25, np.zeros((L.N_METRIC, 5)), 0, 1, eq.parameter_array(), 0.3,
        eq.new_diagnostics(4), np.empty_like(q), np.empty_like(q), np.empty((3, 2, 4)), 1,
        False)
sides = {"pointers": st.arguments,
         "dispatchers": (st.advect, st.sources, st.predictor, st.fallback)}
for name, arguments in sides.items():
    st.arguments = arguments
    st(*args)
    t0 = time.perf_counter()
    for _ in range(2000):
        st(*args)
    print(json.dumps({"side": name, "us_per_call": (time.perf_counter() - t0) / 2e-3}))
"""


def _python(code: str, *argv: str, public: bool = False) -> list[dict]:
    """``code`` in a fresh process with an empty numba cache; its JSON lines."""
    cache = tempfile.mkdtemp(prefix="compile-paths-")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NUMBA_CACHE_DIR": cache,
           "PDEFLOW_NUMBA_FALLBACK": "1" if public else "0"}
    try:
        out = subprocess.run([sys.executable, "-c", code, *argv], cwd=ROOT, env=env,
                             capture_output=True, text=True, timeout=1800, check=True)
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    return [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]


def _cold(side: str, tree: Path) -> dict:
    os.environ["PDEFLOW_NUMBA_FALLBACK"] = "1" if side == "public" else "0"
    cmd = [sys.executable, "-m", "pdeflow", "run", str(tree / CASE)]
    cache = tempfile.mkdtemp(prefix="compile-paths-")
    try:
        cold, warm = _child(cmd, tree, cache), _child(cmd + ["-q"], tree, cache)
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    return {"cold_wall_s": cold["wall_s"], "cold_cpu_s": cold["cpu_s"],
            "warm_wall_s": warm["wall_s"], "warm_cpu_s": warm["cpu_s"]}


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("what", choices=["cold", "compile", "interpreter", "pointers"])
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--tree", type=Path, help="another checkout for `cold` (e.g. main)")
    a = p.parse_args(argv)
    sides = {"cold": ["hooks", "public", *(["tree"] if a.tree else [])],
             "compile": ["hooks", "public"], "interpreter": ["helper", "alone"],
             "pointers": ["both"]}[a.what]
    runs: dict[str, list[dict]] = {}
    for i in range(a.repeats):
        for side in sides:
            load = os.getloadavg()[0]
            if a.what == "cold":
                rows = [_cold(side, a.tree if side == "tree" else ROOT)]
            elif a.what == "pointers":
                rows = _python(_POINTERS)
            else:
                rows = _python(_PREPARE, "thread" if a.what == "interpreter" else "-",
                               side, public=side == "public")
            for row in rows:
                name = row.pop("side", side)
                runs.setdefault(name, []).append(row)
                print(json.dumps({"run": i, "side": name, "load": load, **row}), flush=True)
    for name, rows in runs.items():
        print(name, {k: round(statistics.median(r[k] for r in rows), 3) for k in rows[0]})


if __name__ == "__main__":
    main()
