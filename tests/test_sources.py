"""Unit tests of the source kernels: implicit friction, exchange limiter, hyperbolicity."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pdeflow
from pdeflow.models.two_layer import layout as T
from pdeflow.models.two_layer.exchange import exchange_step, friction_two_layer
from pdeflow.models.two_layer.hyperbolicity import (
    band_lower_edge,
    discriminant,
    eigenvalues,
    is_hyperbolic,
    lower_bound_fl,
)

pos = st.floats(0.01, 2.0)


def exchange_depth(*args: float) -> float:
    """The limited change of h1 [m] that the source stage applies (exchange_step's first
    value)."""
    return exchange_step(*args)[0]
vel = st.floats(-5.0, 5.0)


def sgn_set(x, force, bound, tol):
    """force lies in bound * Sgn(x) (set-valued at 0)."""
    if x > 0:
        return abs(force - bound) <= tol
    if x < 0:
        return abs(force + bound) <= tol
    return abs(force) <= bound + tol


@settings(max_examples=300, deadline=None)
@given(b1=vel, b2=vel, m1=pos, m2=pos, K=st.floats(0, 2), C=st.floats(0, 1),
       B=st.floats(0, 3))
def test_friction_solution_satisfies_set_valued_equations(b1, b2, m1, m2, K, C, B):
    u1, u2 = friction_two_layer(b1, b2, m1, m2, K, C, B)
    d = u1 - u2
    f12 = m1 * (b1 - u1)  # = K Sgn(d) + C d|d|
    tol = 1e-9 * (1 + abs(b1) + abs(b2)) * (1 + m1 + m2 + K + B)
    assert sgn_set(d, f12 - C * d * abs(d), K, tol)
    fb = f12 - m2 * (u2 - b2)  # = B Sgn(u2)
    assert sgn_set(u2, fb, B, tol)


def test_friction_stops_in_finite_time_and_stays():
    u1, u2 = friction_two_layer(0.01, 0.005, 1.0, 1.0, 0.1, 0.0, 0.5)
    assert u1 == 0.0 and u2 == 0.0


@settings(max_examples=300, deadline=None)
@given(h1=pos, h2=pos, du=st.floats(-5, 5), dt=st.floats(1e-4, 1e-1),
       c=st.floats(0, 0.5), k=st.floats(0, 0.95), du_reg=st.floats(0, 1),
       tau=st.sampled_from([0.0, 0.01, 0.5]))
def test_exchange_limited_never_negative_nor_overshooting(h1, h2, du, dt, c, k, du_reg,
                                                          tau):
    r, g, tan = 0.67, 9.81, np.tan(np.radians(30))
    dh1 = exchange_depth(h1, h2, du, dt, r, g, tan, k, c, du_reg, 1e-3, tau)
    assert h1 + dh1 >= 0 and h2 - r * dh1 >= -1e-15
    h_eq = c * du * du / ((1 - k) * r * g * tan)
    if dh1 > 0:
        assert h1 + dh1 <= h_eq + 1e-12
    elif dh1 < 0 and h1 + dh1 > 0:
        assert h1 + dh1 >= min(h_eq, h1) - 1e-12


def test_paper_closure_deposits_everything_at_zero_relative_velocity():
    """The singularity of closure (25) at du = 0 (docs/model.md), documented."""
    r, g, tan = 0.67, 9.81, np.tan(np.radians(30))
    assert exchange_depth(0.5, 0.5, 0.0, 1e-3, r, g, tan, 0.8, 0.01, 0.0, 1e-3, 0.0) == -0.5
    bounded = exchange_depth(0.5, 0.5, 0.0, 1e-3, r, g, tan, 0.8, 0.01, 0.3, 1e-3, 0.0)
    assert -0.5 < bounded < 0
    # relaxed closure: exact relaxation towards h1_eq = 0 with time scale tau
    relaxed = exchange_depth(0.5, 0.5, 0.0, 1e-3, r, g, tan, 0.8, 0.01, 0.0, 1e-3, 0.2)
    assert relaxed == pytest.approx(-0.5 * (1 - np.exp(-1e-3 / 0.2)), rel=1e-12)


def test_relaxed_closure_keeps_paper_rate_where_it_is_slower():
    r, g, tan = 0.67, 9.81, np.tan(np.radians(30))
    args = (0.3, 0.5, 2.0, 1e-3, r, g, tan, 0.5, 0.03, 0.0, 1e-3)
    assert exchange_depth(*args, 0.01) == exchange_depth(*args, 0.0)  # relaxation faster
    assert exchange_depth(*args, 10.0) > exchange_depth(*args, 0.0)  # relaxation slower


def test_discriminant_agrees_with_roots_on_random_states():
    rng = np.random.default_rng(3)
    for _ in range(3000):
        h1, h2 = rng.uniform(0.01, 2, 2)
        u1, u2 = rng.normal(0, 3, 2)
        r = rng.uniform(0.05, 0.99)
        lam = eigenvalues(h1, h2, u1, u2, 9.81, r)
        scale = np.sqrt(9.81 * (h1 + h2)) + abs(u1 - u2)
        real = abs(lam[1].imag) < 1e-6 * scale
        assert real == (discriminant(h1, h2, u1, u2, 9.81, r) >= 0)
        assert is_hyperbolic(h1, h2, u1, u2, 9.81, r, 1) == real


def test_eigenvalues_of_many_velocities_are_the_roots_one_by_one():
    """One call for an array of du gives, row by row, the roots of P(lambda) that a
    call per du gives; they are roots (|P| small against its scale) sorted by real part."""
    g, h1, h2, r = 9.81, 0.4, 1.1, 0.7
    du = np.linspace(-12.0, 12.0, 97)
    lam = eigenvalues(h1, h2, du, 0.5, g, r)
    assert lam.shape == (97, 4)
    for row, d in zip(lam, du, strict=True):
        one = eigenvalues(h1, h2, d, 0.5, g, r)
        np.testing.assert_allclose(np.sort_complex(row), np.sort_complex(one), atol=1e-12)
        assert np.all(np.diff(row.real) >= -1e-12)
        p = ((row - d) ** 2 - g * h1) * ((row - 0.5) ** 2 - g * h2) - r * g * g * h1 * h2
        assert np.abs(p).max() < 1e-9 * (g * (h1 + h2) + d * d) ** 2


def test_fl_is_a_lower_bound_of_the_exact_threshold():
    rng = np.random.default_rng(4)
    for _ in range(500):
        h1, h2 = rng.uniform(0.05, 2, 2)
        r = rng.uniform(0.1, 0.95)
        fl = lower_bound_fl(h1, h2, 9.81, r)
        assert discriminant(h1, h2, 0.999 * fl, 0.0, 9.81, r) >= 0


@pytest.mark.parametrize("mode", ["exact", "bound"])
def test_fextra_restores_hyperbolicity_and_conserves_momentum(mode):
    n = 20
    eq = pdeflow.TwoLayerGranular(hyperbolicity=mode, phi_b_deg=1e-9, k=0.0, c=0.0)
    g = pdeflow.TwoLayerGranular  # noqa: F841 - keep name for readability
    from .helpers import grid

    st_ = eq.make_state(grid(n), h1=np.full(n, 0.5), u1=np.full(n, 2.5),
                        h2=np.full(n, 0.5), u2=np.zeros(n))
    q = st_.data.copy()
    r = eq.parameters.density_ratio
    assert not is_hyperbolic(0.5, 0.5, 2.5, 0.0, 9.81, r, 1)
    p0 = np.sum(r * q[1] + q[3])
    diag = eq.new_diagnostics(n)
    eq.source_kernel()(q, 1e-3, 1e-3, eq.parameter_array(), diag)
    u1, u2 = q[1] / q[0], q[3] / q[2]
    assert all(is_hyperbolic(q[0, i], q[2, i], u1[i], u2[i], 9.81, r, 1) for i in range(n))
    assert diag[T.D_FEXTRA_MAX] > 0
    assert np.sum(r * q[1] + q[3]) == pytest.approx(p0, rel=1e-12)
    # the smallest correction: |du| ends within w of the boundary F_c1 (exact mode)
    if mode == "exact":
        assert not is_hyperbolic(0.5, 0.5, u1[0] - u2[0] + 2 * eq.parameters.w, 0.0,
                                 9.81, r, 1)


def _edge_by_bisection(h1, h2, du_bad, r):
    lo, hi = 0.0, du_bad
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if discriminant(h1, h2, mid, 0.0, 9.81, r) >= 0:
            lo = mid
        else:
            hi = mid
    return lo


def test_band_lower_edge_is_the_first_non_hyperbolic_du():
    rng = np.random.default_rng(3)
    checked = 0
    for _ in range(400):
        h1, h2 = rng.uniform(0.001, 2.0, 2)
        r = rng.uniform(0.05, 0.999)
        du = np.linspace(lower_bound_fl(h1, h2, 9.81, r), 3 * np.sqrt(9.81 * (h1 + h2)),
                         400)
        bad = [d for d in du if discriminant(h1, h2, d, 0.0, 9.81, r) < 0]
        if not bad:
            continue
        du_bad = bad[rng.integers(len(bad))]
        edge = band_lower_edge(h1, h2, 9.81, r, du_bad)
        assert edge == pytest.approx(_edge_by_bisection(h1, h2, bad[0], r), rel=1e-9)
        assert is_hyperbolic(h1, h2, edge * (1 - 1e-10), 0.0, 9.81, r, 1)
        assert not is_hyperbolic(h1, h2, edge * (1 + 1e-8), 0.0, 9.81, r, 1)
        checked += 1
    assert checked > 100
    assert band_lower_edge(0.5, 0.5, 9.81, 0.8, 0.01) == -1.0  # 0.01 m/s is hyperbolic


@pytest.mark.parametrize("mode", [1, 2])
def test_direct_restoration_is_the_bisection_limit(mode):
    """The closed-form inversion of the friction step lands |du| on the band edge:
    hyperbolic, never more F_extra than bisection to w = 1e-3, and |du| within 1e-8
    (relative) of bisection to w = 1e-12."""
    from pdeflow.models.two_layer.friction import (
        bisect_fextra,
        friction_params,
        implicit_friction,
        restore_hyperbolicity,
    )

    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(300):
        eq = pdeflow.TwoLayerGranular(k=rng.uniform(0, 0.9), c=rng.uniform(0, 0.2),
                                      phi_b_deg=rng.uniform(1e-6, 40),
                                      density_ratio=rng.uniform(0.5, 0.99))
        P = eq.parameter_array()
        P[T.HYPERBOLICITY] = mode
        h1, h2 = rng.uniform(0.01, 1.5, 2)
        b1, b2 = rng.uniform(-8, 8, 2)
        dt = rng.uniform(1e-4, 1e-2)
        kc = (P[T.K], P[T.C])  # the paper's interface stress t1 (no erosion this step)
        fp = friction_params(P)
        v1, v2 = implicit_friction(b1, b2, h1, h2, dt, fp, 0.0, *kc)
        if is_hyperbolic(h1, h2, v1, v2, P[T.G_Z], P[T.R], mode):
            continue
        f, u1, u2, bisected = restore_hyperbolicity(b1, b2, h1, h2, v1, v2, dt, fp, *kc)
        assert not bisected  # the direct solve found it
        assert is_hyperbolic(h1, h2, u1, u2, P[T.G_Z], P[T.R], mode)
        assert (u1, u2) == implicit_friction(b1, b2, h1, h2, dt, fp, f, *kc)
        f_w = bisect_fextra(b1, b2, h1, h2, v1 - v2, dt, fp, *kc)
        assert abs(f) <= abs(f_w) * (1 + 1e-12)
        P[T.W] = 1e-12
        fp = friction_params(P)
        f_fine = bisect_fextra(b1, b2, h1, h2, v1 - v2, dt, fp, *kc)
        du_fine = np.subtract(*implicit_friction(b1, b2, h1, h2, dt, fp, f_fine, *kc))
        assert abs((u1 - u2) - du_fine) <= 2e-8 * abs(du_fine)
        checked += 1
    assert checked > 30


@pytest.mark.parametrize("h1, u1", [(1e-4, 0.2), (0.01, 0.3), (0.1, 1.0), (0.5, 2.0)])
def test_erosion_from_a_stuck_lower_layer_creates_no_momentum(h1, u1):
    """Eroded material enters the upper layer at the lower layer's velocity (upwind
    exchange), so eroding a lower layer that basal friction holds at rest can only slow
    the upper layer: on a flat bed the source stage never adds momentum. (Carrying u1
    instead let the bed's reaction to the eroded mass's acceleration create momentum:
    thin fast films then eroded and slid for ever at large c.)"""
    eq = pdeflow.TwoLayerGranular(phi_b_deg=30, k=0.5, c=3.0)
    r = eq.parameters.density_ratio
    q = np.array([[h1], [h1 * u1], [0.5], [0.0]])
    p0 = r * q[1, 0] + q[3, 0]
    diag = eq.new_diagnostics(1)
    eq.source_kernel()(q, 5e-3, 5e-3, eq.parameter_array(), diag)
    assert diag[T.D_ERODED] > 0  # the closure erodes here
    assert q[3, 0] == 0.0  # the lower layer stays stuck
    assert r * q[1, 0] + q[3, 0] <= p0 * (1 + 1e-12)
    # the velocity of a speck is diluted by what it erodes: it cannot keep sliding
    assert q[1, 0] / q[0, 0] < u1 * h1 / (h1 + diag[T.D_ERODED]) + 1e-12


def test_erosion_keeps_momentum_when_the_lower_layer_slides():
    """With a frictionless bed the exchange and interface stresses only move momentum
    between the layers, whichever velocity the exchanged mass carries."""
    eq = pdeflow.TwoLayerGranular(phi_b_deg=1e-9, k=0.5, c=3.0, hyperbolicity="none")
    r = eq.parameters.density_ratio
    q = np.array([[0.05, 0.3], [0.05 * 1.5, 0.3 * 0.2], [0.5, 0.4], [0.5 * 0.3, 0.4 * 0.1]])
    p0 = np.sum(r * q[1] + q[3])
    diag = eq.new_diagnostics(2)
    eq.source_kernel()(q, 5e-3, 5e-3, eq.parameter_array(), diag)
    assert diag[T.D_ERODED] > 0
    assert np.sum(r * q[1] + q[3]) == pytest.approx(p0, rel=1e-12)
