"""pytest-benchmark tests: timings to track across commits, and the hard targets.

Run with ``python -m pytest benchmarks`` (``--benchmark-save=NAME`` and
``--benchmark-compare`` to compare commits). Each benchmark calls a compiled run after
a warm-up; the assertions check what does not depend on the machine's load (results,
signatures), timings are only reported. The numbers in docs/performance.md come from
``run_benchmarks.py``, which interleaves runs for stable ratios.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("pytest_benchmark")

import suite  # noqa: E402

VARIANTS = ("hll/first-order", "rusanov/first-order", "ifcp/first-order", "hll/muscl/minmod",
            "ifcp/muscl/mc", "hll/first-order+strang")


@pytest.mark.parametrize("model", ["single_layer", "two_layer"])
@pytest.mark.parametrize("variant", VARIANTS)
def test_cell_updates(benchmark, model, variant):
    """5.1 case, dx = 0.0125 m, to t = 0.4 s: one model and variant."""
    from pdeflow.analysis.points import case_on_grid, resolve_case
    from pdeflow.variant import Variant

    case = case_on_grid(resolve_case(suite.CASE_5_1), 0.0125, Variant.parse(variant))
    run = suite.fv_stepper_run(case, model, 0.4)
    out = run()
    benchmark.extra_info["cell_updates"] = out["steps"] * out["cells"]
    benchmark.pedantic(run, rounds=5, warmup_rounds=1)
    assert np.all(np.isfinite(out["data"]))


@pytest.mark.parametrize("model", ["single_layer", "two_layer"])
def test_case_5_1_to_rest(benchmark, model):
    from pdeflow.cases import load_case
    from pdeflow.simulate import run_model

    case = load_case(suite.CASE_5_1, ["output.snapshot_times=[]"])
    res = benchmark.pedantic(lambda: run_model(case, model), rounds=5, warmup_rounds=1)
    assert res.summary["at_rest"]


@pytest.mark.parametrize("model", ["single_layer", "two_layer"])
def test_large_grid_steps(benchmark, model):
    """200 steps of the 5.1 column on 10^5 cells (tests/test_stress.py checks the
    results of a run of this size; its wall time is tracked here)."""
    out = benchmark.pedantic(suite.large_grid_run(model), rounds=3, warmup_rounds=1)
    assert out["steps"] == 200 and np.all(np.isfinite(out["data"]))


@pytest.mark.parametrize("H0", [0.5, 2.0])
def test_sweep_member_pdeflow(benchmark, H0):
    case = suite.sweep_case(H0, "single_layer")
    pkg, base = suite._pkg_vs_baseline(case)
    out = benchmark.pedantic(pkg, rounds=5, warmup_rounds=1)
    _, steps, h = base()
    assert out["steps"] == steps
    np.testing.assert_allclose(out["data"][0], h, atol=1e-12)


@pytest.mark.parametrize("H0", [0.5, 2.0])
def test_sweep_member_baseline(benchmark, H0):
    _, base = suite._pkg_vs_baseline(suite.sweep_case(H0, "single_layer"))
    benchmark.pedantic(base, rounds=5, warmup_rounds=1)


@pytest.mark.parametrize("H0", [0.5, 2.0])
def test_sweep_member_pyclaw(benchmark, H0):
    import pyclaw_run

    if not pyclaw_run.available():
        pytest.skip("clawpack is not installed")
    case = suite.sweep_case(H0, "single_layer")
    t_rest = suite.fv_stepper_run(case, "single_layer")()["t"]
    L = suite.sweep_length(H0)
    benchmark.pedantic(lambda: pyclaw_run.collapse(suite.SWEEP_L0, H0, L, suite.SWEEP_DX,
                                                   t_rest), rounds=3, warmup_rounds=1)


def test_pyclaw_2d_without_clawpack_says_so_in_one_line():
    """Where clawpack does not import, ``python benchmarks/pyclaw_2d.py`` prints one line
    naming it and exits with status 1 (clawpack is hidden from a fresh interpreter)."""
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).parent / "pyclaw_2d.py"
    hide = ("import runpy, sys; sys.modules['clawpack'] = None; "
            f"sys.argv = [{str(script)!r}, '--cells', '8']; "
            f"runpy.run_path({str(script)!r}, run_name='__main__')")
    out = subprocess.run([sys.executable, "-c", hide], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 1, out
    assert out.stdout == ""
    assert out.stderr.splitlines() == [
        "pyclaw_2d: clawpack is not installed (pip install clawpack; needs gfortran)"]


def test_pyclaw_2d_solves_the_same_dam_break():
    """PyClaw's HLLE and pdeflow's hll/first-order solve the same 2D dam break: the same
    steps within 5 % (the same dt rule; measured 43/44 and 92/92), and the L1 difference
    of their depths falls under refinement, 32^2 -> 64^2, by more than 1.4x (two first-
    order schemes converging to one solution; measured 2.1x, 1.31e-2 -> 6.2e-3 of H0),
    and is below 2e-2 H0 on 32^2."""
    import pyclaw_2d
    import pyclaw_run

    if not pyclaw_run.available(pyclaw_2d.RIEMANN):
        pytest.skip("clawpack is not installed")
    m = {n: pyclaw_2d.measure_grid(n, repeats=1) for n in (32, 64)}
    for n in (32, 64):
        steps = [r["steps"] for r in m[n]["rows"].values()]
        assert max(steps) <= 1.05 * min(steps), m[n]["rows"]
    l1 = {n: m[n]["l1"]["pdeflow, every cell"] for n in (32, 64)}
    assert l1[32] < 2e-2 and l1[32] / l1[64] > 1.4, l1


def test_pyclaw_2d_dam_break(benchmark):
    """PyClaw's 2D dam break on 64^2 cells (wall time tracked; pyclaw_2d.py compares)."""
    import pyclaw_2d
    import pyclaw_run

    if not pyclaw_run.available(pyclaw_2d.RIEMANN):
        pytest.skip("clawpack is not installed")
    out = benchmark.pedantic(lambda: pyclaw_2d.pyclaw_dam(64), rounds=3, warmup_rounds=1)
    assert out["steps"] > 0 and np.all(np.isfinite(out["h"]))


def test_one_signature_for_a_sweep_of_both_models():
    """A sweep of run_model calls (both models, several grids) compiles no kernel
    twice: one signature each, the stepping loop one kernel for both models."""
    from pdeflow.numerics import compiled
    from pdeflow.simulate import run_model

    for H0 in (0.5, 1.0):
        for model in ("single_layer", "two_layer"):
            run_model(suite.sweep_case(H0, model), model)
    assert max(len(k.signatures) for k in compiled.kernels()) == 1


def test_wet_region_only():
    """A 10x longer domain costs far less than 10x (medians of interleaved runs)."""
    rows = suite.wet_region_savings(repeats=3)
    for r in rows:
        assert r["steps"] == r["steps_long"]
        assert r["ratio"] < 5.0, r
        assert math.isfinite(r["wall_s"])
