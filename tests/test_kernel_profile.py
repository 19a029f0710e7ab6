"""benchmarks/kernel_profile.py: the perf map of numba's JIT code and the report's shares
(the parts that need no perf)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest
from numba import njit

PATH = Path(__file__).resolve().parents[1] / "benchmarks" / "kernel_profile.py"


@pytest.fixture(scope="module")
def kp():
    spec = importlib.util.spec_from_file_location("kernel_profile", PATH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_readable_names(kp):
    assert kp.readable("_ZN7pdeflow8numerics7sources18friction_two_layerB3v53B54c8tJTIeFI"
                       "jxB2IKSgI4CrvSCKg1MMfAwQ4s_2E") == \
        "pdeflow.numerics.sources.friction_two_layer"
    assert kp.readable("_ZN7pdeflow8numerics3pvm10_two_layer12_3clocals_3e19fluct_two_lay"
                       "er_abcB3v25E") == \
        "pdeflow.numerics.pvm._two_layer.<locals>.fluct_two_layer_abc"
    assert kp.readable("cfunc._ZN3abc1fB2v1E") == "cfunc.abc.f"
    assert kp.readable("NRT_incref") == "NRT_incref"


def test_map_covers_compiled_functions(kp, tmp_path):
    @njit(cache=False)
    def inner(x):
        return 2.0 * x

    @njit(cache=False)
    def outer(x):
        return inner(x) + 1.0

    assert outer(1.0) == 3.0
    functions = kp.compiled_functions([outer, inner])
    names = [kp.readable(name) for _, name in functions]
    assert any(n.endswith(".outer") for n in names)
    assert any(n.endswith(".inner") for n in names)
    addresses = [a for a, _ in functions]
    assert addresses == sorted(addresses) and len(set(addresses)) == len(addresses)
    n = kp.write_perf_map(functions, tmp_path / "perf.map")
    lines = (tmp_path / "perf.map").read_text().splitlines()
    assert n == len(lines) == len(functions)
    for line, (address, _) in zip(lines, functions, strict=True):
        start, size, name = line.split(" ", 2)
        assert int(start, 16) == address and 0 < int(size, 16) <= kp.MAX_SIZE and name


def test_shares_of_the_kernels(kp):
    report = """# comment
    30.00%  [.] a.kernel
    10.00%  [.] b.kernel
    20.00%  [.] _PyEval_EvalFrameDefault
    10.00%  [.] a.kernel
"""
    shares, total = kp.kernel_shares(report, {"a.kernel", "b.kernel"})
    assert total == pytest.approx(50.0)
    assert list(shares) == ["a.kernel", "b.kernel"]
    assert shares["a.kernel"] == pytest.approx(80.0)
    assert shares["b.kernel"] == pytest.approx(20.0)
    assert kp.kernel_shares("", {"a.kernel"}) == ({}, 0.0)
