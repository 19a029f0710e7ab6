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
* :func:`specialise` caches a closure on disk under a key made of the constants it
  closes over and the code of the kernels it calls (numba's own key pickles a
  closed-over kernel, which gives a new key in every process, so such a closure would
  never be loaded from the cache), and names it after them; :func:`kernel` and
  :func:`cached` key module-level kernels by their code and their callees' the same way.
* :func:`cached` helpers (and closures specialised with ``helper=True``) are
  :class:`HelperKernel` s: only other kernels call them, so they are compiled without
  the entry points that Python and C function pointers need, which every caller would
  link in and compile again (a call from Python still works).
* :func:`kernels`, :func:`pending` and :func:`in_disk_cache`: what is compiled, what is
  still to compile or load, and what numba's disk cache holds.

The rest of the package does not call :func:`ready` to warm kernels up before a run:
:func:`pdeflow.numerics.warmup.prepare` does, the one entry point of the cold start.
Every numba internal this module relies on (subclassed classes, private attributes) is
listed and checked by ``tests/test_numba_internals.py``.
"""

from __future__ import annotations

import functools
import hashlib
import sys
from collections.abc import Callable, Iterable, Iterator
from types import CodeType, ModuleType
from typing import Any

from numba import types
from numba.core import config
from numba.core.caching import FunctionCache
from numba.core.dispatcher import Dispatcher
from numba.core.registry import CPUDispatcher
from numba.core.runtime.nrt import rtsys
from numba.core.types.function_type import CompileResultWAP
from numba.core.typing.typeof import typeof_impl

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

_SIGNATURES: dict[Any, tuple] = {}
_SPECIALISED: list[Any] = []
_ENTRIES: list[Any] = []


def kernel(*arg_types: Any) -> Callable:
    """Decorator: a module-level numba kernel (disk-cached) with the one signature
    ``arg_types``, compiled lazily (by :func:`ready`, or by the first caller), callable
    from Python and through a function pointer."""

    def wrap(func: Callable) -> Any:
        compiled = _jit(func)
        if isinstance(compiled, Dispatcher):  # not with NUMBA_DISABLE_JIT=1
            _SIGNATURES[compiled] = tuple(arg_types)
        return compiled

    return wrap


def cached(func: Callable | None = None, *, inline: str = "never") -> Any:
    """Decorator: a helper kernel that other kernels call (see :class:`HelperKernel`),
    disk-cached under the code of the function and of every kernel it calls (see
    :class:`_CodeKeyedCache`); ``@cached`` or ``@cached(inline="always")``."""

    def wrap(f: Callable) -> Any:
        return _jit(f, helper=True, inline=inline)

    return wrap(func) if func is not None else wrap


def specialise(func: Callable, *arg_types: Any, helper: bool = False,
               pointer: bool = True) -> Any:
    """A numba kernel of the closure ``func`` with the one signature ``arg_types``,
    disk-cached under its constants (see the module docstring); compiled by
    :func:`ready`. ``helper``: only other kernels call it (see :class:`HelperKernel`);
    ``pointer``: it is also called through a function pointer (:func:`first_class`)."""
    if config.DISABLE_JIT:
        return func
    # numba names compiled code after the function's qualified name and a per-process
    # counter: two closures of one factory compiled in two processes (a run and its
    # compile helper, or two runs) can get one name, and a process that loads both
    # from the disk cache may run one's code for the other (numba issue #10486). Here
    # the name carries what the closure is made of.
    description = repr(_describe_function(func)).encode()
    func.__qualname__ += "_" + hashlib.sha256(description).hexdigest()[:12]
    compiled = _jit(func, helper=helper, pointer=pointer)
    _SIGNATURES[compiled] = tuple(arg_types)
    _SPECIALISED.append(compiled)
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
            twin = self._python_twin = _jit(self.py_func, python_twin=True)
        return twin(*args, **kwargs)


def _jit(func: Callable, *, helper: bool = False, pointer: bool = True,
         inline: str = "never", python_twin: bool = False) -> Any:
    """``numba.njit(func)`` with the disk cache of :class:`_CodeKeyedCache`; ``helper``:
    a :class:`HelperKernel`; not ``pointer``: without the entry point for a function
    pointer."""
    if config.DISABLE_JIT:
        return func
    options = {"nopython": True, "boundscheck": None, "inline": inline,
               "no_cpython_wrapper": helper, "no_cfunc_wrapper": helper or not pointer}
    compiled = (HelperKernel if helper else CPUDispatcher)(
        py_func=func, locals={}, targetoptions=options)
    compiled._cache = _CodeKeyedCache(func, python_twin, options)
    return compiled


def entry(*kernels: Any) -> None:
    """Register kernels that a solver is about to call (e.g. the stepping loop of a
    scheme and the model's kernels it is given): :func:`pending` lists them until they
    are compiled or loaded."""
    for compiled in kernels:
        if isinstance(compiled, Dispatcher) and compiled not in _ENTRIES:
            _ENTRIES.append(compiled)


def needs_compiling(compiled: Any) -> bool:
    """True for a kernel whose declared signature is neither compiled nor loaded."""
    return (isinstance(compiled, Dispatcher) and compiled in _SIGNATURES
            and _SIGNATURES[compiled] not in compiled.signatures)


def ready(compiled: Any) -> Any:
    """Compile (or load) the signature of ``compiled`` and of the kernels it calls,
    callees first, then allow no other signature; returns ``compiled``."""
    if not isinstance(compiled, Dispatcher) or not compiled._can_compile:
        return compiled
    for dep in _callees(compiled):
        ready(dep)
    sig = _SIGNATURES.get(compiled)
    if sig is not None:
        if sig not in compiled.signatures:
            compiled.compile(sig)
        compiled.disable_compile()
    return compiled


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


def first_class(compiled: Any) -> Any:
    """``compiled`` (after :func:`ready`) as a :class:`FunctionPointer`; anything else
    as is (None, or a Python function with NUMBA_DISABLE_JIT=1)."""
    if not isinstance(compiled, Dispatcher):
        return compiled
    return FunctionPointer(compiled.overloads[_SIGNATURES[compiled]])


def referenced_kernels(compiled: Any) -> tuple[list[Any], list[Any]]:
    """(the kernels ``compiled`` closes over, the module-level kernels its code names)."""
    closed, named = named_kernels(compiled)
    return [k for _, k in closed], [k for _, k in named]


def named_kernels(compiled: Any) -> tuple[list[tuple[str, Any]], list[tuple[str, Any]]]:
    """:func:`referenced_kernels` with the name each goes by in the code of
    ``compiled``: (closed over, named at module level), as (name, kernel) pairs."""
    func = compiled.py_func
    cells = zip(func.__code__.co_freevars, func.__closure__ or (), strict=True)
    closed = [(name, cell.cell_contents) for name, cell in cells]
    named = [(name, func.__globals__.get(name)) for name in func.__code__.co_names]
    return ([(n, k) for n, k in closed if isinstance(k, Dispatcher)],
            [(n, k) for n, k in named if isinstance(k, Dispatcher)])


def _callees(compiled: Any) -> Iterator[Any]:
    """The kernels that ``compiled`` closes over, and the module-level kernels with a
    declared signature that it names. (A factory closes over what its scheme calls
    only, None for the rest, so that nothing here is compiled for nothing.)"""
    closed, named = referenced_kernels(compiled)
    yield from closed
    yield from (k for k in named if k in _SIGNATURES)


def kernels() -> list[Any]:
    """Every numba kernel of pdeflow in this process (:mod:`pdeflow.numerics` and the
    models' packages): the module-level ones of the imported modules and the
    specialised ones built so far."""
    found: dict[int, Any] = {}
    top = __package__.split(".")[0] + "."
    for name, module in list(sys.modules.items()):
        if name.startswith(top) and module is not None:
            for value in vars(module).values():
                if isinstance(value, Dispatcher) and value.py_func.__module__ == name:
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
    machine's CPU (read from numba's cache index; False if it cannot be read)."""
    try:
        key = compiled._cache._index_key(_SIGNATURES[compiled],
                                         compiled.targetctx.codegen())
        return key in compiled._cache._cache_file._load_index()  # {} if source changed
    except Exception:  # pragma: no cover - numba internals moved: assume the worst
        return False


@functools.cache
def _code_digest(code: CodeType) -> str:
    """Digest of a function's bytecode and constants (nested code objects included);
    memoised (code objects are immutable)."""
    h = hashlib.sha256(code.co_code)
    for const in code.co_consts:
        h.update(_code_digest(const).encode() if isinstance(const, CodeType)
                 else repr(const).encode())
    return h.hexdigest()


@functools.cache
def _names(code: CodeType) -> frozenset[str]:
    """The global and attribute names a function's code reads, nested code included."""
    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, CodeType):
            names |= _names(const)
    return frozenset(names)


def _describe_function(func: Callable, depth: int = 0) -> tuple:
    """Code digest, closed-over values, global constants read and called kernels of a
    kernel's function."""
    callees = tuple((name, _describe(value, depth + 1)) for name in func.__code__.co_names
                    if isinstance(value := func.__globals__.get(name), Dispatcher))
    cells = tuple(_describe(c.cell_contents, depth + 1) for c in func.__closure__ or ())
    return (func.__module__, func.__qualname__, _code_digest(func.__code__), cells,
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
    if isinstance(value, Dispatcher):
        func = value.py_func
        return (_describe_function(func, depth) if depth < 8
                else (func.__module__, func.__qualname__))
    if isinstance(value, (bool, int, float, str, type(None))):
        return (type(value).__name__, repr(value))
    if isinstance(value, tuple):
        return tuple(_describe(v, depth + 1) for v in value)
    raise TypeError(f"a specialised kernel cannot close over {value!r}")


class _CodeKeyedCache(FunctionCache):
    """numba's disk cache for a kernel, keyed by its code, what it closes over (see the
    module docstring), the code of every kernel it calls and its compile options.
    numba's own key is the kernel's source file's time stamp: a kernel whose callee in
    another file changed would be loaded with the old callee compiled in (and give
    stale results); here it is recompiled."""

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
        own = repr(_describe_function(self._py_func)).encode()
        return (sig, codegen.magic_tuple(), (_code_digest(self._py_func.__code__),
                                             hashlib.sha256(own).hexdigest()),
                self._variant)
