"""pdeflow's uses of numba's private classes, on the numba releases they were tested on.

:mod:`pdeflow.numerics.compiled` imports this module only for numba up to
:data:`~pdeflow.numerics.compiled.NEWEST_TESTED_NUMBA` and without
``PDEFLOW_NUMBA_FALLBACK=1``; otherwise (or if an import here fails) every kernel is a
plain ``numba.njit(cache=...)`` and the same code computes the same numbers, slower to
start (docs/performance.md, "cold-start mechanisms"). What each hook buys:

* :class:`HelperKernel`: helpers compiled without the entry points for Python and C
  function pointers, which every caller would link in and compile again;
* :class:`_CodeKeyedCache`: numba's disk cache keyed by what a kernel is made of
  (:mod:`pdeflow.numerics.kernel_identity`), so that closures over kernels are loaded
  in a later process and a changed callee in another file recompiles its callers; loaded
  without numba's registry refresh;
* :class:`FunctionPointer`: a kernel passed to the stepping loop with its address and
  type looked up once;
* :func:`in_disk_cache`: whether a kernel will load instead of compiling.

``tests/test_numba_internals.py`` checks every internal used here by name.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from typing import Any

from numba import types
from numba.core.caching import FunctionCache
from numba.core.registry import CPUDispatcher
from numba.core.runtime.nrt import rtsys
from numba.core.types.function_type import CompileResultWAP
from numba.extending import typeof_impl

from .kernel_identity import code_digest, describe_function


def jit(func: Callable, *, helper: bool = False, pointer: bool = True,
        inline: str = "never", python_twin: bool = False, parallel: bool = False) -> Any:
    """``numba.njit(func)`` with the disk cache of :class:`_CodeKeyedCache`; ``helper``:
    a :class:`HelperKernel`; not ``pointer``: without the entry point for a function
    pointer; ``parallel``: its ``prange`` loops run on numba's threads."""
    options = {"nopython": True, "boundscheck": None, "inline": inline,
               "no_cpython_wrapper": helper, "no_cfunc_wrapper": helper or not pointer}
    if parallel:  # (only then: the options are part of every kernel's cache key)
        options["parallel"] = True
    compiled = (HelperKernel if helper else CPUDispatcher)(
        py_func=func, locals={}, targetoptions=options)
    compiled._cache = _CodeKeyedCache(func, python_twin, options)
    return compiled


class HelperKernel(CPUDispatcher):
    """A kernel that other kernels call: compiled without the two entry points numba
    gives every function by default, one for calls from Python (it unboxes the
    arguments and boxes the result) and one for C function pointers. Their code would
    be linked into every caller with the rest of the helper and compiled again there,
    at every level of a call tree, which makes deep trees (the source stages) slow to
    compile. A call from Python (a test, the app's spectrum page) goes to a twin with
    the entry points, compiled on its first such call and cached apart. (numba cannot
    call a function without its Python entry point from Python: the process would
    crash.)"""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        twin = self.__dict__.get("_python_twin")
        if twin is None:
            twin = self._python_twin = jit(
                self.py_func, python_twin=True,
                parallel=bool(self.targetoptions.get("parallel")))
        return twin(*args, **kwargs)


class FunctionPointer(CompileResultWAP):
    """A compiled kernel as a first-class function argument, with its address and numba
    type looked up once. (Passed a dispatcher, numba looks up its address on every call
    of the kernel it is passed to; passed numba's own wrapper, it builds the function
    type again on every call. The stepping loop is called once per tracker interval
    with up to four such arguments.)"""

    def __init__(self, cres: Any):
        super().__init__(cres)
        self._numba_type_ = types.FunctionType(cres.signature)


@typeof_impl.register(FunctionPointer)
def _typeof_function_pointer(val: FunctionPointer, c: Any) -> Any:
    return val._numba_type_


def pointer(compiled: Any, sig: tuple) -> FunctionPointer:
    """The compiled signature ``sig`` of ``compiled`` as a :class:`FunctionPointer`."""
    return FunctionPointer(compiled.overloads[sig])


def in_disk_cache(compiled: Any, sig: tuple) -> bool:
    """True if numba's disk cache holds the signature ``sig`` of ``compiled`` for this
    machine's CPU (read from numba's cache index; False if it cannot be read)."""
    try:
        key = compiled._cache._index_key(sig, compiled.targetctx.codegen())
        return key in compiled._cache._cache_file._load_index()  # {} if source changed
    except Exception:  # pragma: no cover - numba internals moved: assume the worst
        return False


class _CodeKeyedCache(FunctionCache):
    """numba's disk cache for a kernel, keyed by its code, what it closes over, the code
    of every kernel it calls and its compile options
    (:func:`~pdeflow.numerics.kernel_identity.describe_function`). numba's own key is
    the kernel's source file's time stamp and the pickled closure: a kernel whose callee
    in another file changed would be loaded with the old callee compiled in (and give
    stale results), and a closed-over kernel pickles differently in every process (such
    a closure would never be loaded); here both are keyed by their code."""

    def __init__(self, py_func: Callable, python_twin: bool = False,
                 options: dict[str, Any] | None = None):
        super().__init__(py_func)
        # a helper's twin (see HelperKernel) has entry points the helper lacks; the
        # compile options (inlining, entry points) change the machine code too
        self._variant = ("python twin" if python_twin else "",
                         tuple(sorted((options or {}).items())))

    def load_overload(self, sig: Any, target_context: Any) -> Any:
        """numba's load without its ``target_context.refresh()``: that loads every
        typing and lowering registry numba has (0.2-0.5 s, most of a warm start's
        kernel load), which only compiling needs, and numba's compiler refreshes the
        context itself before it compiles. Loaded machine code needs the runtime (NRT)
        it links against."""
        rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)

    def _index_key(self, sig: Any, codegen: Any) -> tuple:
        own = repr(describe_function(self._py_func)).encode()
        return (sig, codegen.magic_tuple(), (code_digest(self._py_func.__code__),
                                             hashlib.sha256(own).hexdigest()),
                self._variant)
