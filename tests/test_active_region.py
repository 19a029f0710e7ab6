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
