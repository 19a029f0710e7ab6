"""Compiling a run's kernels on two cores: a helper process fills numba's disk cache.

Called by :func:`pdeflow.numerics.warmup.prepare` only. :func:`start_helper` shares the
kernels to compile between a helper process, which compiles its share into numba's disk
cache (the kernels' cache keys are their code, the same in every process,
:mod:`pdeflow.numerics.compiled`), and the calling process, which compiles the rest,
then loads the helper's kernels from the cache. The helper is

* a **fork** of this process where that is safe (:func:`can_fork`: Linux, no other
  thread): it starts at once and takes any kernel, closures included. The two
  processes take the kernels one at a time from a :class:`SharedQueue`, heaviest first
  by :func:`_work`, so that the estimate only orders them: whichever process is free
  takes the next (a static split by the estimate left one core idle for a second
  while the other compiled what the estimate had undercounted);
* else a **new interpreter** (a server, a Jupyter kernel, a Dask worker: processes with
  threads), which has to import pdeflow first and takes only the kernels it can find by
  name (module-level ones, such as the source stages): a static split
  (:func:`split_work`).

Nothing depends on the helper: if it fails, the calling process compiles its kernels
itself. Measurements of what this saves: docs/performance.md, "Cold first run".
"""

from __future__ import annotations

import contextlib
import dis
import functools
import gc
import multiprocessing
import os
import subprocess
import sys
import threading
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any

from .compiled import in_disk_cache, named_kernels, ready

HELPER_SHARE = 0.5
"""The helper process's share of the compile work (:func:`_work`) that
:func:`split_work` aims at: half. (The estimate is rough: where its split leaves this
process the smaller share, what the caller gives it to do meanwhile fills the wait.)"""


KERNEL_OVERHEAD = 230
"""What compiling one more kernel costs beyond its bytecode (numba's pipeline, an LLVM
module of its own, machine code), in bytes of bytecode that cost as much: fitted to the
compile times of the five entry kernels of test 5.1, each compiled alone (a tree of
many small kernels, the two-layer source stage, costs more per byte than the stepping
loop, whose helpers are inlined)."""


QUEUE_LOCK_TIMEOUT = 10.0
"""Seconds a process waits for the lock of the :class:`SharedQueue` (held for a few
microseconds per kernel) before it takes the other process for dead, stops taking
kernels and leaves what is left to the final pass of
:func:`pdeflow.numerics.warmup.prepare`, which compiles it here."""


GC_THRESHOLD = (10000, 10, 10)
"""Python's garbage-collector thresholds while kernels compile (its default: 700, 10,
10): a collection of the youngest objects every 10000 new ones instead of every 700."""


def start_helper(todo: Sequence[Any]) -> tuple[Any, Iterable[Any]]:
    """(the helper process, the kernels of ``todo`` this process compiles meanwhile),
    or (None, ``todo``) where there is no second core, fewer than two kernels to
    compile (not in the disk cache) or nothing to give the helper. A forked helper and
    this process share a :class:`SharedQueue` of the kernels to compile; a new
    interpreter gets its share of a static split. The helper is waited for with
    ``wait()`` and stopped with ``terminate()``; then every kernel of ``todo`` is still
    to be readied here (those the helper compiled load from the disk cache)."""
    cold = [k for k in todo if not in_disk_cache(k)]
    if _cores() < 2 or len(cold) < 2:
        return None, todo
    if can_fork():
        queue = SharedQueue(sorted(cold, key=lambda k: -_work([k])))
        return _Forked(queue), queue
    theirs = split_work(cold, movable=[k for k in cold if _importable(k)])
    helper = _interpreter(theirs) if theirs else None
    if helper is None:
        return None, todo
    return helper, [k for k in todo if k not in theirs]


class SharedQueue:
    """Kernels handed out one at a time to whichever process asks first: this one and
    the helper forked after the queue was made iterate over it (a counter in shared
    memory, under its lock), and each kernel goes to one of them."""

    def __init__(self, kernels: Sequence[Any]):
        self.kernels = list(kernels)
        self.taken = fork_context().Value("i", 0)

    def __iter__(self) -> Iterator[Any]:
        lock = self.taken.get_lock()
        while True:
            if not lock.acquire(timeout=QUEUE_LOCK_TIMEOUT):
                return  # the other process died holding it: the rest is readied later
            try:
                i = self.taken.value
                self.taken.value = i + 1
            finally:
                lock.release()
            if i >= len(self.kernels):
                return
            yield self.kernels[i]


@contextlib.contextmanager
def fewer_collections() -> Iterator[None]:
    """Python's garbage collector, while numba compiles, walks less: numba's compiler
    makes and drops objects by the million, and a collection started every
    :data:`GC_THRESHOLD` [0] new objects would walk also everything imported so far
    (numba, py-pde, scipy). Frozen, the objects that exist now are not walked; restored
    after."""
    thresholds = gc.get_threshold()
    gc.freeze()
    gc.set_threshold(*GC_THRESHOLD)
    try:
        yield
    finally:
        gc.set_threshold(*thresholds)
        gc.unfreeze()


def split_work(kernels: Sequence[Any], movable: Sequence[Any] | None = None) -> list[Any]:
    """The kernels of ``kernels`` (only ``movable`` ones, if given) that the helper
    process compiles: of all ways to split them in two (neither side empty), the one
    whose helper share of the work is nearest :data:`HELPER_SHARE` (more than 12
    candidates: the heaviest first while the share stays below it). The work of
    kernels is the bytecode size of their call trees (compile time grows with it); a
    callee on both sides counts on both (both compile it)."""
    kernels = list(kernels)
    movable = kernels if movable is None else list(movable)
    if len(kernels) < 2 or not movable:
        return []
    total = _work(kernels)
    if len(movable) > 12:
        chosen: list[Any] = []
        for k in sorted(movable, key=lambda k: -_work([k])):
            if len(chosen) < len(kernels) - 1 and \
                    _work([*chosen, k]) <= HELPER_SHARE * total:
                chosen.append(k)
        return chosen
    splits = ([k for i, k in enumerate(movable) if mask >> i & 1]
              for mask in range(1, 2 ** len(movable)))
    return min((side for side in splits if len(side) < len(kernels)),
               key=lambda side: abs(_work(side) / total - HELPER_SHARE), default=[])


def can_fork() -> bool:
    """True if this process can fork a helper safely and the helper gets a core of its
    own: on Linux (macOS's system libraries do not survive a fork; Windows has none),
    with no other thread running (its locks, numba's compiler lock among them, would
    stay locked in the fork) and a second core."""
    return (sys.platform.startswith("linux") and threading.active_count() == 1
            and _cores() > 1)


def fork_context() -> Any:
    """multiprocessing's "fork" context, with this process's output flushed first (a
    fork must not write this process's buffers again); only where :func:`can_fork`."""
    sys.stdout.flush()
    sys.stderr.flush()
    return multiprocessing.get_context("fork")


def helper_main(names: Sequence[str]) -> None:
    """The new-interpreter helper: ready the kernels named ``module:qualname``."""
    import importlib

    with fewer_collections():
        for name in names:
            module, _, qualname = name.partition(":")
            ready(getattr(importlib.import_module(module), qualname))


class _Forked:
    """A forked helper process, waited for like a ``subprocess.Popen``."""

    def __init__(self, kernels: Iterable[Any]):
        self.process = fork_context().Process(target=ready_each, args=(kernels,),
                                              daemon=True)
        self.process.start()

    def wait(self) -> None:
        self.process.join()

    def terminate(self) -> None:
        self.process.terminate()


def _interpreter(kernels: Sequence[Any]) -> subprocess.Popen | None:
    names = [f"{k.py_func.__module__}:{k.py_func.__qualname__}" for k in kernels]
    # the helper must import this pdeflow, whatever put it on this process's path
    root = str(Path(__file__).resolve().parents[2])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [root, *filter(None, [os.environ.get("PYTHONPATH")])])}
    code = ("import sys; from pdeflow.numerics.compile_parallel import helper_main; "
            "helper_main(sys.argv[1:])")
    try:
        return subprocess.Popen([sys.executable, "-c", code, *names], env=env,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:  # pragma: no cover - no process to spare: compile here
        return None


def ready_each(kernels: Iterable[Any]) -> None:
    """:func:`~pdeflow.numerics.compiled.ready` every kernel of ``kernels``."""
    for k in kernels:
        ready(k)


def _importable(compiled: Any) -> bool:
    """True if a new interpreter finds ``compiled`` by its module and name."""
    func = compiled.py_func
    module = sys.modules.get(func.__module__)
    return "<locals>" not in func.__qualname__ and \
        getattr(module, func.__qualname__, None) is compiled


def _inlined(compiled: Any) -> bool:
    """True for a kernel numba copies into its callers (``inline="always"``): its IR is
    typed and lowered again at every call site, never compiled on its own."""
    return getattr(compiled, "targetoptions", {}).get("inline") == "always"


@functools.cache
def _callee_sites(compiled: Any) -> tuple[tuple[Any, int], ...]:
    """The kernels ``compiled`` closes over or names
    (:func:`~pdeflow.numerics.compiled.named_kernels`), each with how often its code
    loads it: its call sites (memoised: a kernel's code and callees are fixed once it is
    built; :func:`split_work` asks for the same trees for every split it weighs)."""
    func = compiled.py_func
    loads: dict[str, int] = {}
    for ins in dis.get_instructions(func.__code__):
        if ins.opname in ("LOAD_GLOBAL", "LOAD_DEREF"):
            loads[ins.argval] = loads.get(ins.argval, 0) + 1
    closed, named = named_kernels(compiled)
    return tuple((k, loads.get(name, 1)) for name, k in (*closed, *named))


@functools.cache
def _own_work(compiled: Any) -> int:
    """Bytecode size [bytes] that compiling ``compiled`` types and lowers: its own, and
    that of every inlined callee once per call site (recursively)."""
    return len(compiled.py_func.__code__.co_code) + sum(
        sites * _own_work(k) for k, sites in _callee_sites(compiled) if _inlined(k))


def _call_tree(compiled: Any, found: dict[int, Any]) -> dict[int, Any]:
    """``compiled`` and every kernel compiled on its own that it calls, recursively
    (through inlined callees too)."""
    if id(compiled) not in found:
        found[id(compiled)] = compiled
        for kernel, _ in _callee_sites(compiled):
            _call_tree(kernel, found)
    return found


def _work(kernels: Sequence[Any]) -> int:
    """Compile work of the union of the call trees of ``kernels`` [bytes of bytecode]:
    every kernel compiled on its own counts with :func:`_own_work` plus
    :data:`KERNEL_OVERHEAD`."""
    found: dict[int, Any] = {}
    for k in kernels:
        _call_tree(k, found)
    return sum(_own_work(k) + KERNEL_OVERHEAD for k in found.values()
               if not _inlined(k) or k in kernels)


def _cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not on Linux
        return os.cpu_count() or 1
