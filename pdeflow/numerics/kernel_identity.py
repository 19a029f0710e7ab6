"""What a kernel is made of, the same in every process: the identity that names a
specialised closure (:func:`pdeflow.numerics.compiled.specialise`) and keys numba's disk
cache (:mod:`pdeflow.numerics.numba_hooks`).

A kernel's identity is its code, the values it closes over, the numbers it reads as
globals (numba compiles them in as constants) and, recursively, the identity of every
kernel it calls. Pure Python: nothing here touches numba beyond recognising a kernel.
"""

from __future__ import annotations

import functools
import hashlib
from collections.abc import Callable
from types import CodeType, ModuleType
from typing import Any

from numba import config, njit


def _probe() -> None:  # pragma: no cover - never called
    """A function to see what numba's ``njit`` makes of one."""


_KERNEL = () if config.DISABLE_JIT else type(njit(_probe))
"""numba's class of compiled functions, as ``numba.njit`` makes them (no class with
NUMBA_DISABLE_JIT=1, where it makes none). Looked up once: ``numba.extending.is_jitted``
imports it at every call, which made describing a kernel tree 3.6 times slower."""


def is_kernel(value: Any) -> bool:
    """True for a numba-compiled function (a dispatcher)."""
    return isinstance(value, _KERNEL)


@functools.cache
def code_digest(code: CodeType) -> str:
    """Digest of a function's bytecode and constants (nested code objects included);
    memoised (code objects are immutable)."""
    h = hashlib.sha256(code.co_code)
    for const in code.co_consts:
        h.update(code_digest(const).encode() if isinstance(const, CodeType)
                 else repr(const).encode())
    return h.hexdigest()


def digest(func: Callable) -> str:
    """SHA-256 [hex] of :func:`describe_function` of ``func``."""
    return hashlib.sha256(repr(describe_function(func)).encode()).hexdigest()


@functools.cache
def _names(code: CodeType) -> frozenset[str]:
    """The global and attribute names a function's code reads, nested code included."""
    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, CodeType):
            names |= _names(const)
    return frozenset(names)


def describe_function(func: Callable, depth: int = 0) -> tuple:
    """Code digest, closed-over values, global constants read and called kernels of a
    kernel's function."""
    callees = tuple((name, _describe(value, depth + 1)) for name in func.__code__.co_names
                    if is_kernel(value := func.__globals__.get(name)))
    cells = tuple(_describe(c.cell_contents, depth + 1) for c in func.__closure__ or ())
    return (func.__module__, func.__qualname__, code_digest(func.__code__), cells,
            callees, _constants_read(func))


def _constants_read(func: Callable) -> tuple:
    """The global numbers a kernel's code reads, by name, and the numbers it reads as
    attributes of modules (``L.N_DIAG``): numba compiles them in as constants, so a
    kernel must be recompiled when one changes although its code did not. (Read
    values, not memoised: a constant may change within a process.)"""
    out = []
    names = _names(func.__code__)
    for name in sorted(names):
        value = func.__globals__.get(name)
        if isinstance(value, (bool, int, float)):
            out.append((name, repr(value)))
        elif isinstance(value, ModuleType):
            attributes = vars(value)
            numbers = tuple(sorted((k, repr(attributes[k])) for k in names
                                   if isinstance(attributes.get(k), (bool, int, float))))
            if numbers:
                out.append((name, value.__name__, numbers))
    return tuple(out)


def _describe(value: Any, depth: int = 0) -> Any:
    """A description of a closed-over value that is the same in every process."""
    if is_kernel(value):
        func = value.py_func
        return (describe_function(func, depth) if depth < 8
                else (func.__module__, func.__qualname__))
    if isinstance(value, (bool, int, float, str, type(None))):
        return (type(value).__name__, repr(value))
    if isinstance(value, tuple):
        return tuple(_describe(v, depth + 1) for v in value)
    raise TypeError(f"a specialised kernel cannot close over {value!r}")


def closes_over_kernels(func: Callable) -> bool:
    """True if ``func`` closes over a kernel (or a tuple holding one)."""
    def holds(value: Any) -> bool:
        return is_kernel(value) or (isinstance(value, tuple) and any(map(holds, value)))
    return any(holds(c.cell_contents) for c in func.__closure__ or ())
