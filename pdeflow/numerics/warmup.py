"""Compiling or loading a run's kernels before it starts: the one entry point, :func:`prepare`.

Every caller that is about to run compiled kernels (``pdeflow run``, ``converge`` and
``sweep``, a :class:`~pdeflow.simulate.Run`, the study engine and its workers, the app)
calls :func:`prepare` with what it will run, so that neither its wall times nor its
progress bars include the compilation, and a cold start is as short as this module can
make it. Behind that one call (nothing else in the package uses these):

* what is already compiled or loaded in this process is skipped; the rest is compiled
  (or loaded from numba's disk cache) with the one signature each kernel declares
  (:func:`pdeflow.numerics.compiled.ready`);
* with two or more kernels to compile and a second core, a helper process compiles
  part of them meanwhile (:mod:`pdeflow.numerics.compile_parallel`: a fork, or a new
  interpreter that gets this pdeflow on its ``PYTHONPATH``);
* the garbage collector walks less while numba compiles
  (:func:`~pdeflow.numerics.compile_parallel.fewer_collections`);
* a stepper's kernels become function pointers once (its ``ready()``).

Without numba's private hooks (``compiled.HOOKS`` None) no helper process is started:
its closures would not load from the disk cache. :func:`status` says whether anything
is left to compile (for progress bars).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from typing import Any, TextIO

from . import compiled
from .compile_parallel import fewer_collections, ready_each, start_helper
from .compiled import in_disk_cache, needs_compiling, pending
from .kernel_identity import is_kernel

READY = "ready"
""":func:`status`: every kernel is compiled or loaded in this process"""
CACHED = "cached"
""":func:`status`: what is left is in numba's disk cache (loading it is quick)"""
COLD = "cold"
""":func:`status`: some kernel must be compiled (the first run on a machine)"""


def prepare(work: Any, *, log: TextIO | None = None,
            meanwhile: Callable[[], Any] | None = None, parallel: bool = True) -> float:
    """Compile (or load from numba's disk cache) now every kernel that ``work`` calls.

    Args:
        work: a kernel, a stepper (an object with the list ``kernels`` and a method
            ``ready()`` that binds them, such as
            :class:`pdeflow.numerics.splitting.Stepper`), or an iterable of these
            (nested iterables and None are allowed: ``prepare([])`` does nothing).
        log: a stream (e.g. ``sys.stderr``) that is told when kernels have to be
            compiled (once per machine and scheme) and how long it took; None: silent.
        meanwhile: work of the caller's that can fill the wait for the helper process
            (e.g. imports its figures need); called once in any case, also when there
            is nothing to compile.
        parallel: let a helper process compile part of the kernels where it pays.

    Returns:
        The seconds it took, ``meanwhile`` included (0 if nothing was left to compile
        or load).
    """
    items = list(_flatten(work))
    kernels = list(dict.fromkeys(k for item in items for k in _kernels_of(item)))
    state = status(kernels)
    if state == READY:
        if meanwhile is not None:
            meanwhile()
        _bind(items)
        return 0.0
    if state == COLD and log is not None:
        print("pdeflow: compiling numba kernels (once per machine) ...", end="",
              file=log, flush=True)
    t0 = time.perf_counter()
    _compile(kernels, parallel, meanwhile)
    _bind(items)
    seconds = time.perf_counter() - t0
    if state == COLD and log is not None:
        print(f" done in {seconds:.1f} s", file=log, flush=True)
    return seconds


def status(work: Any = None) -> str:
    """:data:`READY`, :data:`CACHED` or :data:`COLD` for the kernels of ``work`` (as
    :func:`prepare` takes it) and those they call; default: every entry kernel built in
    this process (e.g. by a solver's ``make_stepper``). Always :data:`READY` with
    ``NUMBA_DISABLE_JIT=1``."""
    roots = None if work is None else [k for item in _flatten(work)
                                       for k in _kernels_of(item)]
    left = pending(roots)
    if not left:
        return READY
    return CACHED if all(in_disk_cache(k) for k in left) else COLD


def _compile(kernels: list[Any], parallel: bool,
             meanwhile: Callable[[], Any] | None) -> None:
    """Ready ``kernels`` (and their callees), part of them in a helper process if
    ``parallel``; ``meanwhile`` after this process's share, before the wait."""
    with fewer_collections():
        todo = [k for k in kernels if needs_compiling(k)]
        # without the private hooks a helper's closures would not load from the cache
        helper, mine = start_helper(todo) if parallel and compiled.HOOKS \
            else (None, todo)
        try:
            ready_each(mine)
            if meanwhile is not None:
                meanwhile()
        except BaseException:
            if helper is not None:  # e.g. Ctrl-C: no helper outlives this call
                helper.terminate()
            raise
        if helper is not None:
            helper.wait()
        ready_each(todo)  # the helper's share, from the disk cache (or compiled here)


def _flatten(work: Any) -> Iterator[Any]:
    """The kernels and steppers of ``work``, nested iterables opened, None dropped."""
    if work is None:
        return
    if is_kernel(work) or hasattr(work, "kernels") or callable(work):
        yield work
        return
    try:
        items = iter(work) if not isinstance(work, (str, bytes)) else None
    except TypeError:
        items = None
    if items is None:
        raise TypeError(f"prepare takes kernels and steppers (e.g. "
                        f"pdeflow.simulate.case_steppers(case)), got {work!r}")
    for item in items:
        yield from _flatten(item)


def _kernels_of(item: Any) -> list[Any]:
    """The numba kernels of a kernel or a stepper (none for a Python function, as with
    ``NUMBA_DISABLE_JIT=1``)."""
    found = item.kernels if hasattr(item, "kernels") else [item]
    return [k for k in found if is_kernel(k)]


def _bind(items: list[Any]) -> None:
    """Let every stepper of ``items`` bind its (now compiled) kernels."""
    for item in items:
        if hasattr(item, "kernels") and callable(getattr(item, "ready", None)):
            item.ready()
