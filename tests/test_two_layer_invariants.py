"""Conservation, positivity, symmetry and rest of the two-layer splitting scheme."""

import numpy as np
import pytest

import pdeflow
from pdeflow.models.two_layer import layout as T
from pdeflow.numerics.splitting import STATUS_REST

from .helpers import grid, step, two_layer_column


def test_mass_conserved_to_round_off_with_walls():
    eq, st = two_layer_column()
    r = eq.parameters.density_ratio
    m0 = np.sum(r * st.data[0] + st.data[2])
    q, t, steps, status, diag = step(eq, st, 1.0)
    assert steps > 100
    assert diag[T.D_DEPOSITED] > 0.1  # exchange really happened
    m1 = np.sum(r * q[0] + q[2])
    assert abs(m1 - m0) <= 1e-13 * m0


def test_momentum_conserved_by_exchange_and_fextra():
    """Source stages move momentum between layers only (flat bed, no basal friction
    acting when the lower layer is absent)."""
    g = grid(50)
    eq = pdeflow.TwoLayerGranular(bc=("wall", "wall"), phi_b_deg=1e-9, c=0.05)
    st = eq.make_state(g, h1=np.full(50, 0.3), u1=np.full(50, 3.0), h2=np.full(50, 0.2),
                       u2=np.full(50, 0.0))
    q = st.data.copy()
    p0 = np.sum(0.67 * q[1] + q[3])
    diag = eq.new_diagnostics(50)
    eq.source_kernel()(q, 1e-3, 1e-3, eq.parameter_array(), diag)
    assert diag[T.D_HYP_EVENTS] > 0 or diag[T.D_ERODED] + diag[T.D_DEPOSITED] > 0
    assert np.sum(0.67 * q[1] + q[3]) == pytest.approx(p0, rel=1e-12, abs=1e-12)


def test_depths_never_negative_and_dry_cells_still():
    eq, st = two_layer_column(n=100)
    q, t, steps, status, diag = step(eq, st, 2.0)
    assert np.all(q[0] >= 0) and np.all(q[2] >= 0)
    dry = eq.parameters.dry_tolerance
    assert np.all(q[1][q[0] <= dry] == 0) and np.all(q[3][q[2] <= dry] == 0)


def test_mirror_symmetry():
    n = 120
    g = grid(n, -3.0, 3.0)
    x = g.axes_coords[0]
    eq = pdeflow.TwoLayerGranular(bc=("wall", "wall"))
    h2 = np.clip(1.0 - np.abs(x) * 1.5, 0, None)
    h1 = np.where(np.abs(x) < 1.0, 1.2 - h2, 0.0)
    st = eq.make_state(g, h1=h1, h2=h2)
    q, *_ = step(eq, st, 0.6)
    assert np.allclose(q[0], q[0][::-1], atol=1e-12)
    assert np.allclose(q[2], q[2][::-1], atol=1e-12)
    assert np.allclose(q[1], -q[1][::-1], atol=1e-12)
    assert np.allclose(q[3], -q[3][::-1], atol=1e-12)


@pytest.mark.parametrize("model", ["single", "two"])
def test_subcritical_heap_stays_exactly_at_rest(model):
    """A heap flatter than the friction angles is a steady state: no creep at all."""
    n = 200
    g = grid(n, 0.0, 2.0)
    x = g.axes_coords[0]
    heap = np.clip(0.4 - np.tan(np.radians(20)) * np.abs(x - 1.0), 0, None)
    if model == "single":
        eq = pdeflow.SingleLayerGranular(bc=("wall", "wall"), phi_b_deg=30)
        st = eq.make_state(g, h=heap)
    else:
        eq = pdeflow.TwoLayerGranular(bc=("wall", "wall"), phi_b_deg=30)
        st = eq.make_state(g, h1=np.zeros(n), h2=heap)
    q, t, steps, status, diag = step(eq, st, 50.0, stop_at_rest=False, max_steps=2000)
    assert steps == 2000
    assert np.array_equal(q, st.data)


def test_supercritical_heap_slumps_then_stops():
    n = 100
    g = grid(n, 0.0, 2.0)
    x = g.axes_coords[0]
    heap = np.clip(0.4 - np.tan(np.radians(45)) * np.abs(x - 1.0), 0, None)
    eq = pdeflow.SingleLayerGranular(bc=("wall", "wall"), phi_b_deg=30)
    q, t, steps, status, diag = step(eq, eq.make_state(g, h=heap), 20.0,
                                     stop_at_rest=True)
    assert status == STATUS_REST
    assert 0 < t < 20
    assert not np.array_equal(q[0], heap)
    assert np.all(q[1] == 0)
