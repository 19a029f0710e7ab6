r"""The two-layer system (24) at a face: its states, fluctuations and MUSCL cell jump.

The fluctuations are those of :mod:`pdeflow.numerics.pvm` (polynomial-viscosity form)
with the model's path-conservative total jump (the coupling g_z h1bar Delta h2 and
g_z r h2bar Delta h1 of (24)), its wave-speed bounds (:mod:`pdeflow.numerics.hll`) and
the at-rest rule, compiled for one flux at a time (:func:`fluctuations`); a face's
states are tuples ``(h1, h1u1, h2, h2u2)`` (:func:`face`).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from ...numerics import layout as L
from ...numerics.compiled import cached, f8, specialise, types
from ...numerics.hll import hll_coefficients
from ...numerics.ifcp import ifcp_coefficients
from ...numerics.pvm import roe_velocity
from ...numerics.rusanov import rusanov_coefficients
from ...numerics.state import velocity

IFCP_MIN_FRACTION = 0.05
"""IFCP is used where every layer on both sides is at least this fraction of the total
depth; elsewhere (near a layer's front or where a layer thins out) the HLL line."""


@cached
def upper_layer_at_uncovered_step(h1L: float, u1L: float, sL: float, h1R: float,
                                  u1R: float, sR: float, jump: float, c0: float,
                                  c1: float, e0: float, e1: float, dry: float
                                  ) -> tuple[float, float, float, float]:
    r"""Upper-layer fluctuations ``(D^-_h1, D^-_h1u1, D^+_h1, D^+_h1u1)`` at a face where
    the lower layer is at rest on both sides and its step is not covered by the upper
    layer: on one side h1 + h2 <= max(h2L, h2R) (or that side has no upper layer).

    ``sL``, ``sR`` [m] are the upper layer's depths above the top of the step,
    s = max(h1 + h2 - max(h2L, h2R), 0) <= h1 (hydrostatic reconstruction over the
    bed b = h2: Audusse, Bouchut, Bristeau, Klein & Perthame 2004; for the
    path-conservative scheme, the emerged-step wet/dry front of Castro, Ferreiro,
    Garcia, Gonzalez & Pares 2005); ``jump`` the path-conservative momentum jump
    Delta(h1 u1^2) + g_z h1bar Delta H of (24) [m^3/s^2]; ``c0``, ``c1`` the flux's
    viscosity coefficients; ``e0``, ``e1`` IFCP's alpha2 terms (else 0), kept as they
    are; ``dry`` [m] the dry tolerance.

    Why: a lower layer at rest is a bed for the upper one, and the flux's mass viscosity
    alpha0 Delta h1 moves upper-layer material from the thicker side to the thinner
    one whatever the bed does. At a step that rises above the upper layer's surface on
    its lower side, that lifts material of the lower side, which lies wholly below the
    step's top, onto the step: with h2 frozen the potential energy (per rho2 and unit
    width) int r g (h1 h2 + h1^2/2) dx has derivative r g H in h1, so the diffusion
    d_x(nu d_x h1) changes it at the rate -nu r g int d_x H d_x h1; across such a step
    H rises towards the step, so wherever h1 thins that way (a layer in the hollow, a
    film or nothing on the step) the viscosity makes potential energy from nothing.
    Surges of the upper layer dumping material against the counter-slopes of a stepped
    deposit were fed this way and never came to rest at dx = 0.05 m (docs/model.md,
    "Coming to rest when the upper layer erodes"). Between the depths above the top,
    nothing of the lower side reaches the face, and the viscosity moves material only
    down the step.

    What changes is only how the jumps are shared between the two cells: mass and
    momentum are transported and diffused by the flux between the reconstructed states
    (s, s u1) (transport f = (s u1, s u1^2)), so that the momentum they bring a cell
    comes with the mass that carries it (the flux's momentum viscosity alpha0
    Delta(h1 u1) with this mass flux gave thin cells momentum without mass: velocity
    spikes); the hydrostatic part of the momentum jump is shared as the flux shares it,
    (1 -+ alpha1)/2, except that a side without upper layer (h1 <= ``dry``) gets none:
    it has no upper-layer momentum to receive (the source stage zeroes a dry cell's),
    and a cell that gets a trace of mass through its other face turned that share into
    a velocity spike (a blow-up of the MUSCL run of test 5.1 with phi_B = 46 deg,
    c = 3 at dx = 0.0125 m). Otherwise the sums are those of the flux:
    D^- + D^+ = (Delta(h1 u1), ``jump``), the paper's path-conservative discretisation
    of the pressure and of the coupling term g_z h1 d_x h2, so a thin layer on a steep
    deposit keeps its driving force. As s <= h1 on both sides, the flux never takes
    more mass from a cell than between its own depths (positivity).
    """
    fL = sL * u1L
    fR = sR * u1R
    tL = fL * u1L
    tR = fR * u1R
    mass = fL + 0.5 * ((fR - fL) - c0 * (sR - sL) - c1 * (fR - fL) - e0)
    mom = tL + 0.5 * ((tR - tL) - c0 * (fR - fL) - c1 * (tR - tL) - e1)
    pressure = jump - (h1R * u1R * u1R - h1L * u1L * u1L)
    wL = 0.5 * (1.0 - c1) if h1L > dry else 0.0
    wR = 0.5 * (1.0 + c1) if h1R > dry else 0.0
    if wL > 0.0 and wR > 0.0:
        # the thinner side gets at most the share its own depth carries, the thicker
        # side the rest (the sum stays the path-conservative jump): g h1bar Delta H
        # with the mean depth h1bar pushed a film barely above the dry tolerance, beside
        # a thicker layer, to tens of m/s in one step, and MUSCL's corrector (CFL far
        # above 1/2 at those speeds) then made its depth negative (issue 28)
        h1bar = 0.5 * (h1L + h1R)
        if h1L < h1R:
            wL *= h1L / h1bar
            wR = 1.0 - wL
        else:
            wR *= h1R / h1bar
            wL = 1.0 - wR
    return (mass - h1L * u1L, mom - h1L * u1L * u1L + wL * pressure,
            h1R * u1R - mass, h1R * u1R * u1R - mom + wR * pressure)


@cached
def internal_speed(h1: float, u1: float, h2: float, u2: float, g: float,
                   r: float) -> float:
    """IFCP's intermediate node S_int: the approximate internal eigenvalue of larger
    magnitude [m/s], U_c -+ c_int (see :mod:`pdeflow.numerics.ifcp`)."""
    H = h1 + h2
    if H <= 0.0:
        return 0.0
    du = u1 - u2
    uc = (h1 * u2 + h2 * u1) / H
    c2 = (1.0 - r) * g * h1 * h2 / H * (1.0 - du * du / ((1.0 - r) * g * H))
    c = math.sqrt(c2) if c2 > 0.0 else 0.0
    return uc + c if abs(uc + c) >= abs(uc - c) else uc - c


@cached(inline="always")
def face(q, i, axis, sign):
    """State ``(h1, h1u1, h2, h2u2)`` of cell ``i`` of ``q``, momenta times ``sign``
    (one axis: ``axis`` is 0)."""
    return q[0, i], sign * q[1, i], q[2, i], sign * q[3, i]


@functools.cache
def fluctuations(flux: int) -> Any:
    """``fluct(left, right, g, r, dry) -> (D^-, D^+, smax)`` of the two-layer system
    (24) for one flux (layout.FLUX_*): the fluctuations as (h1, h1u1, h2, h2u2) tuples
    and the largest wave speed [m/s]; ``g`` = g_z [m/s^2], ``r`` = rho1/rho2."""
    return specialise(_two_layer(flux == L.FLUX_RUSANOV, flux == L.FLUX_IFCP),
                      types.UniTuple(f8, 4), types.UniTuple(f8, 4), f8, f8, f8,
                      helper=True)


def _two_layer(rusanov: bool, ifcp: bool):
    def fluct_two_layer(left, right, g, r, dry):
        """Path-conservative fluctuations of the two-layer system (24), stage (29)."""
        h1L, m1L, h2L, m2L = left
        h1R, m1R, h2R, m2R = right
        u1L = velocity(h1L, m1L, dry)
        u2L = velocity(h2L, m2L, dry)
        u1R = velocity(h1R, m1R, dry)
        u2R = velocity(h2R, m2R, dry)
        HL = max(h1L, 0.0) + max(h2L, 0.0)
        HR = max(h1R, 0.0) + max(h2R, 0.0)
        cL = math.sqrt(g * HL)
        cR = math.sqrt(g * HR)
        loL = min(u1L if h1L > dry else u2L, u2L if h2L > dry else u1L)
        hiL = max(u1L if h1L > dry else u2L, u2L if h2L > dry else u1L)
        loR = min(u1R if h1R > dry else u2R, u2R if h2R > dry else u1R)
        hiR = max(u1R if h1R > dry else u2R, u2R if h2R > dry else u1R)
        sL = min(loL - cL, loR - cR)
        sR = max(hiL + cL, hiR + cR)
        smax = max(abs(sL), abs(sR))

        dh1 = h1R - h1L
        dh2 = h2R - h2L
        rest1 = m1L == 0.0 and m1R == 0.0
        rest2 = m2L == 0.0 and m2R == 0.0
        dm0 = dm1 = dm2 = dm3 = dp0 = dp1 = dp2 = dp3 = 0.0
        if not (rest1 and rest2):
            # (where both layers are at rest on both sides the at-rest rule below sets
            # every fluctuation: the flux's are not needed)
            a0 = u1R * h1R - u1L * h1L
            a1 = (u1R * u1R * h1R - u1L * u1L * h1L) + g * 0.5 * (h1L + h1R) * (dh1 + dh2)
            a2 = u2R * h2R - u2L * h2L
            a3 = (u2R * u2R * h2R - u2L * u2L * h2L) + g * 0.5 * (h2L + h2R) * (dh2 + r * dh1)

            h1 = h2 = u1 = u2 = 0.0
            if rusanov:
                c0, c1, c2 = rusanov_coefficients(sL, sR)
            elif ifcp:
                h1 = 0.5 * (h1L + h1R)
                h2 = 0.5 * (h2L + h2R)
                u1 = roe_velocity(h1L, u1L, h1R, u1R)
                u2 = roe_velocity(h2L, u2L, h2R, u2R)
                # the parabola is not positivity preserving near a layer's front: there, HLL
                if min(h1L, h1R, h2L, h2R) > IFCP_MIN_FRACTION * max(HL, HR):
                    c0, c1, c2 = ifcp_coefficients(sL, sR, internal_speed(h1, u1, h2, u2, g,
                                                                          r))
                else:
                    c0, c1, c2 = hll_coefficients(sL, sR)
            else:
                c0, c1, c2 = hll_coefficients(sL, sR)
            q0 = c0 * dh1 + c1 * a0
            q1 = c0 * (m1R - m1L) + c1 * a1
            q2 = c0 * dh2 + c1 * a2
            q3 = c0 * (m2R - m2L) + c1 * a3
            e0 = e1 = 0.0
            if ifcp and c2 != 0.0:
                # alpha2 A (A dq), A = pseudo-Jacobian of (28) at the averaged state
                e0 = c2 * a1
                e1 = c2 * ((g * h1 - u1 * u1) * a0 + 2.0 * u1 * a1 + g * h1 * a2)
                b2 = a3
                b3 = r * g * h2 * a0 + (g * h2 - u2 * u2) * a2 + 2.0 * u2 * a3
                q0 += e0
                q1 += e1
                q2 += c2 * b2
                q3 += c2 * b3
            dm0 = 0.5 * (a0 - q0)
            dm1 = 0.5 * (a1 - q1)
            dm2 = 0.5 * (a2 - q2)
            dm3 = 0.5 * (a3 - q3)
            dp0 = a0 - dm0
            dp1 = a1 - dm1
            dp2 = a2 - dm2
            dp3 = a3 - dm3
            if rest2 and dh2 != 0.0:
                # a step of a lower layer at rest: where it rises above the upper layer's
                # surface on one side, the upper layer's transport and viscosity act on the
                # depths above its top (see upper_layer_at_uncovered_step)
                top = max(h2L, h2R)
                sL = h1L + h2L - top
                sR = h1R + h2R - top
                if sL <= 0.0 or sR <= 0.0:
                    dm0, dm1, dp0, dp1 = upper_layer_at_uncovered_step(
                        h1L, u1L, max(sL, 0.0), h1R, u1R, max(sR, 0.0), a1, c0, c1, e0, e1,
                        dry)
        if rest1:
            dH = dh1 + dh2
            dm0 = 0.0
            dp0 = 0.0
            dm1 = 0.5 * g * h1L * dH
            dp1 = 0.5 * g * h1R * dH
        if rest2:
            dE = dh2 + r * dh1
            dm2 = 0.0
            dp2 = 0.0
            dm3 = 0.5 * g * h2L * dE
            dp3 = 0.5 * g * h2R * dE
        return (dm0, dm1, dm2, dm3), (dp0, dp1, dp2, dp3), smax

    return fluct_two_layer


@cached
def cell_jump(qm: np.ndarray, qp: np.ndarray, rate: np.ndarray, lo: int,
                        hi: int, inv_dx: float, g: float, r: float, dry: float,
                        axis: int) -> None:
    """Subtract the path-conservative jump across the linear reconstruction inside cells
    lo..hi (two layers; one axis: ``axis`` is 0)."""
    for i in range(lo, hi + 1):
        h1l, h1r = qm[0, i], qp[0, i]
        h2l, h2r = qm[2, i], qp[2, i]
        u1l = velocity(h1l, qm[1, i], dry)
        u1r = velocity(h1r, qp[1, i], dry)
        u2l = velocity(h2l, qm[3, i], dry)
        u2r = velocity(h2r, qp[3, i], dry)
        dh1 = h1r - h1l
        dh2 = h2r - h2l
        rate[0, i] -= (u1r * h1r - u1l * h1l) * inv_dx
        rate[1, i] -= ((u1r * u1r * h1r - u1l * u1l * h1l)
                       + g * 0.5 * (h1l + h1r) * (dh1 + dh2)) * inv_dx
        rate[2, i] -= (u2r * h2r - u2l * h2l) * inv_dx
        rate[3, i] -= ((u2r * u2r * h2r - u2l * u2l * h2l)
                       + g * 0.5 * (h2l + h2r) * (dh2 + r * dh1)) * inv_dx
