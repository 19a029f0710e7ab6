"""Compiled kernels: one signature each, only what a scheme calls, cached on disk."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from numba import config

from pdeflow.models.single_layer.kernels import KERNELS as SINGLE_LAYER
from pdeflow.models.two_layer.kernels import KERNELS as TWO_LAYER
from pdeflow.numerics import compile_parallel as parallel
from pdeflow.numerics import compiled, warmup
from pdeflow.numerics import layout as L
from pdeflow.numerics.splitting import scheme_stepper

#: the schemes of hll/first-order, Lie splitting, planar, for each model
PLANAR_HLL_SINGLE = (SINGLE_LAYER, L.FLUX_HLL, 1, L.LIMITER_MINMOD, False, L.GEOMETRY_PLANAR)
PLANAR_HLL_TWO = (TWO_LAYER, L.FLUX_HLL, 1, L.LIMITER_MINMOD, False, L.GEOMETRY_PLANAR)

ROOT = Path(__file__).parents[1]

pytestmark = pytest.mark.skipif(config.DISABLE_JIT, reason="nothing is compiled")

#: for what numba's private classes do (pdeflow.numerics.numba_hooks)
hooks_only = pytest.mark.skipif(compiled.HOOKS is None, reason="numba's private hooks off "
                                "(PDEFLOW_NUMBA_FALLBACK=1 or an untested numba)")

# the shipped paper cases through the command line, in a fresh process (so that no other
# test's calls count), then every kernel of pdeflow.numerics and its signatures
PAPER_RUNS = r"""
import json, sys, tempfile
from pdeflow.cli import main
from pdeflow.numerics import compiled
out = tempfile.mkdtemp()
for argv in (["run", "cases/paper_5_1_dam_break.toml", "--outdir", out + "/51"],
             ["run", "cases/paper_5_2_single_collapse.toml", "--outdir", out + "/52"],
             ["sweep", "cases/paper_5_2_two_layer_law.toml", "--summary", out + "/s.json"]):
    assert main([*argv, "-q"]) == 0, argv
kernels = {f"{k.py_func.__module__}.{k.py_func.__qualname__}#{i}": [str(s) for s in k.signatures]
           for i, k in enumerate(compiled.kernels())}
print("KERNELS" + json.dumps(kernels))
"""


def test_the_paper_cases_compile_every_kernel_once():
    """After `pdeflow run` of 5.1 and 5.2 and `pdeflow sweep` of the 5.2 law, every
    kernel has at most one signature (int, float and array-layout variants of the same
    call would each compile one), and the kernels of other fluxes, reconstructions and
    splittings were not compiled."""
    proc = subprocess.run([sys.executable, "-c", PAPER_RUNS], cwd=ROOT, capture_output=True,
                          text=True, timeout=1800,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert proc.returncode == 0, proc.stderr[-3000:]
    line = [x for x in proc.stdout.splitlines() if x.startswith("KERNELS")][0]
    kernels = json.loads(line[len("KERNELS"):])
    several = {k: v for k, v in kernels.items() if len(v) > 1}
    assert not several, several
    used = {k.split("#")[0] for k, v in kernels.items() if v}
    # a closure's name ends in a digest of its constants (compiled.specialise)
    assert any(k.startswith("pdeflow.numerics.splitting.stepping_function.<locals>"
                            ".advance_") for k in used), sorted(used)
    assert "pdeflow.models.two_layer.sources.sources_two_layer" in used
    for name in ("reconstruct_muscl", "predictor", "rusanov", "ifcp", "roe",
                 "internal_speed", "source_rate", "source_stage_"):
        assert not any(name in k for k in used), (name, sorted(used))
    loops = [k for k in kernels if k.startswith("pdeflow.numerics.splitting.stepping")]
    assert sum(bool(kernels[k]) for k in loops) == 1  # first order, Lie, no IFCP fallback


def test_kernels_are_compiled_for_their_declared_signature_only():
    """Called with other but compatible types (a C-contiguous copy instead of py-pde's
    strided state, plain Python ints), a ready kernel converts them instead of
    compiling a second signature."""
    import numpy as np

    import pdeflow
    from pdeflow.models.single_layer.sources import sources_single

    stepper = scheme_stepper(*PLANAR_HLL_SINGLE).ready()
    eq = pdeflow.SingleLayerGranular()
    P = eq.parameter_array()
    q = np.array([[1.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])
    diag = eq.new_diagnostics(4)
    stepper(q, 0, 1e-3, 0.25, np.zeros((L.N_METRIC, 5)), 0, 1, P, 0.3, diag,
            np.empty_like(q), np.empty_like(q), np.empty((3, 2, 4)), 10, False)
    sources_single(q, 0.0, 0.0, P, diag, 0, 3)
    for kernel in (*stepper.kernels, sources_single):
        assert len(kernel.signatures) == 1, kernel


@hooks_only
def test_a_closure_is_cached_under_its_constants(tmp_path):
    """Two specialised kernels of the same code but other constants are two cache
    entries; a fresh process loads both from the disk cache instead of compiling."""
    script = r"""
import json
from pdeflow.numerics import layout as L
from pdeflow.numerics.advection import advection_kernel
from pdeflow.models.single_layer.kernels import KERNELS as SINGLE_LAYER
from pdeflow.numerics.compiled import ready
out = []
for flux in (L.FLUX_HLL, L.FLUX_RUSANOV):
    k = ready(advection_kernel(SINGLE_LAYER, flux, 1, L.LIMITER_MINMOD, L.GEOMETRY_PLANAR))
    out.append([sum(k.stats.cache_hits.values()), sum(k.stats.cache_misses.values())])
print("STATS" + json.dumps(out))
"""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path), "PYTHONPATH": str(ROOT)}
    stats = []
    for _ in range(2):
        proc = subprocess.run([sys.executable, "-c", script], env=env, cwd=ROOT,
                              capture_output=True, text=True, timeout=900)
        assert proc.returncode == 0, proc.stderr[-3000:]
        line = [x for x in proc.stdout.splitlines() if x.startswith("STATS")][0]
        stats.append(json.loads(line[len("STATS"):]))
    assert stats[0] == [[0, 1], [0, 1]]  # compiled
    assert stats[1] == [[1, 0], [1, 0]]  # loaded, each under its own key



# the single-layer advection stage of one flux (a closure over the flux's constants that
# calls a closure for the fluctuations) on a dam-break state: rates and cache hits
ADVECT_ONCE = r"""
import json, sys
import numpy as np
from pdeflow.numerics import layout as L
from pdeflow.numerics.advection import advection_kernel
from pdeflow.models.single_layer.kernels import KERNELS as SINGLE_LAYER
from pdeflow.numerics.compiled import ready
q = np.zeros((2, 8))
q[0, :4] = 1.0
q[1, 2] = 0.5
out = []
for flux in sys.argv[1:]:
    k = ready(advection_kernel(SINGLE_LAYER, getattr(L, flux), 1, L.LIMITER_MINMOD,
                               L.GEOMETRY_PLANAR))
    rate = np.zeros_like(q)
    k(q, rate, np.zeros((3, 2, 8)), np.zeros((1, L.N_DIAG)), 0.1, np.zeros((L.N_METRIC, 9)),
      0, 0, 9.81, 0.0, 1e-6, 0, 7)
    out.append([rate.tolist(), sum(k.stats.cache_hits.values())])
print("STATS" + json.dumps(out))
"""


def test_closures_compiled_in_two_processes_load_together(tmp_path):
    """Two closures of one factory, each compiled in a fresh process (numba numbers
    compiled functions with a per-process counter, so both fluctuation closures get the
    same number), then both loaded from the disk cache in a third, each give the rates
    they gave where they were compiled (numba issue #10486: code of two functions with
    one name can be mixed up by the process that loads both). Without the private
    hooks the advection closures are compiled again in every process (numba's own cache
    key would change): the same rates, no cache hits."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path), "PYTHONPATH": str(ROOT)}
    runs = []
    for fluxes in (["FLUX_HLL"], ["FLUX_RUSANOV"], ["FLUX_HLL", "FLUX_RUSANOV"]):
        proc = subprocess.run([sys.executable, "-c", ADVECT_ONCE, *fluxes], env=env,
                              cwd=ROOT, capture_output=True, text=True, timeout=900)
        assert proc.returncode == 0, proc.stderr[-3000:]
        line = [x for x in proc.stdout.splitlines() if x.startswith("STATS")][0]
        runs.append(json.loads(line[len("STATS"):]))
    (hll, hll_hits), (rusanov, rusanov_hits) = runs[0][0], runs[1][0]
    assert hll != rusanov and hll_hits == rusanov_hits == 0  # compiled, each in its own
    hits = 0 if compiled.HOOKS is None else 1
    assert runs[2] == [[hll, hits], [rusanov, hits]]  # loaded together, each still itself


# load a kernel from the disk cache, run it, then compile a new kernel that calls it
LOAD_THEN_COMPILE = r"""
import json, sys
import numba
import numba.core.base
calls = []
refresh = numba.core.base.BaseContext.refresh
numba.core.base.BaseContext.refresh = lambda self: calls.append(1) or refresh(self)
from pdeflow.numerics import layout as L
from pdeflow.numerics.advection import advection_kernel
from pdeflow.models.single_layer.kernels import KERNELS as SINGLE_LAYER
from pdeflow.numerics.compiled import ready
k = ready(advection_kernel(SINGLE_LAYER, L.FLUX_HLL, 1, L.LIMITER_MINMOD,
                           L.GEOMETRY_PLANAR))
loaded = sum(k.stats.cache_hits.values())
refreshed_by_load = len(calls)
from pdeflow.numerics.state import velocity
twice = numba.njit(lambda h, hu: 2.0 * velocity(h, hu, 1e-6))
print("STATS" + json.dumps([loaded, refreshed_by_load, twice(2.0, 3.0), len(calls) > 0]))
"""


@hooks_only
def test_a_kernel_loaded_without_numbas_refresh_runs_and_compiling_still_works(tmp_path):
    """Loading from the disk cache skips numba's refresh of its typing and lowering
    registries (numba_hooks._CodeKeyedCache.load_overload); a kernel compiled afterwards in
    the same process, calling a pdeflow kernel, is typed and runs (numba's compiler
    refreshes the context itself)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path), "PYTHONPATH": str(ROOT)}
    for _ in range(2):
        proc = subprocess.run([sys.executable, "-c", LOAD_THEN_COMPILE], env=env,
                              cwd=ROOT, capture_output=True, text=True, timeout=900)
        assert proc.returncode == 0, proc.stderr[-3000:]
    line = [x for x in proc.stdout.splitlines() if x.startswith("STATS")][0]
    assert json.loads(line[len("STATS"):]) == [1, 0, 3.0, True]


@hooks_only
def test_cache_key_follows_the_code_of_every_called_kernel(monkeypatch):
    """A kernel's disk-cache key changes when a kernel it calls, in another file and
    two calls down, changes (numba's own key, the file's time stamp, does not: a stale
    cache once gave a wrong test 5.1 result)."""
    from pdeflow.models.two_layer import exchange
    from pdeflow.models.two_layer.sources import sources_two_layer
    from pdeflow.numerics.implicit import coulomb_single

    def key() -> tuple:
        return sources_two_layer._cache._index_key(
            compiled._SIGNATURES[sources_two_layer], sources_two_layer.targetctx.codegen())

    before = key()
    assert key() == before  # the same in every call (and process: test above)
    # sources_two_layer -> friction.implicit_friction -> exchange.friction_two_layer
    monkeypatch.setattr(exchange.friction_two_layer.py_func, "__code__",
                        coulomb_single.py_func.__code__)
    assert key() != before


@hooks_only
def test_the_cache_key_changes_with_the_compile_options():
    """Two kernels of the same code compiled with other options (inlined into callers,
    without entry points) get other machine code, so other cache keys: a changed
    ``inline=`` once loaded the code compiled under the old option."""

    def f(x):
        return 2.0 * x

    plain = compiled._jit(f)
    helper = compiled._jit(f, helper=True)
    inlined = compiled._jit(f, helper=True, inline="always")
    sig = (compiled.f8,)
    keys = {k._cache._index_key(sig, k.targetctx.codegen()) for k in (plain, helper, inlined)}
    assert len(keys) == 3
    again = compiled._jit(f, helper=True)
    assert again._cache._index_key(sig, again.targetctx.codegen()) in keys


@hooks_only
def test_the_cache_key_changes_with_the_constants_a_kernel_reads(monkeypatch):
    """numba compiles module constants in (``L.N_DIAG``, the per-cell F_extra's offset in
    the diagnostics): a kernel whose code is unchanged but whose layout constant moved
    must be recompiled, not loaded with the old offset (a stale source stage once wrote
    F_extra over the retry counter). The key also changes with a constant of the
    kernel's own module, and not with anything else."""
    from pdeflow.models.two_layer import sources as source_stage
    from pdeflow.models.two_layer.sources import sources_two_layer

    def key() -> tuple:
        return sources_two_layer._cache._index_key(
            compiled._SIGNATURES[sources_two_layer], sources_two_layer.targetctx.codegen())

    before = key()
    monkeypatch.setattr(L, "N_DIAG", L.N_DIAG + 1)
    assert key() != before
    monkeypatch.setattr(L, "N_DIAG", L.N_DIAG - 1)
    assert key() == before
    monkeypatch.setattr(source_stage, "UNREAD_CONSTANT", 3, raising=False)
    assert key() == before


# three independent kernels of different sizes in a module of their own (a helper
# process that compiled one that another calls would not be seen: the caller compiles
# its callees itself)
TOY_KERNELS = """
from pdeflow.numerics.compiled import f8, kernel

@kernel(f8)
def small(x):
    return x + 1.0

@kernel(f8)
def medium(x):
    s = 0.0
    for i in range(10):
        s += x * i
    return s

@kernel(f8)
def large(x):
    s = 0.0
    for i in range(10):
        if x > i:
            s += x * i - s / (i + 1.0)
        else:
            s -= x / (i + 1.0)
    return s * s + x
"""

PREPARE = r"""
import json, sys, threading
import toy_kernels as toy
from pdeflow.numerics import compile_parallel as parallel
from pdeflow.numerics import warmup
if sys.argv[1] == "threads":  # a server's process: the helper is a new interpreter
    stop = threading.Event()
    threading.Thread(target=stop.wait, daemon=True).start()
ks = [toy.small, toy.medium, toy.large]
helper = [k.py_func.__name__ for k in parallel.split_work(ks)]
warmup.prepare(ks, meanwhile=lambda: print("MEANWHILE", flush=True))
print("STATS" + json.dumps({"helper": helper, "results": [k(2.0) for k in ks],
    "hits": {k.py_func.__name__: sum(k.stats.cache_hits.values()) for k in ks},
    "misses": {k.py_func.__name__: sum(k.stats.cache_misses.values()) for k in ks}}))
"""


@hooks_only
@pytest.mark.parametrize("threads", ["none", "threads"])
def test_prepare_compiles_part_of_the_kernels_in_a_helper_process(tmp_path, threads):
    """On two cores and a cold cache, a helper process compiles some of the kernels
    (this process then loads them from the disk cache: cache hits) and this process
    compiles the others (cache misses), each kernel once, and does what it is given to
    do meanwhile once (the helper does not); the kernels give the right results. A
    fork takes kernels from the queue it shares with this process (who takes which
    depends on who is free first); a new interpreter (another thread running) takes
    its share of the static split."""
    if parallel._cores() < 2:
        pytest.skip("one core")
    (tmp_path / "toy_kernels.py").write_text(TOY_KERNELS)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
           "PYTHONPATH": os.pathsep.join([str(ROOT), str(tmp_path)])}
    proc = subprocess.run([sys.executable, "-c", PREPARE, threads], env=env,
                          cwd=ROOT, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    line = [x for x in proc.stdout.splitlines() if x.startswith("STATS")][0]
    out = json.loads(line[len("STATS"):])
    assert proc.stdout.count("MEANWHILE") == 1, proc.stdout
    names = ("small", "medium", "large")
    for name in names:
        assert out["hits"][name] + out["misses"][name] == 1, (name, out)
    by_helper = [name for name in names if out["hits"][name]]
    assert 0 < len(by_helper) < 3, out
    if threads == "threads":
        assert by_helper == out["helper"], out
    x = 2.0
    medium = sum(x * i for i in range(10))
    assert out["results"][:2] == [x + 1.0, medium]


def test_the_shared_queue_gives_each_kernel_once_and_survives_a_dead_holder(monkeypatch):
    """The kernels of a shared queue go one each to the processes that iterate over it;
    a process that died holding the queue's lock (killed mid-take) does not hang the
    other: it stops taking after QUEUE_LOCK_TIMEOUT, leaving the rest to prepare's final
    pass."""
    if not parallel.can_fork():
        pytest.skip("no fork here")
    import time

    items = list(range(40))
    queue = parallel.SharedQueue(items)
    ctx = parallel.fork_context()
    theirs = ctx.Array("i", [-1] * len(items))

    def take() -> None:
        for n, item in enumerate(queue):
            theirs[n] = item
            time.sleep(0.005)

    child = ctx.Process(target=take)
    child.start()
    mine = []
    for item in queue:
        mine.append(item)
        time.sleep(0.005)
    child.join()
    taken = [x for x in theirs if x >= 0]
    assert sorted(mine + taken) == items and mine and taken
    queue = parallel.SharedQueue(items)
    it = iter(queue)
    first = [next(it), next(it)]
    holder = parallel.fork_context().Process(
        target=lambda: (queue.taken.get_lock().acquire(), os._exit(0)))
    holder.start()
    holder.join()
    monkeypatch.setattr(parallel, "QUEUE_LOCK_TIMEOUT", 0.2)
    assert first == [0, 1] and list(it) == []


def test_split_work_keeps_this_process_busy_and_no_fork_beside_threads():
    """The helper gets some kernels, never all, the split nearest HELPER_SHARE of the
    work (for test 5.1, both models: within 0.02 of it); with a second thread running
    nothing is forked."""
    import itertools
    import threading

    kernels = list(dict.fromkeys(
        scheme_stepper(*PLANAR_HLL_TWO).kernels
        + scheme_stepper(*PLANAR_HLL_SINGLE).kernels))
    helper = parallel.split_work(kernels)
    assert 0 < len(helper) < len(kernels)
    assert abs(parallel._work(helper) / parallel._work(kernels)
               - parallel.HELPER_SHARE) < 0.02
    total = parallel._work(kernels)
    best = min(abs(parallel._work(side) / total - parallel.HELPER_SHARE)
               for n in range(1, len(kernels))
               for side in itertools.combinations(kernels, n))
    assert abs(parallel._work(helper) / total - parallel.HELPER_SHARE) == best
    assert parallel.split_work(kernels[:1]) == []
    stop = threading.Event()
    thread = threading.Thread(target=stop.wait)
    thread.start()
    try:
        assert not parallel.can_fork()
    finally:
        stop.set()
        thread.join()


WORK_KERNELS = """
from pdeflow.numerics.compiled import cached, f8, kernel


@cached(inline="always")
def twice(x):
    return 2.0 * x


@cached
def half(x):
    return 0.5 * x


@kernel(f8)
def caller(x):
    return twice(x) + twice(x + 1.0) + twice(x + 2.0) + half(x) + half(x + 1.0)
"""


def test_compile_work_counts_an_inlined_callee_per_call_site(tmp_path, monkeypatch):
    """numba types an inlined callee again at each call site and compiles any other
    callee once, on its own: the work of ``caller`` is its bytecode, three times that of
    ``twice`` and once that of ``half``, plus the overhead of the two kernels compiled on
    their own."""
    (tmp_path / "work_kernels.py").write_text(WORK_KERNELS)
    monkeypatch.syspath_prepend(str(tmp_path))
    import work_kernels as w

    def size(k):
        return len(k.py_func.__code__.co_code)

    assert parallel._own_work(w.caller) == size(w.caller) + 3 * size(w.twice)
    assert parallel._work([w.caller]) == (size(w.caller) + 3 * size(w.twice) + size(w.half)
                                          + 2 * parallel.KERNEL_OVERHEAD)


def test_meanwhile_is_called_once_whatever_there_is_to_compile():
    """The caller's work for the wait runs once, also with nothing to compile or wait
    for (kernels already loaded, no kernels)."""
    calls: list[int] = []
    assert warmup.prepare([], meanwhile=lambda: calls.append(1)) == 0.0
    assert warmup.prepare(None, meanwhile=lambda: calls.append(2)) == 0.0
    stepper = scheme_stepper(*PLANAR_HLL_SINGLE)
    warmup.prepare([[stepper], stepper.kernels], meanwhile=lambda: calls.append(3))
    assert warmup.prepare(stepper, meanwhile=lambda: calls.append(4)) == 0.0
    assert calls == [1, 2, 3, 4]


def test_prepare_binds_a_stepper_and_reports_what_is_left():
    """After prepare a stepper's kernels are compiled (status READY) and bound as
    function pointers (without the private hooks: the kernels themselves); a kernel
    nobody compiled yet is COLD or CACHED, never READY."""
    from pdeflow.numerics.compiled import f8, kernel

    stepper = scheme_stepper(SINGLE_LAYER, L.FLUX_RUSANOV, 1, L.LIMITER_MINMOD, False,
                             L.GEOMETRY_PLANAR)
    warmup.prepare([stepper])
    assert warmup.status(stepper) == warmup.READY and stepper.arguments is not None
    if compiled.HOOKS is None:
        assert stepper.arguments[:2] == (stepper.advect, stepper.sources)
    else:
        assert all(isinstance(k, compiled.HOOKS.FunctionPointer)
                   for k in stepper.arguments[:2])

    @kernel(f8)
    def fresh(x):  # pragma: no cover - compiled
        return 2.0 * x

    assert warmup.status([fresh]) in (warmup.COLD, warmup.CACHED)
    assert warmup.prepare(fresh) >= 0.0 and warmup.status(fresh) == warmup.READY
    assert fresh(1.5) == 3.0 and len(fresh.signatures) == 1


def test_prepare_refuses_what_is_no_kernel_or_stepper():
    from pdeflow.cases import load_case

    case = load_case(ROOT / "cases" / "ritter_dam_break.toml")
    for wrong in ([case], "two_layer"):
        with pytest.raises(TypeError, match="case_steppers"):
            warmup.prepare(wrong)


def test_the_rest_of_the_package_warms_kernels_up_through_prepare_only():
    """Outside pdeflow/numerics nothing calls the compile machinery behind
    warmup.prepare: of compile_parallel only the fork helpers the figures use, of
    compiled only ready (the py-pde solvers' rates and hooks compile on demand) and,
    in a model's package, the decorators and types that declare its kernels."""
    import ast

    declare = {"cached", "kernel", "specialise", "types", "f8", "i8", "STATE", "PARAMS",
               "VECTOR", "FIELDS"}
    for path in sorted((ROOT / "pdeflow").rglob("*.py")):
        if path.parent.name == "numerics":
            continue
        in_model = path.parent.parent.name == "models"
        allowed = {"pdeflow.numerics.compile_parallel": {"can_fork", "fork_context"},
                   "pdeflow.numerics.compiled": {"ready"} | (declare if in_model else set())}
        pkg = path.relative_to(ROOT).with_suffix("").parts[:-1]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module:
                base = list(pkg[:len(pkg) - node.level + 1]) if node.level else []
                name = ".".join([*base, node.module])
                names = {a.name for a in node.names}
                assert names <= allowed.get(name, names), (path.name, name, names)
                if name == "pdeflow.numerics":  # no way round the names above
                    assert not names & {"compiled", "compile_parallel"}, path.name


def test_garbage_collector_walks_less_while_compiling_and_is_restored():
    """While kernels compile, the objects that existed before are frozen and the first
    collection threshold raised; afterwards (also after a failure) both are as before."""
    import gc

    before = gc.get_threshold(), gc.get_freeze_count()
    with parallel.fewer_collections():
        assert gc.get_threshold() == parallel.GC_THRESHOLD
        assert gc.get_freeze_count() > before[1]
    assert (gc.get_threshold(), gc.get_freeze_count()) == before
    with pytest.raises(KeyboardInterrupt), parallel.fewer_collections():
        raise KeyboardInterrupt
    assert (gc.get_threshold(), gc.get_freeze_count()) == before


@hooks_only
def test_a_helper_kernel_called_from_python_runs_its_twin():
    """A helper (compiled without the entry point Python needs: calling it would crash
    the process) answers a call from Python through a twin that has it, under a cache
    key of its own."""
    from pdeflow.numerics.state import velocity

    assert isinstance(velocity, compiled.HOOKS.HelperKernel)
    assert velocity.targetoptions["no_cpython_wrapper"]
    assert velocity(2.0, 3.0, 1e-6) == 1.5 and velocity(1e-9, 3.0, 1e-6) == 0.0
    twin = velocity._python_twin
    assert not isinstance(twin, compiled.HOOKS.HelperKernel)
    sig = compiled.f8(compiled.f8, compiled.f8, compiled.f8).args
    codegen = velocity.targetctx.codegen()
    assert twin._cache._index_key(sig, codegen) != velocity._cache._index_key(sig, codegen)
