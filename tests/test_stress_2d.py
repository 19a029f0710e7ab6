"""Stability under stress on a 2D grid (issue 36, verification 7): random 2D states of
both models, every flux, reconstruction, limiter, splitting and basal law, walls on all
four sides.

The states, parameters and schemes are those of tests/test_stress.py
(:func:`tests.test_stress.scenarios` with ``axes=2``) on 8-16 x 6-12 cells: depths from
1e-8 m to ~3 m with dry cells, dry patches and thin films 1 to 6 decades below their
neighbours, velocities up to ~30 m/s along x, along y or at a random angle per cell,
two-layer shears up to 4 F_R; each basal law with its constants drawn over the app's
ranges (:func:`tests.test_stress.law_parameters`). After *every* fv-split step:

* no NaN or inf, no negative depth (a SimulationBlowUp fails the test);
* dry layers have zero momentum (both components);
* the mass sum (rho1 h1 + rho2 h2) dx dy / rho2 (one layer: sum h dx dy), the quantity
  the exchange conserves (it moves M/rho1 of upper and -M/rho2 of lower depth), is
  conserved to 16 eps per step relative (:func:`tests.test_stress.check_step_invariants`,
  as in 1D: walls pass no mass, each face's mass fluctuations sum to the jump of the
  mass flux, so only the roundings of the cell updates and of the sum remain, a few
  eps of the total per step: measured at most 2.7 eps per step over 300 states; at
  most 30 steps, so the bound is 1.1e-13, well inside the 1e-12 of the 2D runs' mass
  checks).

A state mirrored across the slope (y -> W - y, v -> -v) gives the mirrored run, to
round-off (:data:`MIRROR_TOLERANCE`; not bit for bit).

Default suite (``python -m pytest tests/test_stress_2d.py``): 12 of the 36 variants
(model x flux x first order / MUSCL-minmod / MUSCL-mc x Lie / Strang), each with one
law, every law meeting every choice (:data:`DEFAULT`), 3 random states each, and 20
mirrored pairs of the same variants. The long run (``-m slow``: all 144 combinations of variant and
law, 70 states each, 10080 in all, and 500 mirrored pairs)::

    python -m pytest tests/test_stress_2d.py -m slow -p no:randomly

One finding is not shown closed (xfail, not strict): :data:`STRANG_WAKES_CELLS`.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, note, settings
from hypothesis import strategies as st

from pdeflow.analysis.positivity import FLUXES, SCHEMES
from pdeflow.models.friction_laws import LAWS
from tests.test_stress import (
    PROFILE,
    T_FAR,
    Scenario,
    check_invariants_step_by_step,
    law_parameters,
    no_swallowed_exceptions,
    scenarios,
    stepper_for,
)

LAW_NAMES = tuple(LAWS)  #: the shipped laws, read once (a test may register its own)
VARIANTS = [(two, flux, rec, limiter, splitting)
            for two in (True, False) for flux in FLUXES for rec, limiter in SCHEMES
            for splitting in ("lie", "strang")]
"""every (two-layer?, flux, reconstruction, limiter, splitting) of the 2D runs (36)"""
DEFAULT = [(bool((law + (k == 2)) % 2), FLUXES[k], *SCHEMES[(law + 2 * k) % 3],
            ("lie", "strang")[(law + k) % 2], LAW_NAMES[law])
           for k in range(len(FLUXES)) for law in range(len(LAW_NAMES))]
"""the default suite's 12 variants, each with one law: row (flux k, law l) has
reconstruction (l + 2k) mod 3, two layers if l + [k = 2] is odd, Strang if l + k is odd,
so that every law meets every model, flux, reconstruction/limiter and splitting
(test_every_law_meets_every_choice). A variant costs its first step a compilation of
its stepping loop (~8 s on a cold numba cache, milliseconds from then on), so the
default suite compiles 12 of the 36 steppers; the slow run has all 144 pairs."""
PER_VARIANT = 3  #: random states per variant in the default suite
PER_VARIANT_SLOW = 70  #: ... per variant and law in the slow run (144 x 70 = 10080)


@st.composite
def scenarios_2d(draw, law: str | None = None, **fixed) -> Scenario:
    """A random 2D scenario (``fixed`` as :func:`tests.test_stress.scenarios`) with the
    basal law ``law`` (drawn if None) and its constants."""
    scenario = draw(scenarios(axes=2, **fixed))
    scenario.params.update(draw(law_parameters(law or draw(st.sampled_from(LAW_NAMES)))))
    return scenario


def variant_id(two, flux, rec, limiter, splitting, law=None) -> str:
    """e.g. ``two/hll/muscl/mc+strang-voellmy`` (the test ids)."""
    rec = f"{rec}/{limiter}" if rec == "muscl" else rec
    return f"{'two' if two else 'one'}/{flux}/{rec}+{splitting}" + (f"-{law}" if law else "")


def check_2d(variant: tuple, law: str, data: st.DataObject, n_steps: int) -> None:
    """Draw a state of ``variant`` (:data:`VARIANTS`) with the basal law ``law`` and
    run it ``n_steps`` single fv-split steps, checking the invariants (module docstring)
    after each; a SimulationBlowUp fails."""
    two, flux, rec, limiter, splitting = variant
    scenario = data.draw(scenarios_2d(law, two=two, flux=flux, reconstruction=rec,
                                      limiter=limiter, splitting=splitting))
    eq, state = scenario.make()
    note(repr(scenario))  # one line; hypothesis prints the draw with its profiles
    check_invariants_step_by_step(eq, state, scenario.cfl, scenario.splitting, n_steps)


@pytest.mark.parametrize("case", DEFAULT, ids=[variant_id(*c) for c in DEFAULT])
@settings(PROFILE, max_examples=min(PROFILE.max_examples, PER_VARIANT))
@given(data=st.data(), n_steps=st.integers(5, 30))
def test_random_2d_states_keep_the_invariants(case, data, n_steps):
    """Each variant with its law of :data:`DEFAULT`, 3 random states of 5-30 steps:
    the invariants of the module docstring after every step."""
    check_2d(case[:-1], case[-1], data, n_steps)


STRANG_WAKES_CELLS = (
    "Strang's first half source step can wake cells at the edge of the live box, whose "
    "fluctuations may reach a cell outside it (test_strang_half_step_that_wakes_cells_"
    "keeps_the_mass: fixed for its state by the box windows, not shown in general)")
"""the finding of the slow run that is not shown closed (docs/two_d.md)"""


def slow_case(variant: tuple, law: str):
    """``(variant, law)`` of the slow test, marked xfail (not strict) where a finding is
    not shown closed: its stored state passes since the box windows, the general case
    is not shown."""
    if variant_id(*variant, law) == "two/ifcp/first-order+strang-coulomb":
        return pytest.param(variant, law, marks=pytest.mark.xfail(
            strict=False, reason=STRANG_WAKES_CELLS))
    return pytest.param(variant, law)


@pytest.mark.slow
@pytest.mark.parametrize("variant, law", [slow_case(v, law) for v in VARIANTS
                                          for law in LAW_NAMES],
                         ids=[variant_id(*v, law) for v in VARIANTS for law in LAW_NAMES])
@settings(PROFILE, max_examples=PER_VARIANT_SLOW)
@given(data=st.data(), n_steps=st.integers(5, 30))
def test_random_2d_states_keep_the_invariants_every_law(variant, law, data, n_steps):
    """:func:`test_random_2d_states_keep_the_invariants` for every variant with every
    law, 70 states each (10^4 in all, as the 1D stress's long run)."""
    check_2d(variant, law, data, n_steps)


def test_every_law_meets_every_choice():
    """The default suite's pairing (:data:`DEFAULT`) runs each law with each model,
    flux, reconstruction/limiter and splitting, on distinct variants."""
    assert len({c[:-1] for c in DEFAULT}) == len(DEFAULT)
    assert {c[:-1] for c in DEFAULT} <= set(VARIANTS)
    for k in range(len(VARIANTS[0])):
        choices = {v[k] for v in VARIANTS}
        assert {(c[k], c[-1]) for c in DEFAULT} == {(a, b) for a in choices
                                                    for b in LAW_NAMES}, k


def mirrored(scenario: Scenario) -> Scenario:
    """``scenario`` reflected across the slope: every profile read from y = W - y, the
    cross-slope velocities v, v1, v2 negated."""
    profiles = {k: (-p if k.startswith("v") else p)[:, ::-1].copy()
                for k, p in scenario.profiles.items()}
    return Scenario(scenario.two_layer, scenario.params, scenario.scheme, scenario.splitting,
                    scenario.cfl, scenario.length, profiles, scenario.geometry,
                    scenario.width)


MIRROR_TOLERANCE = {False: 1e-12, True: 1e-9}
"""|difference| allowed between a run and its mirrored run, relative to the largest
|value| of each field (and for the times) [-], by two-layer or not. Not bit for bit: a
cell adds its low and high y-faces' terms in the same order however the state is
mirrored, so mirrored cells round differently (measured over 150 runs of both models:
22 bit-identical, the others within 7e-14 after up to 30 steps). The two-layer model's
restoration and friction iterate (bisection, Newton) and its flow amplifies that
round-off: the slow run found 6.5e-11 after 18 steps (paper closure, MUSCL), within
the 1e-9 of its x <-> y mirror (tests/test_two_d_two_layer_pde.py, docs/two_d.md)."""


def check_mirror(scenario: Scenario, n_steps: int) -> None:
    """Run ``scenario`` and :func:`mirrored` ``n_steps`` single fv-split steps each:
    the times and the final state, read back from y = W - y with hv negated, agree to
    :data:`MIRROR_TOLERANCE` of its model."""
    note(repr(scenario))
    runs = []
    for s in (scenario, mirrored(scenario)):
        eq, state = s.make()
        stepper = stepper_for(eq, state, s.cfl, s.splitting)
        t, times = 0.0, []
        for _ in range(n_steps):
            with no_swallowed_exceptions():
                t = stepper(state, t, T_FAR)
            times.append(t)
        runs.append((np.array(times), state.data))
    (t1, q1), (t2, q2) = runs
    back = q2[:, :, ::-1].copy()
    back[2::3] *= -1.0  # the cross-slope momenta
    tolerance = MIRROR_TOLERANCE[scenario.two_layer]
    np.testing.assert_allclose(t2, t1, rtol=tolerance, atol=0.0)
    scale = np.abs(q1).max(axis=(1, 2))
    assert np.all(np.abs(back - q1).max(axis=(1, 2)) <= tolerance * scale), \
        np.abs(back - q1).max(axis=(1, 2)) / np.where(scale > 0, scale, 1.0)


@st.composite
def default_scenarios(draw) -> Scenario:
    """A random 2D scenario of one of the :data:`DEFAULT` variants (whose steppers the
    default suite compiles anyway), with any law."""
    two, flux, rec, limiter, splitting, _ = draw(st.sampled_from(DEFAULT))
    return draw(scenarios_2d(None, two=two, flux=flux, reconstruction=rec,
                             limiter=limiter, splitting=splitting))


@settings(PROFILE, max_examples=min(PROFILE.max_examples, 20))
@given(default_scenarios(), st.integers(5, 20))
def test_a_state_mirrored_across_the_slope_gives_the_mirrored_run(scenario, n_steps):
    """A random 2D state of a :data:`DEFAULT` variant, any law, and its mirror image
    across the slope give mirrored runs (:func:`check_mirror`)."""
    check_mirror(scenario, n_steps)


@pytest.mark.slow
@settings(PROFILE, max_examples=500)
@given(scenarios_2d(), st.integers(5, 30))
def test_a_state_mirrored_across_the_slope_gives_the_mirrored_run_long(scenario, n_steps):
    """:func:`test_a_state_mirrored_across_the_slope_gives_the_mirrored_run` on 500
    states."""
    check_mirror(scenario, n_steps)


def test_friction_newton_stops_where_the_lower_layer_is_stuck_to_round_off():
    """Found by test_random_2d_states_keep_the_invariants_every_law (slow run,
    two/hll/first-order+strang-mu_i: layers of ~1e-5 m, r = 0.064, exchange 'none'; the
    hypothesis blob is in the report of issue 36's verification 7). One cell's implicit
    friction (velocities b [m/s], m1 = r h1 and m2 = h2 [m], the interface's K dt = 0
    and C dt, the bed's B dt [m^2/s]): the lower layer is pushed just past its bound, so
    the 2D Newton step solves for its velocity, whose iterates fall to |u2| ~ 1e-18 m/s.
    There the Hessian's B dt/|u2| term (~1e10 m) makes it rank one to round-off, its
    determinant rounded to 0, and the compiled kernel raised ZeroDivisionError; inside
    the stepper numba swallowed it and left the source stage half done (dry cells kept
    their momentum). Newton now stops at that iterate, the minimum to round-off."""
    from pdeflow.models.two_layer.friction_2d import _upper_over, friction_two_layer_2d
    from pdeflow.numerics.compiled import ready

    b1x, b1y, b2x, b2y = (0.008141392258105819, -0.013373215375611494,
                          0.005889556549602334, -0.0024680719583932125)
    m1, m2, kdt, cdt, bdt = (2.9497088043108923e-07, 3.3266591051888287e-06, 0.0,
                             1.9479721315184736e-06, 2.156737456542439e-08)
    u1x, u1y, u2x, u2y = ready(friction_two_layer_2d)(b1x, b1y, b2x, b2y, m1, m2, kdt,
                                                      cdt, bdt)
    assert np.hypot(u2x, u2y) < 1e-15  # stuck, to round-off
    # the upper layer slides over it as over a lower layer at rest
    s, nx, ny, _, _ = ready(_upper_over)(0.0, 0.0, b1x, b1y, m1, kdt, cdt)
    np.testing.assert_allclose([u1x, u1y], [s * nx, s * ny], rtol=1e-12)


def test_strang_half_step_that_wakes_cells_keeps_the_mass():
    """Found by test_random_2d_states_keep_the_invariants_every_law (slow run,
    two/ifcp/first-order+strang-coulomb; tests/data/stress_2d_strang_wakes_cells.npz):
    two thin layers (h1, h2 <= 7.5e-7 m, below the dry tolerance of 1e-6 m in most
    cells) on a 10 x 10 grid of 0.1 m, theta = phi_b = 10 deg, r = 0.75, the paper's
    closure, Strang, CFL 0.28. On the loop's row windows (ddc5339) step 3 lost 1.9e-5
    of the mass r h1 + h2 (HLL too; Lie, or exchange 'none', kept it to round-off): the
    window was the rows within reach of the cells live after the last step (cells
    8..56, so b = 0..76), Strang's first half source step woke cells at rest that were
    not live (the deposit lifts sub-dry layers above the dry tolerance, and at theta =
    phi_b they slide: cells 38, 48, 58, 68 of column 8), and their fluctuations reached
    cell 78, outside the window: the face 68|78 was applied to cell 68 only. The box
    windows (numerics/boxes.py: rows x columns within reach of the live cells) hold
    cell 78, and every step keeps the mass. The 1D stress draws no Strang two-layer
    state with exchange (tests/test_stress.py); 1500 such 1D states drawn for this
    finding, and the 1D runs along each line of this state, kept the mass."""
    from pathlib import Path

    profiles = dict(np.load(Path(__file__).parent / "data" /
                            "stress_2d_strang_wakes_cells.npz"))
    params = {"phi_b_deg": 10.0, "theta_deg": 10.0, "density_ratio": 0.75,
              "phi_int_deg": 10.0, "k": 0.0, "c": 1.0, "exchange_closure": "paper"}
    scenario = Scenario(True, params, {"flux": "ifcp", "reconstruction": "first-order"},
                        "strang", 0.28125, 1.0, profiles, "planar", 1.0)
    eq, state = scenario.make()
    check_invariants_step_by_step(eq, state, scenario.cfl, scenario.splitting, 5)
