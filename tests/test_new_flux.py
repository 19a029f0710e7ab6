"""The recipe "Adding a flux" of docs/architecture.md, followed once: a toy interface
flux registered from here (one line), its fluctuations for the single layer written
here, run by ``GranularPDE(scheme=...)`` and the fv-split solver.

The toy flux, "mixed", is a Lax-Friedrichs-type viscosity halfway between HLL's and
Rusanov's: in the polynomial-viscosity form its coefficients are the mean of theirs.
The fluctuations are linear in the coefficients, and all three fluxes share the wave
speeds (so the time step), so one step from a state where every face moves is the mean
of an HLL step and a Rusanov step: a check that the toy kernel is the one that ran.

What a flux needs from the package today: its name and code (``register_flux``), and
each model's fluctuations for that code. A shipped model answers the codes it knows in
its ``flux.fluctuations``; here the single layer's kernels are wrapped (the way a model
outside the package, tests/shallow_water/, brings its own).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import pdeflow
from pdeflow.models.single_layer.kernels import KERNELS
from pdeflow.numerics.compiled import f8, specialise, types
from pdeflow.numerics.hll import hll_coefficients
from pdeflow.numerics.rusanov import rusanov_coefficients
from pdeflow.numerics.scheme import FLUXES, Scheme, SchemeError, register_flux, unregister_flux
from pdeflow.numerics.state import velocity
from pdeflow.variant import Variant
from tests.helpers import grid, step


def fluct_mixed(left, right, g, r, dry):  # pragma: no cover - compiled
    """Single-layer fluctuations ``(D^-, D^+, smax)`` with the mean of HLL's and
    Rusanov's viscosity coefficients (the at-rest rule of every flux kept)."""
    hL, mL = left
    hR, mR = right
    uL = velocity(hL, mL, dry)
    uR = velocity(hR, mR, dry)
    cL = math.sqrt(g * max(hL, 0.0))
    cR = math.sqrt(g * max(hR, 0.0))
    sL = min(uL - cL, uR - cR)
    sR = max(uL + cL, uR + cR)
    smax = max(abs(sL), abs(sR))
    if mL == 0.0 and mR == 0.0:
        dH = hR - hL
        return (0.0, 0.5 * g * hL * dH), (0.0, 0.5 * g * hR * dH), smax
    a0 = mR - mL
    a1 = uR * mR + 0.5 * g * hR * hR - (uL * mL + 0.5 * g * hL * hL)
    h0, h1, _ = hll_coefficients(sL, sR)
    r0, r1, _ = rusanov_coefficients(sL, sR)
    c0 = 0.5 * (h0 + r0)
    c1 = 0.5 * (h1 + r1)
    dm0 = 0.5 * (a0 - c0 * (hR - hL) - c1 * a0)
    dm1 = 0.5 * (a1 - c0 * (mR - mL) - c1 * a1)
    return (dm0, dm1), (a0 - dm0, a1 - dm1), smax


@pytest.fixture(scope="module")
def mixed():
    """The toy flux registered as ``mixed``, and a single-layer PDE class whose
    kernels answer its code."""
    code = register_flux("mixed")
    kernel = specialise(fluct_mixed, types.UniTuple(f8, 2), types.UniTuple(f8, 2), f8, f8,
                        f8, helper=True)

    def fluctuations(flux: int):
        return kernel if flux == code else KERNELS.fluctuations(flux)

    class MixedSingleLayer(pdeflow.SingleLayerGranular):
        system = dataclasses.replace(
            pdeflow.SingleLayerGranular.system,
            kernels=dataclasses.replace(KERNELS, fluctuations=fluctuations,
                                        fluxes=(*KERNELS.fluxes, code)))

    yield MixedSingleLayer
    unregister_flux("mixed")


def test_the_name_reaches_the_scheme_and_the_variant_grammar(mixed):
    assert "mixed" in FLUXES
    scheme = Scheme.parse("mixed/muscl/mc+strang")
    assert scheme.flux == "mixed" and scheme.codes[0] == max(
        pdeflow.numerics.layout.FLUXES.values())
    assert Variant.parse("mixed/first-order@bound").scheme.flux == "mixed"
    with pytest.raises(SchemeError, match="'mixed'"):
        Scheme("nope")  # the one-line error lists the new flux
    with pytest.raises(SchemeError, match="registered already"):
        register_flux("hll")


def test_one_step_is_the_mean_of_hll_and_rusanov(mixed):
    """Every face moves (u = 0.5 m/s everywhere over a depth step, walls): the step of
    the toy flux is the mean of the HLL and Rusanov steps within 1e-12 m (and m^2/s):
    round-off of a few dozen operations on values of order 1. It differs from both by
    far more (the toy kernel ran)."""
    g = grid(40, 0.0, 2.0)
    x = g.axes_coords[0]
    h = np.where(x < 1.0, 1.0, 0.5)
    q = {}
    for flux in ("hll", "rusanov", "mixed"):
        eq = mixed(bc=("wall", "wall"), scheme=f"{flux}/first-order")
        q[flux], t, steps, *_ = step(eq, eq.make_state(g, h=h, u=np.full(40, 0.5)), 1.0,
                                      max_steps=1)
        assert steps == 1
    mean = 0.5 * (q["hll"] + q["rusanov"])
    np.testing.assert_allclose(q["mixed"], mean, rtol=0, atol=1e-12)
    assert np.abs(q["mixed"] - q["hll"]).max() > 1e-4
    assert np.abs(q["mixed"] - q["rusanov"]).max() > 1e-4


@pytest.mark.parametrize("scheme", ["mixed/first-order", "mixed/muscl/mc+strang"])
def test_a_dam_break_runs_with_the_new_flux(mixed, scheme):
    """Through py-pde's ``solve`` with fv-split: a dam break between walls keeps its mass
    (1e-12 relative: the scheme is conservative, only round-off of the sums is left)
    and non-negative depths, and moves."""
    g = grid(100, 0.0, 4.0)
    x = g.axes_coords[0]
    eq = mixed(bc=("wall", "wall"), scheme=scheme, phi_b_deg=20.0)
    state = eq.make_state(g, h=np.where(x < 1.0, 1.0, 0.0))
    final = eq.solve(state, t_range=0.5, solver="fv-split", cfl=0.3, tracker=None)
    assert final.data[0].sum() == pytest.approx(state.data[0].sum(), rel=1e-12)
    assert final.data[0].min() >= 0.0
    assert final.data[0][x > 1.5].max() > 0.01  # the front went past 1.5 m


def test_a_model_without_the_flux_refuses_it(mixed):
    """The shipped single layer has no fluctuations for the toy flux: a one-line error
    names the fluxes it has, before any step (no silent fallback on HLL)."""
    eq = pdeflow.SingleLayerGranular(bc=("wall", "wall"), scheme="mixed/first-order")
    state = eq.make_state(grid(10, 0.0, 1.0), h=np.full(10, 0.1))
    with pytest.raises(ValueError, match=r"flux must be one of \['hll', 'rusanov', "
                                         r"'ifcp'\] for this model, got 'mixed'"):
        eq.solve(state, t_range=0.1, solver="fv-split", tracker=None)
    assert np.array_equal(state.data[0], np.full(10, 0.1))
