"""The numba internals that pdeflow's compile layer relies on, each checked by name.

:mod:`pdeflow.numerics.compiled` subclasses numba's ``CPUDispatcher``, ``FunctionCache``
and ``CompileResultWAP`` and reads private attributes of numba's dispatchers and disk
cache; pyproject.toml pins numba to the versions these checks passed on. A numba
release that moves one of them fails here, with the internal and the numba version in
the message, instead of giving wrong cache hits or a crash deep inside a run.
"""

from __future__ import annotations

import importlib
import inspect
import sys
from pathlib import Path

import numba
import pytest
from numba.core import config
from packaging.requirements import Requirement

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).parents[1]

CLASSES = {
    "numba.core.registry.CPUDispatcher": "subclassed by compiled.HelperKernel, "
                                         "instantiated by compiled._jit",
    "numba.core.dispatcher.Dispatcher": "what compiled.ready and warmup.prepare accept",
    "numba.core.caching.FunctionCache": "subclassed by compiled._CodeKeyedCache",
    "numba.core.caching.IndexDataCacheFile": "read by compiled.in_disk_cache",
    "numba.core.types.function_type.CompileResultWAP": "subclassed by "
                                                       "compiled.FunctionPointer",
    "numba.core.cpu.CPUTargetOptions": "takes compiled._jit's target options",
}
"""numba classes pdeflow uses beyond numba's public API: what for"""

SIGNATURES = {
    "numba.core.registry.CPUDispatcher.__init__": ["self", "py_func", "locals",
                                                   "targetoptions"],
    "numba.core.caching.FunctionCache.__init__": ["self", "py_func"],
    "numba.core.caching.FunctionCache._index_key": ["self", "sig", "codegen"],
    "numba.core.caching.FunctionCache.load_overload": ["self", "sig", "target_context"],
    "numba.core.caching.FunctionCache.save_overload": ["self", "sig", "data"],
    "numba.core.caching.FunctionCache._load_overload": ["self", "sig", "target_context"],
    "numba.core.runtime.nrt.rtsys.initialize": ["ctx"],
    "numba.core.caching.IndexDataCacheFile._load_index": ["self"],
    "numba.core.types.function_type.CompileResultWAP.__init__": ["self", "cres"],
    "numba.core.dispatcher.Dispatcher.compile": ["self", "sig"],
    "numba.core.dispatcher.Dispatcher.disable_compile": ["self", "val"],
}
"""leading parameters of the numba methods pdeflow calls or overrides"""

ATTRIBUTES = {
    "numba.core.cpu.CPUTargetOptions": ["no_cpython_wrapper", "no_cfunc_wrapper",
                                        "inline", "boundscheck"],
    "numba.core.dispatcher.Dispatcher": ["signatures", "stats"],
    "numba.core.caching.FunctionCache": ["_guard_against_spurious_io_errors"],
    "numba.core.typing.typeof.typeof_impl": ["register"],
    "numba.core.types.function_type.CompileResultWAP": ["__wrapper_address__",
                                                        "signature"],
}
"""class attributes (options, properties, methods) pdeflow reads"""

INSTANCE_ATTRIBUTES = ["_cache", "_can_compile", "overloads", "targetctx",
                       "targetoptions", "py_func", "signatures", "stats"]
"""attributes of a compiled dispatcher that pdeflow reads or replaces (``_cache``)"""


def _fail(internal: str, problem: str) -> None:
    pytest.fail(f"numba {numba.__version__}: {internal} {problem}. "
                f"pdeflow.numerics.compiled relies on it: adapt compiled.py to this numba "
                f"or keep numba within the range pyproject.toml pins", pytrace=False)


def _resolve(dotted: str) -> object:
    """The object named ``dotted`` (module path, then attributes), or a loud failure."""
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj: object = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for name in parts[i:]:
            if not hasattr(obj, name):
                _fail(dotted, f"is missing ({'.'.join(parts[:i])} has no {name!r})")
            obj = getattr(obj, name)
        return obj
    _fail(dotted, "is missing (no such module)")
    return None  # pragma: no cover - _fail raised


def test_installed_numba_is_within_the_pinned_range():
    """pyproject.toml bounds numba on both sides; the installed numba is inside."""
    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    (req,) = [Requirement(d) for d in deps if Requirement(d).name == "numba"]
    assert any(s.operator in ("<", "<=") for s in req.specifier), \
        f"pyproject.toml: numba needs an upper bound, got {req}"
    if numba.__version__ not in req.specifier:
        _fail("the release", f"is outside the tested range {req.specifier} of "
                             f"pyproject.toml: run this file, then move the bound")


@pytest.mark.parametrize("dotted", sorted(CLASSES))
def test_numba_classes_pdeflow_builds_on_exist(dotted):
    if not inspect.isclass(_resolve(dotted)):
        _fail(dotted, f"is no longer a class ({CLASSES[dotted]})")


@pytest.mark.parametrize("dotted", sorted(SIGNATURES))
def test_numba_methods_pdeflow_calls_keep_their_parameters(dotted):
    params = list(inspect.signature(_resolve(dotted)).parameters)
    expected = SIGNATURES[dotted]
    if params[:len(expected)] != expected:
        _fail(dotted, f"takes {params}, pdeflow calls it as {expected}")


@pytest.mark.parametrize("dotted", sorted(ATTRIBUTES))
def test_numba_attributes_pdeflow_reads_exist(dotted):
    obj = _resolve(dotted)
    for name in ATTRIBUTES[dotted]:
        if not hasattr(obj, name):
            _fail(f"{dotted}.{name}", "is missing")


@pytest.mark.skipif(config.DISABLE_JIT, reason="nothing is compiled")
def test_a_compiled_kernel_has_the_private_state_pdeflow_reads():
    """On a kernel of pdeflow's: the dispatcher attributes, the cache it replaced, the
    index entry that in_disk_cache looks for (read here without its fallback to
    False, so that the failure says what moved) and the function pointer."""
    from pdeflow.models.single_layer.sources import sources_single
    from pdeflow.numerics import compiled

    k = compiled.ready(sources_single)
    for name in INSTANCE_ATTRIBUTES:
        if not hasattr(k, name):
            _fail(f"CPUDispatcher instance attribute {name!r}", "is missing")
    if k._can_compile:
        _fail("Dispatcher.disable_compile()", "no longer clears Dispatcher._can_compile")
    if not isinstance(k._cache, compiled._CodeKeyedCache):
        _fail("Dispatcher._cache", "is no longer the cache numba compiles through")
    sig = compiled._SIGNATURES[k]
    for name in ("_py_func", "_cache_file"):
        if not hasattr(k._cache, name):
            _fail(f"FunctionCache.{name}", "is missing")
    index = k._cache._cache_file._load_index()
    if not isinstance(index, dict):
        _fail("IndexDataCacheFile._load_index()", f"returns {type(index).__name__}")
    if k._cache._index_key(sig, k.targetctx.codegen()) not in index:
        _fail("the disk cache index", "does not hold the key FunctionCache._index_key "
                                      "gave when it saved the kernel")
    assert compiled.in_disk_cache(k)
    pointer = compiled.first_class(k)
    if not isinstance(pointer.__wrapper_address__(), int):
        _fail("CompileResultWAP.__wrapper_address__()", "returns no address")


def test_a_moved_internal_fails_with_its_name_and_the_numba_version():
    with pytest.raises(pytest.fail.Exception,
                       match=rf"numba {numba.__version__}: numba.core.caching.Gone is "
                             r"missing \(numba.core.caching has no 'Gone'\)"):
        _resolve("numba.core.caching.Gone")
