"""The stepper visits only the wet region plus its stencil: that must change nothing.

A collapse on a domain ten times longer (same dx, the extra cells dry) must give the
same state, bit for bit, in the cells of the short domain, for every scheme variant,
as long as the flow has not reached the short domain's far end.
"""

import numpy as np
import pytest

import pdeflow

from .helpers import grid, step


def collapse(two_layer: bool, n: int, **scheme):
    g = grid(n, 0.0, 0.05 * n)
    x = g.axes_coords[0]
    column = np.where(x < 0.5, 1.0, 0.0)
    if two_layer:
        eq = pdeflow.TwoLayerGranular(bc=("wall", "wall"), **scheme)
        return eq, eq.make_state(g, h1=0.4 * column, h2=0.6 * column)
    eq = pdeflow.SingleLayerGranular(bc=("wall", "wall"), **scheme)
    return eq, eq.make_state(g, h=column)


@pytest.mark.parametrize("two_layer", [False, True])
@pytest.mark.parametrize("scheme,strang", [
    ({}, False), ({}, True), ({"reconstruction": "muscl", "limiter": "mc"}, False),
    ({"reconstruction": "muscl", "flux": "ifcp"}, True)])
def test_dry_cells_beyond_the_flow_change_nothing(two_layer, scheme, strang):
    short, long_ = 60, 600
    eq, s_short = collapse(two_layer, short, **scheme)
    _, s_long = collapse(two_layer, long_, **scheme)
    q1, t1, n1, _, d1 = step(eq, s_short, 0.3, strang=strang)
    q2, t2, n2, _, d2 = step(eq, s_long, 0.3, strang=strang)
    assert np.all(q1[0, short - 5:] == 0.0)  # the flow is still far from the end
    assert (t1, n1) == (t2, n2)
    np.testing.assert_array_equal(q1, q2[:, :short])
    assert np.all(q2[:, short:] == 0.0)
    if two_layer:
        np.testing.assert_array_equal(d1[pdeflow.numerics.layout.N_DIAG:],
                                      d2[pdeflow.numerics.layout.N_DIAG:][:short])


def test_a_dirty_initial_state_is_cleaned_everywhere():
    """The first step visits every cell: films below the dry tolerance lose their
    momentum and negative round-off is clipped, also far from the flow."""
    eq, st = collapse(True, 200)
    st.data[1, 150] = 1e-9  # momentum in a dry cell
    st.data[2, 180] = -1e-14  # round-off below zero
    q, *_ = step(eq, st, 0.05)
    assert q[1, 150] == 0.0 and q[2, 180] == 0.0


_ALLOC_SCRIPT = r"""
import json, sys
import numpy as np
from numba.core.runtime import rtsys
import pdeflow
from tests.helpers import grid, step

out = []
for two, scheme, strang in ((True, {}, False), (True, {"reconstruction": "muscl"}, True),
                            (False, {}, False), (False, {"reconstruction": "muscl"}, False)):
    g = grid(200, 0.0, 10.0)
    x = g.axes_coords[0]
    col = np.where(x < 1.0, 1.0, 0.0)
    if two:
        eq = pdeflow.TwoLayerGranular(**scheme)
        st = eq.make_state(g, h1=0.5 * col, h2=0.5 * col)
    else:
        eq = pdeflow.SingleLayerGranular(**scheme)
        st = eq.make_state(g, h=col)
    step(eq, st, 0.01, strang=strang)  # compile or load
    counts = []
    for t_end in (0.05, 0.5):
        a0 = rtsys.get_allocation_stats()
        steps = step(eq, st, t_end, strang=strang)[2]
        counts.append((steps, rtsys.get_allocation_stats().alloc - a0.alloc))
    out.append(counts)
# 2D: both models, first order and MUSCL + Strang, one and two threads
from pde import CartesianGrid
g2 = CartesianGrid([[0, 3.0], [0, 3.0]], [40, 40])
x, y = np.meshgrid(*g2.axes_coords, indexing="ij")
disc = np.where(np.hypot(x - 1.0, y - 1.5) < 0.5, 0.5, 0.0)
walls = (("wall", "wall"), ("wall", "wall"))
for two in (True, False):
    for scheme in ("hll/first-order", "hll/muscl/mc+strang"):
        for threads in (1, 2):
            if two:
                eq = pdeflow.TwoLayerGranular(theta_deg=30, scheme=scheme, bc=walls)
                make = lambda: eq.make_state(g2, h1=0.4 * disc, h2=0.6 * disc)
            else:
                eq = pdeflow.SingleLayerGranular(theta_deg=30, phi_b_deg=20, scheme=scheme,
                                                 bc=walls)
                make = lambda: eq.make_state(g2, h=disc)
            counts = []
            for t_end in (0.001, 0.01, 0.1):  # (the first: compile or load)
                st = make()
                solver = pdeflow.FVSplitSolver(eq, threads=threads, t_end=t_end)
                stepper = solver.make_stepper(st)
                a0 = rtsys.get_allocation_stats()
                stepper(st, 0.0, t_end)
                counts.append((solver.info["steps"],
                               rtsys.get_allocation_stats().alloc - a0.alloc))
            out.append(counts[1:])
print(json.dumps(out))
"""


def test_the_stepping_loop_allocates_nothing_per_step():
    """numba's runtime counts its allocations (NUMBA_NRT_STATS=1, set before numba is
    imported, hence a subprocess): a run of ten times as many steps allocates exactly as
    often as a short one, on a 1D and a 2D grid (whose passes over rows put what the
    rows share in one array a call, ``boxes.gather_rows``), with one and two threads."""
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).parents[1]
    env = {**os.environ, "NUMBA_NRT_STATS": "1"}
    res = subprocess.run([sys.executable, "-c", _ALLOC_SCRIPT], cwd=root, env=env,
                         capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr[-2000:]
    for (steps_short, allocs_short), (steps_long, allocs_long) in json.loads(
            res.stdout.strip().splitlines()[-1]):
        assert steps_long > 5 * steps_short
        assert allocs_long == allocs_short
