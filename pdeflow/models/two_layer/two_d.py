r"""The two-layer system (24) on a 2D grid (x down the slope, y across): its states at a
face, its fluctuations and its MUSCL cell jump, for the scheme's face loop.

State rows ``h1, h1u1, h1v1, h2, h2u2, h2v2`` (three per layer). At a face normal to
an axis the model hands the scheme each layer's depth, momentum normal to the face and
tangential momentum (:func:`face`), and takes the fluctuations back into :data:`ROWS`.
In the face's frame the depths and the normal momenta obey the 1D system (24) with the
normal velocities (docs/two_d.md, "The system in a direction n"): their fluctuations
are the 1D path-conservative ones of :mod:`.flux` (with the coupling terms
g_z h1 d_n h2 and r g_z h2 d_n h1, the wave-speed bounds, the at-rest rule and the rule
at an uncovered step), every flux. Each layer's tangential momentum is carried by the
layer's own mass flux through the face, upwinded (the contact wave of HLLC's star
states reduced to its transport, as :mod:`tests.shallow_water.two_d` does for one
layer). A state without tangential momentum gets the 1D fluctuations and zero
tangential ones, so a 2D run uniform across a direction gives the 1D run's numbers.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from ...numerics.compiled import cached, f8, specialise, types
from ...numerics.state import velocity
from .flux import fluctuations as normal_fluctuations

ROWS = ((0, 1, 2, 3, 4, 5), (0, 2, 1, 3, 5, 4))
"""per axis: the row of q that each entry of a face tuple (h1, normal momentum 1,
tangential momentum 1, h2, normal momentum 2, tangential momentum 2) goes into"""
LAYER_ROWS = 3
"""rows per layer: depth, momentum along x, momentum along y"""


@cached(inline="always")
def face(q, i, axis, sign):
    """State ``(h1, n1, t1, h2, n2, t2)`` of cell (or face value) ``i`` at a face normal
    to ``axis`` (0: x, 1: y): depths [m], normal momenta times ``sign`` and tangential
    momenta [m^2/s]."""
    if axis == 0:
        return q[0, i], sign * q[1, i], q[2, i], q[3, i], sign * q[4, i], q[5, i]
    return q[0, i], sign * q[2, i], q[1, i], q[3, i], sign * q[5, i], q[4, i]


@cached(inline="always")
def _upwind(hL, nL, tL, hR, nR, tR, d_mass, dry):
    """Tangential-momentum fluctuation ``(D^-, D^+)`` [m^3/s^2] of one layer: its
    tangential velocity rides on the layer's mass flux through the face (f_L + D^-_h,
    from the 1D fluctuation ``d_mass``), taken from the upwind side."""
    fL = velocity(hL, nL, dry) * hL
    fR = velocity(hR, nR, dry) * hR
    vL = velocity(hL, tL, dry)
    vR = velocity(hR, tR, dry)
    mass = fL + d_mass
    t_minus = mass * (vL if mass > 0.0 else vR) - fL * vL
    return t_minus, (fR * vR - fL * vL) - t_minus


@functools.cache
def fluctuations(flux: int) -> Any:
    """``fluct(left, right, g, r, dry) -> (D^-, D^+, smax)`` of the 2D two-layer system
    in a face's normal frame, tuples as :func:`face`'s, for one flux (layout.FLUX_*);
    ``g`` = g_z [m/s^2], ``r`` = rho1/rho2, ``dry`` [m]; smax [m/s]."""
    normal = normal_fluctuations(flux)

    def fluct_two_layer_2d(left, right, g, r, dry):
        h1L, n1L, t1L, h2L, n2L, t2L = left
        h1R, n1R, t1R, h2R, n2R, t2R = right
        dm, dp, smax = normal((h1L, n1L, h2L, n2L), (h1R, n1R, h2R, n2R), g, r, dry)
        m1, p1 = _upwind(h1L, n1L, t1L, h1R, n1R, t1R, dm[0], dry)
        m2, p2 = _upwind(h2L, n2L, t2L, h2R, n2R, t2R, dm[2], dry)
        return ((dm[0], dm[1], m1, dm[2], dm[3], m2),
                (dp[0], dp[1], p1, dp[2], dp[3], p2), smax)

    tuple6 = types.UniTuple(f8, 6)
    return specialise(fluct_two_layer_2d, tuple6, tuple6, f8, f8, f8, helper=True)


@cached
def cell_jump(qm: np.ndarray, qp: np.ndarray, rate: np.ndarray, lo: int, hi: int,
              inv_dx: float, g: float, r: float, dry: float, axis: int) -> None:
    """MUSCL: subtract the path-conservative jump along ``axis`` across the linear
    reconstruction inside cells lo..hi (``inv_dx`` [1/m]): the 1D two-layer jump of
    :func:`.flux.cell_jump` for the depths and normal momenta, and each layer's
    tangential momentum transported by its normal mass flux."""
    n = 1 + axis
    t = 2 - axis
    for i in range(lo, hi + 1):
        h1l, h1r = qm[0, i], qp[0, i]
        h2l, h2r = qm[3, i], qp[3, i]
        u1l = velocity(h1l, qm[n, i], dry)
        u1r = velocity(h1r, qp[n, i], dry)
        u2l = velocity(h2l, qm[3 + n, i], dry)
        u2r = velocity(h2r, qp[3 + n, i], dry)
        dh1 = h1r - h1l
        dh2 = h2r - h2l
        rate[0, i] -= (u1r * h1r - u1l * h1l) * inv_dx
        rate[n, i] -= ((u1r * u1r * h1r - u1l * u1l * h1l)
                       + g * 0.5 * (h1l + h1r) * (dh1 + dh2)) * inv_dx
        rate[3, i] -= (u2r * h2r - u2l * h2l) * inv_dx
        rate[3 + n, i] -= ((u2r * u2r * h2r - u2l * u2l * h2l)
                           + g * 0.5 * (h2l + h2r) * (dh2 + r * dh1)) * inv_dx
        v1l = velocity(h1l, qm[t, i], dry)
        v1r = velocity(h1r, qp[t, i], dry)
        v2l = velocity(h2l, qm[3 + t, i], dry)
        v2r = velocity(h2r, qp[3 + t, i], dry)
        rate[t, i] -= (u1r * h1r * v1r - u1l * h1l * v1l) * inv_dx
        rate[3 + t, i] -= (u2r * h2r * v2r - u2l * h2l * v2l) * inv_dx


def state(h1: np.ndarray, h1u1: np.ndarray, h1v1: np.ndarray, h2: np.ndarray,
          h2u2: np.ndarray, h2v2: np.ndarray) -> np.ndarray:
    """q[field, cell] of the layers' depths [m] and momenta [m^2/s] given on the grid's
    cells ``[n0, n1]`` (flattened as the scheme's metric flattens them)."""
    return np.stack([h1, h1u1, h1v1, h2, h2u2, h2v2]).reshape(6, -1).astype(float)
