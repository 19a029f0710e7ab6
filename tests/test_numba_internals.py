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
from numba import config
from packaging.requirements import Requirement

from pdeflow.numerics import compiled

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).parents[1]

CLASSES = {
    "numba.core.registry.CPUDispatcher": "subclassed by numba_hooks.HelperKernel, "
                                         "instantiated by numba_hooks.jit",
    "numba.core.dispatcher.Dispatcher": "what compiled.ready and warmup.prepare accept",
    "numba.core.caching.FunctionCache": "subclassed by numba_hooks._CodeKeyedCache",
    "numba.core.caching.IndexDataCacheFile": "read by numba_hooks.in_disk_cache",
    "numba.core.types.function_type.CompileResultWAP": "subclassed by "
                                                       "numba_hooks.FunctionPointer",
    "numba.core.cpu.CPUTargetOptions": "takes numba_hooks.jit's target options",
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

BOTH_PATHS = {"numba.core.dispatcher.Dispatcher.compile",
              "numba.core.dispatcher.Dispatcher.disable_compile"}
"""methods the public path calls too (compiled.ready): checked on every numba"""

ATTRIBUTES = {
    "numba.core.cpu.CPUTargetOptions": ["no_cpython_wrapper", "no_cfunc_wrapper",
                                        "inline", "boundscheck", "parallel"],
    "numba.core.dispatcher.Dispatcher": ["signatures", "stats"],
    "numba.core.caching.FunctionCache": ["_guard_against_spurious_io_errors"],
    "numba.extending.typeof_impl": ["register"],
    "numba.core.types.function_type.CompileResultWAP": ["__wrapper_address__",
                                                        "signature"],
}
"""class attributes (options, properties, methods) pdeflow reads"""

INSTANCE_ATTRIBUTES = ["_cache", "overloads", "targetctx",
                       "targetoptions", "py_func", "signatures", "stats"]
"""attributes of a compiled dispatcher that pdeflow reads or replaces (``_cache``)"""


hooks_only = pytest.mark.skipif(compiled.HOOKS is None, reason="numba's private hooks off "
                                "(PDEFLOW_NUMBA_FALLBACK=1 or an untested numba)")


def _fail(internal: str, problem: str) -> None:
    pytest.fail(f"numba {numba.__version__}: {internal} {problem}. "
                f"pdeflow.numerics.numba_hooks relies on it: adapt numba_hooks.py to this "
                f"numba or lower compiled.NEWEST_TESTED_NUMBA below it", pytrace=False)


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


def test_numba_has_a_lower_bound_only():
    """pyproject.toml lets any numba from 0.59 on be installed (a newer one than tested
    takes the public path); the installed one is inside."""
    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    (req,) = [Requirement(d) for d in deps if Requirement(d).name == "numba"]
    assert [(s.operator, s.version) for s in req.specifier] == [(">=", "0.59")], req
    assert numba.__version__ in req.specifier


def test_the_hooks_are_used_on_tested_numba_releases_only(monkeypatch):
    """The private hooks are on for numba up to NEWEST_TESTED_NUMBA, off for a newer
    release and with PDEFLOW_NUMBA_FALLBACK=1 (0 or empty: on)."""
    major, minor = compiled.NEWEST_TESTED_NUMBA
    monkeypatch.delenv("PDEFLOW_NUMBA_FALLBACK", raising=False)
    for version, on in ((f"{major}.{minor}.9", True), (f"{major}.{minor - 1}.0", True),
                        (f"{major}.{minor + 1}.0rc1", False), (f"{major + 1}.0.0", False),
                        (f"{major}.{minor}rc1", True), ("unknown", False)):
        monkeypatch.setattr(numba, "__version__", version)
        assert (compiled._private_hooks() is not None) == on, version
    monkeypatch.setattr(numba, "__version__", f"{major}.{minor}.0")
    for value, on in (("1", False), ("0", True), ("", True)):
        monkeypatch.setenv("PDEFLOW_NUMBA_FALLBACK", value)
        assert (compiled._private_hooks() is not None) == on, value


@hooks_only
@pytest.mark.parametrize("dotted", sorted(CLASSES))
def test_numba_classes_pdeflow_builds_on_exist(dotted):
    if not inspect.isclass(_resolve(dotted)):
        _fail(dotted, f"is no longer a class ({CLASSES[dotted]})")


@pytest.mark.parametrize("dotted", sorted(SIGNATURES))
def test_numba_methods_pdeflow_calls_keep_their_parameters(dotted):
    if compiled.HOOKS is None and dotted not in BOTH_PATHS:
        pytest.skip("numba's private hooks off")
    params = list(inspect.signature(_resolve(dotted)).parameters)
    expected = SIGNATURES[dotted]
    if params[:len(expected)] != expected:
        _fail(dotted, f"takes {params}, pdeflow calls it as {expected}")


@hooks_only
@pytest.mark.parametrize("dotted", sorted(ATTRIBUTES))
def test_numba_attributes_pdeflow_reads_exist(dotted):
    obj = _resolve(dotted)
    for name in ATTRIBUTES[dotted]:
        if not hasattr(obj, name):
            _fail(f"{dotted}.{name}", "is missing")


@hooks_only
@pytest.mark.skipif(config.DISABLE_JIT, reason="nothing is compiled")
def test_a_compiled_kernel_has_the_private_state_pdeflow_reads():
    """On a kernel of pdeflow's: the dispatcher attributes, the cache it replaced, the
    index entry that in_disk_cache looks for (read here without its fallback to
    False, so that the failure says what moved) and the function pointer."""
    from pdeflow.models.single_layer.sources import sources_single

    hooks = compiled.HOOKS
    k = compiled.ready(sources_single)
    for name in INSTANCE_ATTRIBUTES:
        if not hasattr(k, name):
            _fail(f"CPUDispatcher instance attribute {name!r}", "is missing")
    if not isinstance(k._cache, hooks._CodeKeyedCache):
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
    assert isinstance(pointer, hooks.FunctionPointer)
    if not isinstance(pointer.__wrapper_address__(), int):
        _fail("CompileResultWAP.__wrapper_address__()", "returns no address")


def test_a_moved_internal_fails_with_its_name_and_the_numba_version():
    with pytest.raises(pytest.fail.Exception,
                       match=rf"numba {numba.__version__}: numba.core.caching.Gone is "
                             r"missing \(numba.core.caching has no 'Gone'\)"):
        _resolve("numba.core.caching.Gone")
