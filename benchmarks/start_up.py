"""A warm start: how long ``pdeflow`` takes when the numba cache holds its kernels.

Measured by ``python benchmarks/run_benchmarks.py --only start`` (into
``benchmarks/measurements/start_up.json``, rendered into docs/performance.md):

* **kernel load**: in a fresh process, after ``import pdeflow``, the time
  :func:`pdeflow.numerics.warmup.prepare` takes to load the 5.1 case's kernels (both
  models) from the disk cache (``pdeflow.simulate.case_steppers``), wall and CPU time of
  the process; median over fresh processes.
* **commands**: ``pdeflow run cases/paper_5_1_dam_break.toml --summary s.json -q``,
  the same with the default outputs (summary and every figure, ``--outdir``) and
  ``python -c "import pde"``, run in turn (A B C A B C ...), each in a fresh working
  directory; the ratios are taken run by run and their median reported, so that a
  change of the machine's load hits both sides of a ratio alike.
* **app**: ``pdeflow app`` started to the dam-break page's first picture
  (:mod:`app_start`), when Chromium and Playwright are there.

Every process uses one numba cache of its own, filled by one run first, and one
bytecode cache (``PYTHONPYCACHEPREFIX``, ``PYTHONDONTWRITEBYTECODE`` unset for the
children): where the environment sets ``PYTHONDONTWRITEBYTECODE``, every process would
otherwise compile pdeflow's modules from source while py-pde's come compiled from
site-packages, which is no warm start.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import statistics
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import cold_start

ROOT = Path(__file__).resolve().parents[1]
CASE = "cases/paper_5_1_dam_break.toml"

_LOAD = r"""
import json, sys, time
t0 = time.perf_counter()
import pdeflow  # noqa: F401
from pdeflow.cases import load_case
from pdeflow.numerics.warmup import prepare
from pdeflow.simulate import case_steppers
t1 = time.perf_counter()
steppers = case_steppers(load_case(sys.argv[1]))
w0, c0 = time.perf_counter(), time.process_time()
prepare(steppers)
w1, c1 = time.perf_counter(), time.process_time()
print("RESULT" + json.dumps({"import_s": t1 - t0, "load_s": w1 - w0, "load_cpu_s": c1 - c0}),
      file=sys.stderr)
"""


def _child(cmd: list[str], cache: str) -> dict[str, Any]:
    """``cmd`` in a fresh working directory with this checkout on PYTHONPATH and the
    numba cache ``cache`` (:func:`cold_start._child`): wall and CPU time [s], and what
    its RESULT line on stderr says."""
    return cold_start._child(cmd, ROOT, cache)


def commands() -> dict[str, list[str]]:
    """The timed commands by label (``pdeflow`` as ``python -m pdeflow``)."""
    case = str(ROOT / CASE)
    run = [sys.executable, "-m", "pdeflow", "run", case]
    return {"run -q": [*run, "--summary", "s.json", "-q"],
            "run (figures)": [*run, "--outdir", "out"],
            "import pde": [sys.executable, "-c", "import pde"]}


def measure(repeats: int = 9, app: bool = True, log: Any = sys.stderr) -> dict[str, Any]:
    """Kernel loads and the commands of the module docstring, ``repeats`` each (each
    round's times printed to ``log``; None: quiet)."""
    load = os.getloadavg()
    cache = tempfile.mkdtemp(prefix="pdeflow-start-numba-")
    try:
        with _bytecode_cache(os.path.join(cache, "pycache")):
            cmds = commands()
            _child(cmds["run -q"], cache)  # fills the cache
            loads = [_child([sys.executable, "-c", _LOAD, str(ROOT / CASE)], cache)
                     for _ in range(repeats)]
            runs: dict[str, list[dict[str, Any]]] = {k: [] for k in cmds}
            for i in range(repeats + 1):  # the first round is not counted
                for label, cmd in cmds.items():
                    r = _child(cmd, cache)
                    if i:
                        runs[label].append(r)
                if log is not None and i:
                    print(f"start-up round {i}/{repeats}: " + ", ".join(
                        f"{k} {v[-1]['wall_s']:.2f} s" for k, v in runs.items()),
                        file=log, flush=True)
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    pde = runs["import pde"]
    out: dict[str, Any] = {
        "case": CASE, "repeats": repeats, "load_avg_at_start": load,
        "kernel_load": {k: statistics.median(r[k] for r in loads)
                        for k in ("import_s", "load_s", "load_cpu_s")},
        "kernel_loads_s": [r["load_s"] for r in loads],
        "commands": {k: {"wall_s": statistics.median(r["wall_s"] for r in v),
                         "cpu_s": statistics.median(r["cpu_s"] for r in v),
                         "walls": [r["wall_s"] for r in v]} for k, v in runs.items()},
        "ratios": {k: {"wall": statistics.median(a["wall_s"] / b["wall_s"]
                                                 for a, b in zip(v, pde, strict=True)),
                       "cpu": statistics.median(a["cpu_s"] / b["cpu_s"]
                                                for a, b in zip(v, pde, strict=True))}
                   for k, v in runs.items() if k != "import pde"},
        "figures_extra_s": statistics.median(
            a["wall_s"] - b["wall_s"]
            for a, b in zip(runs["run (figures)"], runs["run -q"], strict=True)),
    }
    if app:
        # the app's server, like the commands, with a bytecode cache (its first start
        # fills it)
        with tempfile.TemporaryDirectory(prefix="pdeflow-start-pycache-") as prefix, \
                _bytecode_cache(prefix):
            out["app"] = _app(max(3, repeats // 2))
    out["load_avg_at_end"] = os.getloadavg()
    return out


@contextlib.contextmanager
def _bytecode_cache(prefix: str) -> Iterator[None]:
    """Inside the block, the child processes (they inherit this environment) write and
    read their bytecode in ``prefix``."""
    names = ("PYTHONPYCACHEPREFIX", "PYTHONDONTWRITEBYTECODE")
    saved = {name: os.environ.get(name) for name in names}
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
    os.environ["PYTHONPYCACHEPREFIX"] = prefix
    try:
        yield
    finally:
        for name, value in saved.items():
            os.environ.pop(name, None)
            if value is not None:
                os.environ[name] = value


def _app(repeats: int) -> dict[str, Any] | None:
    """:func:`app_start.warm_start_to_first_picture`, or None without a browser."""
    import app_start

    from tests.browser import CHROMIUM

    try:
        import playwright  # noqa: F401
    except ImportError:
        return None
    if not Path(CHROMIUM).is_file():
        return None
    out = app_start.warm_start_to_first_picture(repeats)
    return {"median_s": out["median_s"][0], "walls_s": out["walls_s"][0],
            "load_avg_at_start": out["load_avg_at_start"]}


def render(data: dict[str, Any]) -> str:
    """The docs/performance.md section."""
    k, c, r = data["kernel_load"], data["commands"], data["ratios"]
    load = data["load_avg_at_start"][0]
    L = ["## Warm start\n",
         "Measured by `python benchmarks/run_benchmarks.py --only start` "
         "(`benchmarks/start_up.py`): the numba cache and a bytecode cache "
         "(`PYTHONPYCACHEPREFIX`) filled by one run first, then "
         f"{data['repeats']} fresh processes of each; load average {load:.1f} at the "
         "start (2 cores). *Kernel load*: `pdeflow.numerics.warmup.prepare` of the 5.1 "
         "case's kernels (both models) after `import pdeflow`. The commands ran in turn "
         "(A B C A B C ...); *ratio* is the median of the ratios run by run "
         "(wall, and CPU = user + system).\n",
         "| | wall [s] | CPU [s] | ratio to `import pde` (wall / CPU) |",
         "|---|---:|---:|---|",
         f"| kernel load of 5.1 (both models) | {k['load_s']:.3f} | {k['load_cpu_s']:.3f} "
         f"| |"]
    labels = {"run -q": "`pdeflow run <5.1> --summary s.json -q`",
              "run (figures)": "`pdeflow run <5.1> --outdir out` (summary and figures)",
              "import pde": "`python -c \"import pde\"`"}
    for key, label in labels.items():
        ratio = (f"{r[key]['wall']:.2f}x / {r[key]['cpu']:.2f}x" if key in r else "")
        L.append(f"| {label} | {c[key]['wall_s']:.2f} | {c[key]['cpu_s']:.2f} | {ratio} |")
    L.append("")
    L.append(f"The default figures cost {data['figures_extra_s']:.2f} s more than the "
             "quiet run (median of the differences run by run).")
    app = data.get("app")
    if app:
        L.append("")
        L.append(f"`pdeflow app` to the dam-break page's first picture, kernels cached "
                 f"(`benchmarks/app_start.py`, Chromium): {app['median_s']:.1f} s median "
                 f"({', '.join(f'{w:.1f}' for w in app['walls_s'])} s; load "
                 f"{app['load_avg_at_start']:.1f}).")
    return "\n".join(L) + "\n"


def target_rows(data: dict[str, Any]) -> list[str]:
    """The rows of the Targets table."""
    k, r = data["kernel_load"], data["ratios"]
    rows = [f"| cached kernel load of 5.1 (both models) <= 0.3 s | {k['load_s']:.3f} s "
            f"(see *Warm start*) | {_met(k['load_s'] <= 0.3)} |",
            f"| warm `pdeflow run <5.1> --summary s.json -q` <= 1.3x `python -c \"import "
            f"pde\"` | {r['run -q']['wall']:.2f}x wall, {r['run -q']['cpu']:.2f}x CPU | "
            f"{_met(r['run -q']['wall'] <= 1.3)} |",
            f"| with the default figures at most 1 s more | "
            f"{data['figures_extra_s']:.2f} s more | {_met(data['figures_extra_s'] <= 1.0)} |"]
    app = data.get("app")
    if app:
        rows.append(f"| `pdeflow app` warm start to the first picture <= 5 s | "
                    f"{app['median_s']:.1f} s (load {app['load_avg_at_start']:.1f}) | "
                    f"{_met(app['median_s'] <= 5.0)} |")
    return rows


def _met(ok: bool) -> str:
    return "**met**" if ok else "**missed**"
