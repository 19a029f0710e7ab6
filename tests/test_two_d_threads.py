"""The 2D fv-split loop's passes run row by row on numba's threads
(pdeflow.numerics.threads, issue 36): the same numbers, bit for bit, with any thread
count; bad thread counts refused in one line; a 1D run starts no threads.

Bit identity is the design property compared (np.array_equal, on one machine with one
binary): every cell's result is the same arithmetic in the same order whatever the
threads, and what rows share is combined in row order (maxima, the source stage's
bookings), so no tolerance applies. The runs are small collapses with dry margins on
every side, so that the loop's box is smaller than the grid and moves.
"""

from __future__ import annotations

import subprocess
import sys

import numba
import numpy as np
import pytest
from pde import CartesianGrid

import pdeflow
from pdeflow.numerics.threads import available_threads

NX, NY, DX = 40, 30, 0.1  #: cells along x (down the slope) and y, their width [m]

needs_two = pytest.mark.skipif(available_threads() < 2, reason="one core: one thread")


def _collapse(two_layer: bool, scheme: str):
    """A column (radius 0.3 m, 0.3 m deep) on a walled plane at 20 deg, 1 m below the
    upper wall, in the middle across: dry margins beside the box the loop visits."""
    grid = CartesianGrid([[0, NX * DX], [0, NY * DX]], [NX, NY])
    x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
    column = np.where(np.hypot(x - 1.0, y - NY * DX / 2) < 0.3, 0.3, 0.0)
    bc = (("wall", "wall"), ("wall", "wall"))
    if two_layer:
        eq = pdeflow.TwoLayerGranular(theta_deg=20.0, scheme=scheme, bc=bc)
        return eq, eq.make_state(grid, h1=0.4 * column, h2=0.6 * column)
    eq = pdeflow.SingleLayerGranular(theta_deg=20.0, phi_b_deg=30.0, scheme=scheme, bc=bc)
    return eq, eq.make_state(grid, h=column)


def _run(eq, state, threads: int, t_end: float = 0.3):
    out, info = eq.solve(state, t_end, solver="fv-split", tracker=None, ret_info=True,
                         stop_at_rest=False, threads=threads)
    return out.data, info["solver"]["steps"], info["solver"]["post_step_data"].copy()


# the default suite runs two of the eight (each compiles the loop's parallel kernels
# for its scheme, tens of seconds on a cold cache): one layer first order with Lie, two
# layers MUSCL with Strang; -m slow runs the others
DEFAULT_THREADED = {(False, "hll/first-order", ""), (True, "hll/muscl/mc", "+strang")}


@needs_two
@pytest.mark.parametrize(("two_layer", "scheme", "splitting"), [
    pytest.param(two, scheme, split,
                 id=f"{('single_layer', 'two_layer')[two]}-{scheme}-{split[1:] or 'lie'}",
                 marks=() if (two, scheme, split) in DEFAULT_THREADED else pytest.mark.slow)
    for two in (False, True) for scheme in ("hll/first-order", "hll/muscl/mc")
    for split in ("", "+strang")])
def test_one_and_two_threads_give_the_same_bits(two_layer, scheme, splitting):
    eq, state = _collapse(two_layer, scheme + splitting)
    before = numba.get_num_threads()
    q1, steps1, diag1 = _run(eq, state, 1)
    q2, steps2, diag2 = _run(eq, state, 2)
    assert numba.get_num_threads() == before  # the solver restores numba's setting
    depth = q1[0] + q1[3] if two_layer else q1[0]
    depth = depth.reshape(NX, NY)
    wet_x = np.flatnonzero(depth.max(axis=1) > 0)
    wet_y = np.flatnonzero(depth.max(axis=0) > 0)
    assert steps1 > 20 and wet_x[-1] >= 19  # it flowed down the slope, off the column
    assert wet_y[0] > 1 and wet_y[-1] < NY - 2  # dry margins in y: the box is narrower
    assert steps1 == steps2
    assert np.array_equal(q1, q2)
    # the bookings (times of motion, F_extra and its cell, exchanged depths, counters)
    # and the per-cell F_extra/rho1, folded in row order
    assert np.array_equal(diag1, diag2)


@needs_two
def test_numba_thread_setting_alone_changes_no_bit():
    """The threads set with numba.set_num_threads around the solver's own setting
    (threads=2 inside a block where numba was set to 1, and the reverse)."""
    eq, state = _collapse(True, "hll/muscl/minmod+strang")
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        q2, _, _ = _run(eq, state, 2, t_end=0.3)
        assert numba.get_num_threads() == 1
        numba.set_num_threads(2)
        q1, _, _ = _run(eq, state, 1, t_end=0.3)
    finally:
        numba.set_num_threads(before)
    assert np.array_equal(q1, q2)


@pytest.mark.parametrize("threads", [0, -1, 1.5, "2", True, None, "many"])
def test_bad_thread_counts_are_refused_in_one_line(threads):
    eq, state = _collapse(False, "hll/first-order")
    with pytest.raises(ValueError) as err:
        eq.solve(state, 0.1, solver="fv-split", tracker=None, threads=threads)
    message = str(err.value)
    assert "\n" not in message
    assert message.startswith(f"threads must be an integer in [1, {available_threads()}]")


def test_more_threads_than_numba_has_are_refused():
    eq, state = _collapse(False, "hll/first-order")
    with pytest.raises(ValueError, match=r"threads must be an integer in \[1, "):
        eq.solve(state, 0.1, solver="fv-split", tracker=None,
                 threads=available_threads() + 1)


def test_a_1d_run_starts_no_threads_and_compiles_no_parallel_kernel():
    """A 1D fv-split run (any threads) neither launches numba's threading layer nor
    builds a parallel kernel (a 1D run's cold start pays nothing for the 2D threads)."""
    code = """
import numpy as np
from pde import CartesianGrid
import pdeflow
from numba.np.ufunc import parallel
from pdeflow.numerics import compiled
grid = CartesianGrid([[0, 4]], 80)
x = grid.axes_coords[0]
eq = pdeflow.TwoLayerGranular(scheme="hll/muscl/mc")
state = eq.make_state(grid, h1=np.where(x < 1, 0.3, 0.0), h2=np.where(x < 1, 0.5, 0.0))
eq.solve(state, 0.2, solver="fv-split", tracker=None, threads=2)
built = [k for k in compiled.kernels() if k.targetoptions.get("parallel") and k.signatures]
print(parallel._is_initialized, len(built))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=900, check=True).stdout.split()
    assert out == ["False", "0"]
