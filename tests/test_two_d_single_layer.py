"""The single-layer model on a 2D CartesianGrid (issue 36, first step): its 2D kernels
(pdeflow/models/single_layer/two_d.py, sources_2d.py) and the py-pde shell on a 2D grid.

A state without cross-slope momentum (v = 0) gives the 1D arithmetic: the fluctuations
across a face add zero tangential momentum, and the vector friction step u* / |u*| s_new
is +-s_new exactly when v = 0 (sqrt(u*u) == |u| in IEEE arithmetic).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pdeflow.models import SingleLayerParameters
from pdeflow.models.friction_laws import LAWS
from pdeflow.models.single_layer.kernels import kernels, kernels_2d
from pdeflow.numerics import layout as L

RNG = np.random.default_rng(36)
LAW_NAMES = ("coulomb", "pouliquen", "mu_i", "voellmy")


def _parameters(law: str, theta: float = 25.0) -> tuple[np.ndarray, object]:
    """(parameter vector, basal law's kernels or None) of a single layer with ``law``."""
    p = SingleLayerParameters(theta_deg=theta, phi_b_deg=20.0, friction_law=law)
    return p.to_array(), (None if law == "coulomb" else LAWS[law].kernels)


@pytest.mark.parametrize("law", LAW_NAMES)
def test_v_zero_sources_are_the_1d_arithmetic(law):
    """On 400 random cells (depths 0..1 m, some dry, speeds up to 3 m/s either way, some
    at rest) with v = 0, the 2D source stage, MUSCL predictor and method-of-lines rate
    write exactly the 1D kernels' numbers into (h, hu) and leave hv at 0; exact
    comparison, since the 2D arithmetic reduces to the 1D one when v = 0 (module
    docstring)."""
    P, basal = _parameters(law)
    one, two = kernels(basal), kernels_2d(basal)
    n = 400
    h = RNG.uniform(0, 1, n) * (RNG.uniform(0, 1, n) > 0.1)
    u = RNG.uniform(-3, 3, n) * (RNG.uniform(0, 1, n) > 0.2)
    q1 = np.stack([h, h * u])
    q2 = np.stack([h, h * u, np.zeros(n)])
    d1, d2 = np.zeros(L.N_DIAG + n), np.zeros(L.N_DIAG + n)
    one.source_stage(q1, 0.01, 0.01, P, d1)
    two.source_stage(q2, 0.01, 0.01, P, d2)
    assert np.array_equal(q2[:2], q1) and not np.any(q2[2])
    assert np.array_equal(d1, d2)
    q1 = np.stack([h, h * u])
    q2 = np.stack([h, h * u, np.zeros(n)])
    one.predictor(q1, 0.05, P, 0, n - 1)
    two.predictor(q2, 0.05, P, 0, n - 1)
    assert np.array_equal(q2[:2], q1) and not np.any(q2[2])
    r1, r2 = np.zeros((2, n)), np.zeros((3, n))
    one.mol_sources(np.stack([h, h * u]), r1, P)
    two.mol_sources(np.stack([h, h * u, np.zeros(n)]), r2, P)
    assert np.array_equal(r2[:2], r1) and not np.any(r2[2])


def test_vector_coulomb_friction_opposes_the_velocity():
    """Horizontal (theta = 0), Coulomb mu = tan 20 deg: a cell moving at speed s in a
    random direction keeps its direction and leaves the step at max(s - dt g mu, 0)
    (relative 1e-14: a few roundings of the direction and the product); below the
    threshold the cell stops exactly (set-valued)."""
    P, _ = _parameters("coulomb", theta=0.0)
    stage = kernels_2d(None).source_stage
    dt, n = 0.02, 200
    mu_dt = dt * P[L.G_Z] * math.tan(math.radians(20.0))
    s = RNG.uniform(0, 4 * mu_dt, n)
    a = RNG.uniform(0, 2 * math.pi, n)
    h = np.full(n, 0.5)
    q = np.stack([h, h * s * np.cos(a), h * s * np.sin(a)])
    stage(q, dt, dt, P, np.zeros(L.N_DIAG + n))
    speed = np.hypot(q[1], q[2]) / h
    expected = np.maximum(s - mu_dt, 0.0)
    assert np.allclose(speed, expected, rtol=1e-14, atol=0.0)
    moving = expected > 0
    assert np.allclose(np.arctan2(q[2], q[1])[moving] % (2 * math.pi), a[moving],
                       rtol=1e-13, atol=1e-13)
    assert not np.any(q[1:, ~moving])
    assert 40 < moving.sum() < 180  # both branches are exercised


# --- the py-pde shell on a 2D grid: GranularPDE.solve with fv-split -------------------

N = 40  #: cells along the flow
DX = 0.125  #: cell width along both axes [m] (a power of 2: both grids get it exactly)
ACROSS = 3  #: cells across the flow
CFL = 0.2  #: the 1D run's; the 2D run takes 2 CFL (test_two_d_loop.py's module docstring)
SCHEMES = [f"{flux}/{rec}+{split}" for flux in ("hll", "rusanov", "ifcp")
           for rec in ("first-order", "muscl/minmod", "muscl/mc")
           for split in ("lie", "strang")]
QUICK = ["hll/first-order+lie", "rusanov/muscl/minmod+strang", "ifcp/muscl/mc+lie"]


def _dam_break() -> tuple[np.ndarray, np.ndarray]:
    """A column (1 m) beside a smaller heap at rest (0.3 m) and dry cells [m, m/s]."""
    x = (np.arange(N) + 0.5) * DX
    h = np.where(x < 1.5, 1.0, np.where((x > 3.0) & (x < 3.5), 0.3, 0.0))
    return h, np.where(x < 1.5, 0.2, 0.0)


def _uniform_across(scheme: str, law: str, rotated: bool, slope: bool = True) -> None:
    """The 2D run uniform across the flow (along y; rotated: along x, the flow along y)
    against the 1D run: same steps, every cell of every line equal, no cross momentum.
    On the slope (``slope``) rotated, the plane is inclined along y (azimuth 90 deg)."""
    from pde import CartesianGrid

    from pdeflow.models import SingleLayerGranular

    theta = 25.0 if slope else 0.0
    h, u = _dam_break()
    kw = {"theta_deg": theta, "phi_b_deg": 20.0, "friction_law": law, "scheme": scheme}
    one = SingleLayerGranular(bc=("wall", "open"), **kw)
    st1, info1 = one.solve(one.make_state(CartesianGrid([[0, N * DX]], N), h=h, u=u), 0.6,
                           solver="fv-split", cfl=CFL, tracker=None, ret_info=True)
    if rotated:
        grid = CartesianGrid([[0, ACROSS * DX], [0, N * DX]], [ACROSS, N])
        bc = (("open", "wall"), ("wall", "open"))
        profiles = {"h": np.tile(h, (ACROSS, 1)), "v": np.tile(u, (ACROSS, 1))}
    else:
        grid = CartesianGrid([[0, N * DX], [0, ACROSS * DX]], [N, ACROSS])
        bc = (("wall", "open"), ("wall", "open"))
        profiles = {"h": np.repeat(h[:, None], ACROSS, 1), "u": np.repeat(u[:, None], ACROSS, 1)}
    two = SingleLayerGranular(bc=bc, slope_azimuth_deg=90.0 if rotated else 0.0, **kw)
    st2, info2 = two.solve(two.make_state(grid, **profiles), 0.6, solver="fv-split",
                           cfl=2 * CFL, tracker=None, ret_info=True)
    assert info2["solver"]["steps"] == info1["solver"]["steps"]
    q = st2.data
    for j in range(ACROSS):
        line = (q[0, j, :], q[2, j, :], q[1, j, :]) if rotated else \
            (q[0, :, j], q[1, :, j], q[2, :, j])
        assert np.array_equal(line[0], st1.data[0]), (scheme, law, rotated, j)
        assert np.array_equal(line[1], st1.data[1]), (scheme, law, rotated, j)
        assert not np.any(line[2]), (scheme, law, rotated, j)
    assert np.any(st1.data[1]) and st1.data[0].max() < 1.0  # the dam did break


@pytest.mark.parametrize("law", ["coulomb", "pouliquen"])
@pytest.mark.parametrize("scheme", QUICK)
def test_uniform_across_gives_the_1d_run(scheme, law):
    """A dam break on a 25 deg slope uniform in y, and rotated (uniform in x, the flow
    along y: horizontal, and on the plane inclined along y, ``slope_azimuth_deg`` = 90),
    through GranularPDE.solve with fv-split: the 1D run's numbers bit for bit (exact
    comparison: the faces across carry exactly zero fluctuations, gravity across the
    flow is exactly 0 and the vector friction is the 1D arithmetic when the velocity
    lies along one axis), with the same number of steps."""
    for rotated, slope in ((False, True), (True, False), (True, True)):
        _uniform_across(scheme, law, rotated, slope)


@pytest.mark.slow
@pytest.mark.parametrize("law", ["coulomb", "mu_i", "voellmy"])
@pytest.mark.parametrize("scheme", [s for s in SCHEMES if s not in QUICK])
def test_uniform_across_gives_the_1d_run_every_scheme(scheme, law):
    """:func:`test_uniform_across_gives_the_1d_run` for every flux, reconstruction and
    splitting and the other laws."""
    for rotated, slope in ((False, True), (True, False), (True, True)):
        _uniform_across(scheme, law, rotated, slope)


def _square(n: int, side: float):
    from pde import CartesianGrid

    grid = CartesianGrid([[0, side], [0, side]], [n, n])
    x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
    return grid, np.hypot(x - side / 2, y - side / 2)


@pytest.mark.parametrize("theta, azimuth", [(0.0, 0.0), (5.0, 0.0), (5.0, 30.0)])
@pytest.mark.parametrize("scheme", ["hll/first-order", "hll/muscl/mc+strang"])
def test_a_cone_below_the_friction_angle_stays_at_rest(theta, azimuth, scheme):
    """A cone (0.5 m high, sides at 10 deg) on a plane at theta = 0 and 5 deg, inclined
    along x and along 30 deg from x (``slope_azimuth_deg``), with a 30 deg basal friction
    angle: the drive, at most g (sin theta + cos theta tan 10 deg), stays
    below the friction g cos theta tan 30 deg everywhere, so the set-valued friction
    holds every cell. 100 s of fv-split (not stopped at rest): every value is unchanged
    and the momenta are 0, exactly: the claim is exact rest (a cell at rest moves no
    mass through its faces, and the friction sets its velocity to exactly 0)."""
    from pdeflow.models import SingleLayerGranular

    grid, r = _square(24, 3.0)
    h = np.maximum(0.5 - r * math.tan(math.radians(10.0)), 0.0)
    eq = SingleLayerGranular(theta_deg=theta, phi_b_deg=30.0, scheme=scheme,
                             slope_azimuth_deg=azimuth, bc=("open", "open"))
    state = eq.make_state(grid, h=h)
    out, info = eq.solve(state, 100.0, solver="fv-split", stop_at_rest=False, tracker=None,
                         ret_info=True)
    assert info["solver"]["steps"] > 1000
    assert np.array_equal(out.data[0], h)
    assert not np.any(out.data[1:])
    # stopped at rest (the default), fv-split ends the run itself in its first step
    out, info = eq.solve(state, 100.0, solver="fv-split", tracker=None, ret_info=True)
    assert info["solver"]["steps"] == 1 and info["solver"]["rest_time"] < 0.1
    assert np.array_equal(out.data[0], h) and not np.any(out.data[1:])


@pytest.mark.parametrize("law", ["coulomb", "voellmy"])
@pytest.mark.parametrize("scheme", ["hll/first-order", "hll/muscl/mc"])
def test_radial_collapse_mass_positivity_and_symmetry(scheme, law):
    """A cylinder column (radius 0.5 m, 1 m deep) in a 2 m x 2 m box with walls on all
    sides, horizontal (theta = 0), friction angle 15 deg, 1.5 s: the mass stays to
    round-off (relative 1e-12: sums of 1600 cells over a few hundred steps, each face's
    mass fluctuations adding to the jump of the mass flux, zero at a wall), no depth is
    negative, and the state is symmetric under x <-> y to round-off (1e-12 m, m^2/s:
    the x- and y-faces add their terms to a cell in a different order, a few units of
    1e-16 per step)."""
    from pdeflow.models import SingleLayerGranular

    grid, r = _square(40, 2.0)
    h = np.where(r < 0.5, 1.0, 0.0)
    eq = SingleLayerGranular(phi_b_deg=15.0, friction_law=law, scheme=scheme,
                             bc=("wall", "wall"))
    out = eq.solve(eq.make_state(grid, h=h), 1.5, solver="fv-split", tracker=None)
    f = out.data
    assert abs(f[0].sum() - h.sum()) <= 1e-12 * h.sum()
    assert f[0].min() >= 0.0
    assert np.abs(f[0] - f[0].T).max() <= 1e-12
    assert np.abs(f[1] - f[2].T).max() <= 1e-12
    assert f[0, 20, 20] < 0.7 and f[0, 20, 5] > 0.01  # the column spread


def test_method_of_lines_rate_and_a_py_pde_solver():
    """py-pde's own solvers integrate the 2D model through the compiled method-of-lines
    rate: on a state uniform in y it is the 1D rate exactly (the faces across add 0,
    the regularised friction along (u, 0) is the 1D sgn), and py-pde's explicit Euler
    (its compiled fixed-step loop, which keeps its own reference to the state: the
    post-step hook must write in place) over 0.2 s (dt 1 ms) gives the 1D run's numbers
    exactly; with walls the mass stays to round-off (relative 1e-12)."""
    from pde import CartesianGrid

    from pdeflow.models import SingleLayerGranular

    h, u = _dam_break()
    eq = SingleLayerGranular(theta_deg=25.0, phi_b_deg=20.0, bc=("wall", "wall"))
    st1 = eq.make_state(CartesianGrid([[0, N * DX]], N), h=h, u=u)
    grid = CartesianGrid([[0, N * DX], [0, ACROSS * DX]], [N, ACROSS])
    st2 = eq.make_state(grid, h=np.repeat(h[:, None], ACROSS, 1),
                        u=np.repeat(u[:, None], ACROSS, 1))
    rate1 = eq.make_evolution_rate(st1, "numba")(st1.data, 0.0)
    rate2 = eq.make_evolution_rate(st2, "numba")(st2.data, 0.0)
    for j in range(ACROSS):
        assert np.array_equal(rate2[:2, :, j], rate1)
    assert not np.any(rate2[2]) and np.any(rate1[1])
    kw = {"solver": "euler", "dt": 1e-3, "backend": "numba", "tracker": None}
    out1 = eq.solve(st1, 0.2, **kw)
    out2 = eq.solve(st2, 0.2, **kw)
    for j in range(ACROSS):
        assert np.array_equal(out2.data[0, :, j], out1.data[0])
        assert np.array_equal(out2.data[1, :, j], out1.data[1])
    assert not np.any(out2.data[2])
    assert abs(out2.data[0].sum() - ACROSS * h.sum()) <= 1e-12 * ACROSS * h.sum()
    assert out1.data[0, 0] < 0.9  # it flowed


def test_bad_2d_input_gets_a_one_line_error():
    """A 1D profile on a 2D grid, an array of the wrong shape, a cross-slope velocity on
    a 1D grid, boundaries per axis on a 1D grid, a model without 2D kernels (the tests'
    1D shallow water) on a 2D grid, a negative depth in a 2D state (named by its cell
    (i, j) and position): each a one-line ValueError naming the parameter, before any
    work."""
    from pde import CartesianGrid

    from pdeflow.models import SingleLayerGranular
    from tests.shallow_water.model import ShallowWater

    grid = CartesianGrid([[0, 1.0], [0, 0.5]], [8, 4])
    eq = SingleLayerGranular()
    cases = [
        (lambda: eq.make_state(grid, h=np.ones(8)), r"^h must have shape \(8, 4\), got \(8,\)"),
        (lambda: eq.make_state(grid, h=np.ones((8, 4)), v=np.ones((4, 8))),
         r"^v must have shape \(8, 4\), got \(4, 8\)"),
        (lambda: eq.make_state(CartesianGrid([[0, 1.0]], 8), h=np.ones(8), v=np.ones(8)),
         r"^unknown profile\(s\) \['v'\]"),
        (lambda: SingleLayerGranular(bc=(("wall", "open"), ("wall", "wall"))).make_state(
            CartesianGrid([[0, 1.0]], 8), h=np.ones(8)), r"^bc gives a pair per axis"),
        (lambda: SingleLayerGranular(bc=(("wall", "shut"), ("wall", "wall"))),
         r"^bc must be a pair of 'wall' or 'open'"),
        (lambda: ShallowWater().make_state(grid, h=np.ones((8, 4))),
         r"^grid must be a 1D CartesianGrid or a PolarSymGrid"),
    ]
    bad = eq.make_state(grid, h=np.ones((8, 4)))
    bad.data[0, 2, 1] = -0.5
    cases.append((lambda: eq.solve(bad, 0.1, solver="fv-split", tracker=None),
                   r"^h must be >= 0 m, got -0.5 in cell \(2, 1\) \(x=0.3125 m, "
                   r"y=0.1875 m\) and 0 more$"))
    for make, message in cases:
        with pytest.raises(ValueError, match=message) as err:
            make()
        assert "\n" not in str(err.value)


def _paraboloid_error(n: int, scheme: str) -> float:
    """Relative L1 error [-] of the depth at t = 0.5 s of the frictionless spreading
    paraboloid (see :func:`test_frictionless_spreading_paraboloid`) on an n x n grid."""
    from pdeflow.models import SingleLayerGranular

    g, h0, r0, t = 9.81, 1.0, 1.0, 0.5
    grid, r = _square(n, 6.0)
    # phi_b must lie in (0, 90) deg: 1e-6 deg is a deceleration of 2e-7 m/s^2, against
    # accelerations of order g in the cap
    eq = SingleLayerGranular(phi_b_deg=1e-6, scheme=scheme, bc=("open", "open"))
    out = eq.solve(eq.make_state(grid, h=h0 * np.maximum(1 - (r / r0) ** 2, 0.0)), t,
                   solver="fv-split", cfl=0.4, tracker=None)
    big_r = math.sqrt(r0**2 + 2 * g * h0 * t**2)
    exact = h0 * (r0 / big_r) ** 2 * np.maximum(1 - (r / big_r) ** 2, 0.0)
    return float(np.abs(out.data[0] - exact).sum() / exact.sum())


@pytest.mark.parametrize(("scheme", "order"), [("hll/first-order", 0.7),
                                               ("hll/muscl/mc", 1.2)])
def test_frictionless_spreading_paraboloid(scheme, order):
    """The self-similar spreading paraboloid on a horizontal plane, exact for the
    frictionless shallow-water equations: h = H0 (R0/R)^2 (1 - r^2/R^2), u = r R'/R with
    R R'' = 2 g H0 (R0/R)^2, R(0) = R0, R'(0) = 0 (put u = r R'/R and h into u_t + u u_r
    + g h_r = 0 and the mass balance of the radial flow; the radial, k = 1 case of the
    planar/radial family h = H0 (R0/R)^(k+1) (1 - r^2/R^2)), which integrates in closed
    form to R(t) = sqrt(R0^2 + 2 g H0 t^2); the same cap on a flat 2D grid. H0 = R0 =
    1 m, t = 0.5 s (R = 2.43 m), on 6 m x 6 m with 40^2, 80^2, 160^2 cells (about 2 s in
    all): the relative L1 error of the depth falls on each halving of the cells at the
    observed order ``order`` or better (measured: 0.85, 0.89 first order; 1.58, 1.39
    MUSCL, whose second order the kinks of the dry fronts cap)."""
    errors = [_paraboloid_error(n, scheme) for n in (40, 80, 160)]
    assert errors[0] < 0.2, errors
    orders = [math.log2(a / b) for a, b in zip(errors, errors[1:], strict=False)]
    assert min(orders) >= order, (errors, orders)
