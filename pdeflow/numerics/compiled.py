"""Compiled kernels: one signature each, specialised to the scheme a run uses, cached.

A run compiles only what its scheme calls. The kernels that depend on the scheme (the
stepping loop, the advection stage, the face fluctuations) are built by factories such
as :func:`pdeflow.numerics.advection.advection_kernel` as closures over the scheme's
choices, held as Python booleans and integers: numba drops the branches of every other
flux, reconstruction, limiter, splitting and model before it types anything, so their
kernels are never compiled. The stepping loop takes the model's kernels as arguments
(:func:`pdeflow.numerics.splitting.stepping_kernel`), so that one loop serves both
models. Parameters and grids stay arguments: a sweep over them never recompiles.

What the factories and the kernels share is kept here:

* :func:`kernel` (module-level kernels) and :func:`specialise` (closures) record the one
  signature of a kernel: the state is any 2D float64 array (py-pde's data is a view),
  scratch arrays are C-contiguous, the parameter vector is read-only, scalars are
  float64, codes int64 and flags bool. :func:`ready` compiles that signature (or loads it
  from numba's disk cache) and then stops the kernel from compiling others: a call with
  compatible types (a C-contiguous state, a writable parameter vector, a literal int) is
  converted instead of compiling a second signature.
* :func:`specialise` names a closure after the constants it closes over and the code
  of the kernels it calls (:mod:`pdeflow.numerics.kernel_identity`).
* Every kernel is cached on disk. On the numba releases pdeflow was tested on, numba's
  private classes make a start faster (:data:`HOOKS`, :mod:`pdeflow.numerics.numba_hooks`);
  elsewhere kernels are plain ``numba.njit(cache=True)``, computing the same numbers.
* :func:`kernels`, :func:`pending` and :func:`in_disk_cache`: what is compiled, what is
  still to compile or load, and what numba's disk cache holds.

The rest of the package does not call :func:`ready` to warm kernels up before a run:
:func:`pdeflow.numerics.warmup.prepare` does, the one entry point of the cold start.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Callable, Iterable, Iterator
from types import ModuleType
from typing import Any

import numba
from numba import config, njit, types

from .kernel_identity import closes_over_kernels, digest, is_kernel

f8 = types.float64
i8 = types.int64
flag = types.boolean
STATE = types.Array(f8, 2, "A")
"""the state q[field, cell]: any layout (py-pde's state data is a view)"""
FIELDS = types.Array(f8, 2, "C")
"""scratch arrays of the state's shape (rates, backups)"""
WORK = types.Array(f8, 3, "C")
"""scratch array of shape (stages, fields, cells)"""
VECTOR = types.Array(f8, 1, "C")
"""the diagnostics vector (see :mod:`pdeflow.numerics.layout`)"""
METRIC = types.Array(f8, 2, "C", readonly=True)
"""the grid's metric (see :mod:`pdeflow.numerics.geometry`)"""
PARAMS = types.Array(f8, 1, "C", readonly=True)
"""the parameter vector (see :mod:`pdeflow.numerics.layout`)"""

NEWEST_TESTED_NUMBA = (0, 68)
"""The newest numba release (major, minor) that :mod:`pdeflow.numerics.numba_hooks`
was tested on: a newer numba takes the public path."""


def _private_hooks() -> ModuleType | None:
    """:mod:`pdeflow.numerics.numba_hooks` where it was tested and imports, else None:
    with ``PDEFLOW_NUMBA_FALLBACK=1``, a numba newer than :data:`NEWEST_TESTED_NUMBA`
    (or one whose internals moved) every kernel is a plain ``numba.njit``."""
    if os.environ.get("PDEFLOW_NUMBA_FALLBACK", "0") not in ("", "0"):
        return None
    release = re.match(r"(\d+)\.(\d+)", numba.__version__)
    if release is None or tuple(map(int, release.groups())) > NEWEST_TESTED_NUMBA:
        return None
    try:
        from . import numba_hooks
    except (ImportError, AttributeError):  # pragma: no cover - an internal moved
        return None
    return numba_hooks


HOOKS = _private_hooks()
"""numba's private classes in use (:mod:`pdeflow.numerics.numba_hooks`), or None: the
public path"""

_SIGNATURES: dict[Any, tuple] = {}
_SPECIALISED: list[Any] = []
_ENTRIES: list[Any] = []
_READY: set[Any] = set()


def kernel(*arg_types: Any) -> Callable:
    """Decorator: a module-level numba kernel (disk-cached) with the one signature
    ``arg_types``, compiled lazily (by :func:`ready`, or by the first caller), callable
    from Python and through a function pointer."""

    def wrap(func: Callable) -> Any:
        compiled = _jit(func)
        if is_kernel(compiled):  # not with NUMBA_DISABLE_JIT=1
            _SIGNATURES[compiled] = tuple(arg_types)
        return compiled

    return wrap


def cached(func: Callable | None = None, *, inline: str = "never") -> Any:
    """Decorator: a helper kernel that only other kernels call (with :data:`HOOKS`
    compiled without entry points, :class:`~pdeflow.numerics.numba_hooks.HelperKernel`),
    disk-cached; ``@cached`` or ``@cached(inline="always")``."""

    def wrap(f: Callable) -> Any:
        return _jit(f, helper=True, inline=inline)

    return wrap(func) if func is not None else wrap


def specialise(func: Callable, *arg_types: Any, helper: bool = False,
               pointer: bool = True, inline: str = "never", name: str | None = None,
               parallel: bool = False) -> Any:
    """A numba kernel of the closure ``func`` with the one signature ``arg_types``,
    disk-cached (see the module docstring); compiled by :func:`ready`. ``helper``: only
    other kernels call it (see :func:`cached`);
    ``pointer``: it is also called through a function pointer (:func:`first_class`).
    Without ``arg_types`` (a helper, e.g. ``inline="always"``) it declares no signature
    and is compiled by the kernels that call it, as :func:`cached` helpers are.
    ``name``: the module-level name the caller binds it to (one closure of its
    factory), so that a new interpreter finds it by name
    (:mod:`pdeflow.numerics.compile_parallel`). ``parallel``: its ``prange`` loops run on
    numba's threads (:mod:`pdeflow.numerics.threads`; a 2D grid's passes only)."""
    if config.DISABLE_JIT:
        return func
    # numba names compiled code after the function's qualified name and a per-process
    # counter: two closures of one factory compiled in two processes (a run and its
    # compile helper, or two runs) can get one name, and a process that loads both
    # from the disk cache may run one's code for the other (numba issue #10486). Here
    # the name carries what the closure is made of, or is a module-level name.
    func.__qualname__ = name or func.__qualname__ + "_" + digest(func)[:12]
    compiled = _jit(func, helper=helper, pointer=pointer, inline=inline, parallel=parallel)
    if arg_types:
        _SIGNATURES[compiled] = tuple(arg_types)
    _SPECIALISED.append(compiled)
    return compiled


def _jit(func: Callable, *, helper: bool = False, pointer: bool = True,
         inline: str = "never", parallel: bool = False) -> Any:
    """``numba.njit(func)``, disk-cached; with :data:`HOOKS`, ``helper``: without entry
    points for Python and function pointers, not ``pointer``: without the latter
    (:func:`pdeflow.numerics.numba_hooks.jit`); ``parallel``: numba's ``parallel=True``."""
    if config.DISABLE_JIT:
        return func
    if HOOKS is not None:
        return HOOKS.jit(func, helper=helper, pointer=pointer, inline=inline,
                         parallel=parallel)
    # numba's own cache key pickles what a closure closes over, and a kernel pickles
    # differently in every process: such a closure would be compiled in every process
    # and leave a cache entry each time, so it is not cached
    return njit(inline=inline, cache=not closes_over_kernels(func), parallel=parallel)(func)


def entry(*kernels: Any) -> None:
    """Register kernels that a solver is about to call (e.g. the stepping loop of a
    scheme and the model's kernels it is given): :func:`pending` lists them until they
    are compiled or loaded."""
    for compiled in kernels:
        if is_kernel(compiled) and compiled not in _ENTRIES:
            _ENTRIES.append(compiled)


def needs_compiling(compiled: Any) -> bool:
    """True for a kernel whose declared signature is neither compiled nor loaded."""
    return (is_kernel(compiled) and compiled in _SIGNATURES
            and _SIGNATURES[compiled] not in compiled.signatures)


def ready(compiled: Any) -> Any:
    """Compile (or load) the signature of ``compiled`` and of the kernels it calls,
    callees first, then allow no other signature; returns ``compiled``."""
    if not is_kernel(compiled) or compiled in _READY:
        return compiled
    for dep in _callees(compiled):
        ready(dep)
    sig = _SIGNATURES.get(compiled)
    if sig is not None:
        if sig not in compiled.signatures:
            compiled.compile(sig)
        compiled.disable_compile()
    _READY.add(compiled)
    return compiled


def first_class(compiled: Any) -> Any:
    """``compiled`` (after :func:`ready`) as a function pointer with :data:`HOOKS`
    (:class:`pdeflow.numerics.numba_hooks.FunctionPointer`); anything else as is (a
    kernel on the public path: numba converts it at each call; None; a Python function
    with NUMBA_DISABLE_JIT=1)."""
    if HOOKS is None or not is_kernel(compiled):
        return compiled
    return HOOKS.pointer(compiled, _SIGNATURES[compiled])


def named_kernels(compiled: Any) -> tuple[list[tuple[str, Any]], list[tuple[str, Any]]]:
    """(the kernels ``compiled`` closes over, the module-level kernels its code names),
    each as (the name it goes by in the code, kernel)."""
    func = compiled.py_func
    cells = zip(func.__code__.co_freevars, func.__closure__ or (), strict=True)
    closed = [(name, cell.cell_contents) for name, cell in cells]
    named = [(name, func.__globals__.get(name)) for name in func.__code__.co_names]
    return ([(n, k) for n, k in closed if is_kernel(k)],
            [(n, k) for n, k in named if is_kernel(k)])


def _callees(compiled: Any) -> Iterator[Any]:
    """The kernels that ``compiled`` closes over, and the module-level kernels with a
    declared signature that it names. (A factory closes over what its scheme calls
    only, None for the rest, so that nothing here is compiled for nothing.)"""
    closed, named = named_kernels(compiled)
    yield from (k for _, k in closed)
    yield from (k for _, k in named if k in _SIGNATURES)


def kernels() -> list[Any]:
    """Every numba kernel of pdeflow in this process (:mod:`pdeflow.numerics` and the
    models' packages): the module-level ones of the imported modules and the
    specialised ones built so far."""
    found: dict[int, Any] = {}
    top = __package__.split(".")[0] + "."
    for name, module in list(sys.modules.items()):
        if name.startswith(top) and module is not None:
            for value in vars(module).values():
                if is_kernel(value) and value.py_func.__module__ == name:
                    found[id(value)] = value
    for compiled in _SPECIALISED:
        found[id(compiled)] = compiled
    return list(found.values())


def pending(roots: Iterable[Any] | None = None) -> list[Any]:
    """The kernels of ``roots`` (default: the entry kernels built in this process, see
    :func:`entry`) and the kernels they call that are neither compiled nor loaded yet."""
    todo = [k for k in (_ENTRIES if roots is None else roots) if needs_compiling(k)]
    seen: dict[int, Any] = {}
    while todo:
        k = todo.pop()
        if id(k) not in seen and needs_compiling(k):
            seen[id(k)] = k
            todo.extend(_callees(k))
    return list(seen.values())


def in_disk_cache(compiled: Any) -> bool:
    """True if numba's disk cache holds the declared signature of ``compiled`` for this
    machine's CPU; always False on the public path (numba has no public way to tell)."""
    return HOOKS is not None and HOOKS.in_disk_cache(compiled, _SIGNATURES[compiled])
