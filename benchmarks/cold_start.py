"""Cold first run: ``pdeflow run cases/paper_5_1_dam_break.toml`` with an empty numba cache.

Measured by ``python benchmarks/run_benchmarks.py --only cold`` (stored under a label,
``--label``, in ``benchmarks/measurements/cold_start.json``, rendered into
docs/performance.md). Every run gets a fresh, empty ``NUMBA_CACHE_DIR`` and a fresh
working directory (the command writes ``results/<case>/`` there), so each one compiles
every kernel it needs, as the first run on a new machine does.

* **plain**: ``python -m pdeflow run CASE`` and the installed ``pdeflow`` script, as a
  user types them: wall time and CPU time (user + system) of the whole process.
* **split**: the same command through a small wrapper that books the time spent in
  top-level imports, in numba compilations (outermost ``numba:compile`` events; a
  compilation triggered by an import counts as compilation), in the figures (the
  functions of ``pdeflow.plotting``) and the rest (interpreter start, reading the case,
  the two runs, the summary), and lists the kernels compiled with their signatures.
* **warm**: the plain command once more with the cache the cold run left (what every
  later run costs).

Medians over ``repeats`` fresh runs. ``--tree`` measures another checkout (e.g. the
commit before a change) with this same harness.
"""

from __future__ import annotations

import json
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
CASE = "cases/paper_5_1_dam_break.toml"

_SPLIT = r"""
import builtins, functools, inspect, json, sys, time
# exclusive times: each moment is booked on the innermost of import, compilation,
# figures (an import inside a figure function counts as import), else on the rest
spent = {"imports": 0.0, "compile": 0.0, "figures": 0.0, "rest": 0.0}
stack = [["rest", time.perf_counter()]]

def _enter(category):
    now = time.perf_counter()
    spent[stack[-1][0]] += now - stack[-1][1]
    stack.append([category, now])

def _leave():
    now = time.perf_counter()
    category, t0 = stack.pop()
    spent[category] += now - t0
    stack[-1][1] = now

def _timed(category, f):
    @functools.wraps(f)
    def wrapper(*args, **kwargs):
        _enter(category)
        try:
            return f(*args, **kwargs)
        finally:
            _leave()
    return wrapper

builtins.__import__ = _timed("imports", builtins.__import__)
from numba.core import event

import os
kernels = []
class _Compiles(event.Listener):
    # also runs in the helper process that compiles part of the kernels (a fork):
    # every process appends what it compiled to the file PDEFLOW_COLD_KERNELS
    def on_start(self, ev):
        _enter("compile")
    def on_end(self, ev):
        _leave()
        d = ev.data["dispatcher"]
        name = f"{d.py_func.__module__}.{d.py_func.__qualname__}"
        if name.startswith("pdeflow"):
            with open(os.environ["PDEFLOW_COLD_KERNELS"], "a") as log:
                log.write(json.dumps([name, str(ev.data["args"]), os.getpid()]) + "\n")

event.register("numba:compile", _Compiles())
import pdeflow.plotting as _plotting
# compiling on two cores: this process's own compilations, then waiting for the helper
import pdeflow.numerics.warmup as _warmup
_warmup._compile = _timed("compile", _warmup._compile)
import pdeflow.numerics.compile_parallel as _parallel
_ready_each = _parallel.ready_each

def _booked_ready_each(kernels):
    # CPU time of each process's share (this process's first call, the helper's
    # only one): how evenly the two cores were loaded
    c0 = time.process_time()
    try:
        return _ready_each(kernels)
    finally:
        with open(os.environ["PDEFLOW_COLD_SHARES"], "a") as log:
            log.write(json.dumps([os.getpid(), time.process_time() - c0]) + "\n")

_parallel.ready_each = _warmup.ready_each = _booked_ready_each
try:
    import pdeflow.case_figures as _case_figures
    _figure_modules = [_plotting, _case_figures]
except ImportError:  # a checkout (--tree) from before pdeflow.case_figures
    _figure_modules = [_plotting]
for _module in _figure_modules:
    for _name, _f in list(vars(_module).items()):
        if inspect.isfunction(_f) and _f.__module__ == _module.__name__:
            setattr(_module, _name, _timed("figures", _f))
try:  # since session8 the figures are drawn by a forked worker: this process waits
    from pdeflow.figure_worker import RunFigures as _RunFigures
    _RunFigures.start = _timed("figures", _RunFigures.start)
    _RunFigures.draw = _timed("figures", _RunFigures.draw)
except ImportError:
    pass
import runpy
sys.argv = ["pdeflow", *sys.argv[1:]]
try:
    runpy.run_module("pdeflow", run_name="__main__", alter_sys=True)
except SystemExit as err:
    code = err.code
else:
    code = 0
spent[stack[-1][0]] += time.perf_counter() - stack[-1][1]
print("RESULT" + json.dumps({
    "imports_s": spent["imports"], "compile_s": spent["compile"],
    "figures_s": spent["figures"], "other_s": spent["rest"],
    "in_process_s": sum(spent.values()), "main_pid": os.getpid(), "code": code}),
    file=sys.stderr)
"""


def _child(cmd: list[str], tree: Path, cache: str | None) -> dict[str, Any]:
    """Run ``cmd`` in a fresh working directory with ``tree`` on PYTHONPATH and the
    numba cache in ``cache`` (a fresh empty one if None); wall and CPU time [s]."""
    own = cache is None
    cache = cache or tempfile.mkdtemp(prefix="pdeflow-cold-numba-")
    work = tempfile.mkdtemp(prefix="pdeflow-cold-cwd-")
    kernel_log = Path(work) / "kernels.jsonl"
    share_log = Path(work) / "shares.jsonl"
    env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": str(tree),
           "PDEFLOW_COLD_KERNELS": str(kernel_log), "PDEFLOW_COLD_SHARES": str(share_log)}
    env.pop("NUMBA_DISABLE_JIT", None)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True,
                          timeout=1800)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    compiled = ([json.loads(line) for line in kernel_log.read_text().splitlines()]
                if kernel_log.exists() else [])
    shares = ([json.loads(line) for line in share_log.read_text().splitlines()]
              if share_log.exists() else [])
    shutil.rmtree(work, ignore_errors=True)
    if own:
        shutil.rmtree(cache, ignore_errors=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stderr[-3000:]}")
    out: dict[str, Any] = {"wall_s": wall, "cpu_s": (after.ru_utime - before.ru_utime)
                           + (after.ru_stime - before.ru_stime)}
    for line in proc.stderr.splitlines():
        if line.startswith("RESULT"):
            out.update(json.loads(line[6:]))
    if "main_pid" in out:
        out["kernels"] = sorted({(name, sig) for name, sig, _ in compiled})
        out["helper_kernels"] = sorted({name for name, _, pid in compiled
                                        if pid != out["main_pid"]})
        own = [cpu for pid, cpu in shares if pid == out["main_pid"]]
        helper = [cpu for pid, cpu in shares if pid != out["main_pid"]]
        out["share_cpu_s"] = own[0] if own else None
        out["helper_share_cpu_s"] = helper[0] if helper else None
    return out


def _median(rows: list[dict[str, Any]], key: str) -> float | None:
    vals = [r[key] for r in rows if r.get(key) is not None]
    return statistics.median(vals) if vals else None


def measure(repeats: int = 3, tree: Path = ROOT, log: Any = None,
            commit_id: str | None = None) -> dict[str, Any]:
    """``repeats`` fresh cold runs of each command (interleaved), then warm ones;
    ``commit_id`` names the code measured (default: ``tree``'s git commit)."""
    load = os.getloadavg()
    case = str(Path(tree) / CASE)
    script = shutil.which("pdeflow")
    commands = {"python -m pdeflow run": [sys.executable, "-m", "pdeflow", "run", case],
                "split": [sys.executable, "-c", _SPLIT, "run", case]}
    if script:
        commands["pdeflow run (script)"] = [script, "run", case]
    runs: dict[str, list[dict[str, Any]]] = {k: [] for k in commands}
    warm: list[dict[str, Any]] = []
    for i in range(repeats):
        for label, cmd in commands.items():
            runs[label].append(_child(cmd, Path(tree), None))
            if log is not None:
                r = runs[label][-1]
                print(f"cold {i + 1}/{repeats} {label}: {r['wall_s']:.1f} s wall, "
                      f"{r['cpu_s']:.1f} s CPU", file=log, flush=True)
        cache = tempfile.mkdtemp(prefix="pdeflow-cold-numba-")
        try:
            _child(commands["python -m pdeflow run"], Path(tree), cache)
            warm.append(_child(commands["python -m pdeflow run"], Path(tree), cache))
        finally:
            shutil.rmtree(cache, ignore_errors=True)
    split = runs["split"]
    kernels = split[-1].get("kernels", [])
    out: dict[str, Any] = {
        "case": CASE, "repeats": repeats, "commit": commit_id or commit(Path(tree)),
        "load_avg_at_start": load,
        "commands": {k: {"wall_s": _median(v, "wall_s"), "cpu_s": _median(v, "cpu_s"),
                         "walls": [r["wall_s"] for r in v]}
                     for k, v in runs.items() if k != "split"},
        "split": {k: _median(split, k) for k in ("wall_s", "cpu_s", "imports_s",
                                                 "compile_s", "figures_s", "other_s",
                                                 "share_cpu_s", "helper_share_cpu_s")},
        "warm": {"wall_s": _median(warm, "wall_s"), "cpu_s": _median(warm, "cpu_s")},
        "kernels": sorted({k for k, _ in kernels}),
        "signatures": len(kernels),
        "helper_kernels": split[-1].get("helper_kernels", []),
        "other_tree": Path(tree).resolve() != ROOT,
    }
    return out


def latest(data: dict[str, Any]) -> tuple[str, dict[str, Any]]:
    """(label, measurement) of the last measurement of this checkout's code (not of
    another tree measured for comparison, ``--tree``)."""
    return [(k, d) for k, d in data.items() if not d.get("other_tree")][-1]


INTRO = """
`pdeflow run cases/paper_5_1_dam_break.toml` with an empty `NUMBA_CACHE_DIR` (a fresh one
per run, and a fresh working directory): the first run on a new machine, which compiles
every kernel it calls. Measured by `python benchmarks/run_benchmarks.py --only cold
--label LABEL` (`benchmarks/cold_start.py`); medians of fresh runs; *CPU* is user +
system time of the process and of its helper processes, less sensitive than wall time
to the other jobs on this shared machine. *imports*, *compile*, *figures* and *rest*
split the same command run through a wrapper that times top-level imports, numba's
compilations (since *session4* with the wait for the helper process that compiles part
of the kernels on the second core, `pdeflow.numerics.warmup.prepare`) and
`pdeflow.plotting` (since *session4* drawn on two cores; since *session8* drawn by a
forked worker, and *figures* is this process's wait for it; the rest: interpreter start,
reading the case, both runs, the summary). *warm*: the command again with the cache
the cold run left. *load*: 1-minute load average of the machine at the start (2 cores).
"""
CHANGES = {
    "before": "every kernel compiled for every scheme, some with several signatures",
    "after": "kernels built per scheme (closures over its choices), one signature each",
    "session3": "the same, after the stepping loop took its kernels as function "
                "pointers and the cache keys followed the code of every callee",
    "session4": "compiled on two cores (a forked helper process compiles the two-layer "
                "source stage), figures drawn on two cores without `tight_layout`",
    "session5": "helper kernels compiled without the Python and function-pointer entry "
                "points that every caller linked in and compiled again "
                "(`compiled.HelperKernel`), fewer garbage collections while compiling, "
                "none at exit (26 kernels: the two advection stages, closures, now have "
                "names of their own)",
    "session5-before": "the code of *session4* (7ae905d), measured again half an hour "
                       "after *session5* on the same day (the machine's speed drifts "
                       "within a day: its CPU time moves with it)",
    "session7": "kernels loaded without numba's registry refresh, fewer imports (issue "
                "27); nothing compiled less than in *session6*. Measured at load 3-5 (other "
                "developers' tests and sweeps on both cores): the wall times are not "
                "comparable with the rows above, the CPU time is (13.0 s against 13.6 s)",
    "session8-before": "the code of *session7* with this harness, which also books the "
                       "CPU time of the two processes' shares of the compile work",
    "session8": "the compile work split by an estimate that counts inlined helpers per "
                "call site and a fixed cost per kernel (`compile_parallel._work`): the two "
                "processes' shares of the CPU time closer (column *shares*); the figures drawn "
                "by a worker forked while the kernels compile (`pdeflow.figure_worker`); the "
                "two-layer source stage and fluctuations reworked for speed (issue 27)",
    "session9-before": "the code of *session8* (7b6bedb), measured in the same quarter of "
                       "an hour as *session9* (the machine was faster than in *session8*)",
    "session9": "the fork and this process take the kernels from a shared queue, heaviest "
                "first (`compile_parallel.SharedQueue`); the stepping loop calls the "
                "inlined advection stage from one site (issue 27)",
    "session9b": "the code of *session9* measured again five minutes later, then "
                 "*session9-before-b*: the code of *session8* again (the pairs show how "
                 "far the machine drifts in minutes)",
    "session9-before-b": "see *session9b*",
}
"""what the code of each measured label changed (rendered under the table)"""
MECHANISMS = """
### What each cold-start mechanism is for, and what it was measured to save

`pdeflow.numerics.warmup.prepare` is the one call that compiles a run's kernels before
the run; the mechanisms behind it, with the measurements and incidents that put them
there (test 5.1 cold, on this 2-core machine; numbers from the sessions in the table
above, not re-measured since the code moved behind `prepare`):

* **Helper process on the second core** (`compile_parallel`): test 5.1 compiled ~11 s
  in one process, one core busy (*session3*); with a forked helper 5.5 s (*session4*).
  Since *session9* the fork and this process take the entry kernels one at a time
  from a shared queue (`compile_parallel.SharedQueue`), heaviest first by an estimate
  of each one's compile work: the bytecode of its call tree, an inlined helper counted
  once per call site (numba types it again there), plus `KERNEL_OVERHEAD` per kernel
  compiled on its own. Whichever process is free takes the next kernel, so the
  estimate only orders them. Before, the estimate split the kernels in two once, the
  helper's share nearest `HELPER_SHARE` = 0.5 (*session8*; plain bytecode and 0.42
  before it, which gave this process 2.5 times the helper's CPU time,
  *session8-before*, column *shares*); it undercounts the two-layer source stage's
  tree, and the shares stayed uneven (*session9-before*, *-b*: 6.2 / 4.4 and 6.6 /
  5.3 s; with the queue, *session9*, *9b*: 4.6 / 4.8 and 4.9 / 5.4 s). Where no fork
  is safe (threads: a server, Jupyter, Dask) the helper is a new
  interpreter, which first spends ~1 s importing pdeflow and takes the static split.
* **One call site of the advection stage in the stepping loop**: the first attempt
  of a step, IFCP's redo with HLL and the positivity retries call the inlined stage
  from one place, where they had two (three with IFCP; numba types and lowers an
  inlined function at every site). With the queue: compile 4.7 and 5.2 s against 5.9
  and 6.4 s for the code before (column *compile*, *session9* and *9b* against
  *session9-before* and *-b*, measured in the same quarter hour).
* **Helpers without entry points** (`numba_hooks.HelperKernel`): the two-layer source stage
  is a tree of 20 helper kernels; with the Python and function-pointer entry points
  every caller linked in and compiled again at every level (*session5*, together with
  the fewer collections below: 4.2 s of compilation against 5.5 s in *session4*).
* **Fewer garbage collections while compiling** (`compile_parallel.fewer_collections`):
  0.7-0.8 s of collecting in 8.5-10.4 s of compiling in one process, 0.2 s with it;
  **none at exit** (`pdeflow.__main__`, `gc.freeze()`): 0.4-0.8 s of a first run.
* **Function pointers looked up once** (`numba_hooks.FunctionPointer`): passed a
  dispatcher, numba looks up its address on every call of the stepping loop, about
  0.3 ms; passed numba's own wrapper it builds the function type again, 10-30 us.
* **Closures named after their constants** (`compiled.specialise`, numba issue #10486):
  a rate test once failed with a cache that many test processes had filled, one
  closure's code loaded for another's.
* **Cache keys following every callee's code** (`numba_hooks._CodeKeyedCache`): numba's own
  key, the source file's time stamp, once loaded a kernel with an old callee compiled
  in and gave a wrong test 5.1 result.
* **The public path**: on a numba newer than `compiled.NEWEST_TESTED_NUMBA`, or with
  `PDEFLOW_NUMBA_FALLBACK=1`, `numba_hooks` is not imported and none of its mechanisms
  apply: kernels are plain `numba.njit(cache=True)` with entry points, no helper
  process compiles, kernels are passed to the stepping loop as dispatchers, and
  closures over kernels (the advection stages, the stepping loop, the models' source
  stages, built per basal law) are compiled in every process, since numba's own cache
  key for them changes from one process to the next.
  The numbers computed are the same (`tests/test_numba_fallback.py`).
* **The app** loads its kernels in a background thread (`app/kernels.py`) and says so:
  its first picture came 13 s after a start with an empty cache (docs/teaching.md).
"""
"""why each mechanism is there (rendered under the kernel lists)"""
COLUMNS = ("code", "runs", "load", "`python -m pdeflow run` wall [s]", "CPU [s]",
           "`pdeflow` script wall [s]", "imports [s]", "compile [s]", "figures [s]",
           "rest [s]", "shares: this process / helper, CPU [s]", "warm wall [s]",
           "kernels compiled (signatures)")


def render(data: dict[str, Any]) -> str:
    """The cold-start section of docs/performance.md from ``{label: measure(...)}``."""
    L = ["## Cold first run\n", " ".join(INTRO.split()) + "\n",
         "| " + " | ".join(COLUMNS) + " |", "|---|" + "---:|" * (len(COLUMNS) - 2) + "---|"]

    def f(v: float | None) -> str:
        return "-" if v is None else f"{v:.1f}"

    def shares(s: dict[str, Any]) -> str:
        if s.get("share_cpu_s") is None:
            return "-"
        return f"{f(s['share_cpu_s'])} / {f(s.get('helper_share_cpu_s'))}"

    for label, d in data.items():
        c = d["commands"]
        plain = c.get("python -m pdeflow run", {})
        script = c.get("pdeflow run (script)", {})
        s = d["split"]
        load = d.get("load_avg_at_start")
        L.append(f"| {label} ({d.get('commit', '?')}) | {d['repeats']} | "
                 f"{f(load[0]) if load else '?'} | {f(plain.get('wall_s'))} | "
                 f"{f(plain.get('cpu_s'))} | {f(script.get('wall_s'))} | "
                 f"{f(s['imports_s'])} | {f(s['compile_s'])} | {f(s.get('figures_s'))} | "
                 f"{f(s['other_s'])} | "
                 f"{shares(s)} | "
                 f"{f(d['warm']['wall_s'])} | {len(d['kernels'])} ({d['signatures']}) |")
    L.append("")
    L += [f"* *{label}*: {CHANGES[label]}." for label in data if label in CHANGES]
    label, d = latest(data)
    s = d["split"]
    rest = s["imports_s"] + s.get("figures_s", 0.0) + s["other_s"]
    L.append(f"\nWithout any compilation the command would still take {rest:.1f} s "
             f"(*{label}*: imports, figures and the rest), the floor of a cold run; "
             f"compiling took {s['compile_s']:.1f} s of {s['wall_s']:.1f} s.")
    def names(kernels: list[str]) -> str:
        # a closure's name ends in a digest of its constants (compiled.specialise)
        short = (re.sub(r"_[0-9a-f]{12}$", "", k.replace("pdeflow.numerics.", "")
                        .replace(".<locals>", "")) for k in kernels)
        return ", ".join(f"`{k}`" for k in dict.fromkeys(short))

    for label, d in data.items():
        L.append(f"\nKernels compiled by the cold run, *{label}*: {names(d['kernels'])}.")
        if d.get("helper_kernels"):
            L.append(f"Of these, the helper process compiled {names(d['helper_kernels'])}.")
    L.append(MECHANISMS)
    return "\n".join(L) + "\n"


def commit(tree: Path) -> str:
    """Short commit id of ``tree`` (with ``+`` if it has uncommitted changes)."""
    try:
        rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=tree,
                             capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "pdeflow"], cwd=tree,
                               capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "?"
    return rev + ("+" if dirty else "")
