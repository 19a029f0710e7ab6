"""The single layer at a face: its states, fluctuations and MUSCL cell jump.

The Saint-Venant fluctuations in the polynomial-viscosity form of
:mod:`pdeflow.numerics.pvm` with Davis's wave-speed bounds u -+ sqrt(g_z h), compiled
for one flux at a time (:func:`fluctuations`); a face's states are tuples ``(h, hu)``
(:func:`face`). A one-layer model of the same conservative part reuses them.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from ...numerics import layout as L
from ...numerics.compiled import cached, f8, specialise, types
from ...numerics.hll import hll_coefficients
from ...numerics.ifcp import roe_coefficients
from ...numerics.pvm import roe_velocity
from ...numerics.rusanov import rusanov_coefficients
from ...numerics.state import velocity


@cached(inline="always")
def face(q, i, axis, sign):
    """State ``(h, hu)`` of cell (or face value) ``i`` of ``q``, the momentum times
    ``sign`` (-1: the mirror image of a wall's ghost cell; one axis: ``axis`` is 0)."""
    return q[0, i], sign * q[1, i]


@functools.cache
def fluctuations(flux: int) -> Any:
    """``fluct(left, right, g, r, dry) -> (D^-, D^+, smax)`` of the single layer for one
    flux (layout.FLUX_*): the fluctuations as (h, hu) tuples and the largest wave speed
    [m/s]; ``g`` = g_z [m/s^2], ``r`` unused."""
    return specialise(_single(flux == L.FLUX_RUSANOV, flux == L.FLUX_IFCP),
                      types.UniTuple(f8, 2), types.UniTuple(f8, 2), f8, f8, f8,
                      helper=True)


def _single(rusanov: bool, ifcp: bool):
    def fluct_single(left, right, g, r, dry):
        """Fluctuations of the single-layer system."""
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
        a0 = uR * hR - uL * hL
        a1 = uR * uR * hR + 0.5 * g * hR * hR - (uL * uL * hL + 0.5 * g * hL * hL)
        if rusanov:
            c0, c1, c2 = rusanov_coefficients(sL, sR)
        elif ifcp and hL > dry and hR > dry:
            u = roe_velocity(hL, uL, hR, uR)
            c = math.sqrt(0.5 * g * (hL + hR))
            c0, c1, c2 = roe_coefficients(u - c, u + c, 0.1 * c)
        else:
            c0, c1, c2 = hll_coefficients(sL, sR)
        q0 = c0 * (hR - hL) + c1 * a0
        q1 = c0 * (mR - mL) + c1 * a1
        dm0 = 0.5 * (a0 - q0)
        dm1 = 0.5 * (a1 - q1)
        return (dm0, dm1), (a0 - dm0, a1 - dm1), smax

    return fluct_single


@cached
def cell_jump(qm: np.ndarray, qp: np.ndarray, rate: np.ndarray, lo: int, hi: int,
                     inv_dx: float, g: float, r: float, dry: float, axis: int) -> None:
    """Subtract the flux difference across the reconstruction inside cells lo..hi
    (single layer; ``r`` unused; one axis: ``axis`` is 0)."""
    for i in range(lo, hi + 1):
        hl, hr = qm[0, i], qp[0, i]
        ul = velocity(hl, qm[1, i], dry)
        ur = velocity(hr, qp[1, i], dry)
        rate[0, i] -= (ur * hr - ul * hl) * inv_dx
        rate[1, i] -= (ur * ur * hr + 0.5 * g * hr * hr
                       - ul * ul * hl - 0.5 * g * hl * hl) * inv_dx
