"""The single layer's source rate for the method of lines (py-pde's generic solvers) and
its numpy twin: gravity along the bed and basal friction with sgn(u) regularised as
u / max(|u|, mol_eps) (see :mod:`pdeflow.models.two_layer.rates`)."""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from ...numerics.compiled import FIELDS, PARAMS, STATE, specialise
from ...numerics.rheology import BasalLaw, basal_accel, law_block, law_block_np
from ...numerics.vectorized import at_rest, layer_fluctuations, velocity_np
from . import layout as S


@functools.cache
def source_rate(law: BasalLaw | None) -> Any:
    """The kernel ``(q, rate, P)`` that adds gravity along the bed and the regularised
    basal friction of the law ``law`` (None: Coulomb's) to ``rate`` (single layer)."""
    coulomb = law is None
    # closes over what its law calls only (None for Coulomb), as the scheme's factories
    accel, block = (None, None) if coulomb else (basal_accel(law), law_block)

    def source_rate_single(q, rate, P):
        for i in range(q.shape[1]):
            h = max(q[0, i], 0.0)
            if h > P[S.DRY]:
                u = q[1, i] / h
                if coulomb:
                    rate[1, i] += P[S.G_X] * h - P[S.G_Z] * h * P[S.TAN_B] * u / max(
                        abs(u), P[S.MOL_EPS])
                else:
                    rate[1, i] += P[S.G_X] * h - h * accel(
                        block(P, S.LAW), h, P[S.G_Z], h, abs(u)) * u / max(
                            abs(u), P[S.MOL_EPS])

    return specialise(source_rate_single, STATE, FIELDS, PARAMS)


def source_rate_np(q: np.ndarray, P: np.ndarray, law: BasalLaw | None = None) -> np.ndarray:
    """Gravity along the bed and regularised basal friction of the single layer with
    the law ``law`` (None: Coulomb's): the numpy twin of :func:`source_rate`."""
    rate = np.zeros_like(q)
    h = np.maximum(q[0], 0.0)
    u = velocity_np(h, q[1], P[S.DRY])
    eps = P[S.MOL_EPS]
    wet = h > P[S.DRY]
    if law is None:
        fric = P[S.G_Z] * h * P[S.TAN_B] * u / np.maximum(np.abs(u), eps)
    else:
        fric = h * law.accel_np(law_block_np(P, S.LAW), h, P[S.G_Z], h,
                                np.abs(u)) * u / np.maximum(np.abs(u), eps)
    rate[1] = np.where(wet, P[S.G_X] * h - fric, 0.0)
    return rate


def fluctuations_np(left: np.ndarray, right: np.ndarray, g: float,
                    dry: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """HLL fluctuations of the single layer over all faces between the states ``left``
    and ``right`` (the numpy twin of :func:`.flux.fluctuations` for HLL):
    (D^-, D^+, S_L, S_R)."""
    hl, hr = left[0], right[0]
    ml, mr = left[1], right[1]
    ul = velocity_np(hl, ml, dry)
    ur = velocity_np(hr, mr, dry)
    cL = np.sqrt(g * sum([np.maximum(hl, 0.0)]))
    cR = np.sqrt(g * sum([np.maximum(hr, 0.0)]))
    sL = np.minimum(ul - cL, ur - cR)
    sR = np.maximum(ul + cL, ur + cR)
    dH = sum([np.maximum(hr, 0.0)]) - sum([np.maximum(hl, 0.0)])
    a1 = ur * ur * hr + 0.5 * g * hr * hr - ul * ul * hl - 0.5 * g * hl * hl
    fluct = layer_fluctuations(hl, hr, ml, mr, ul, ur, a1, sL, sR)
    dm0, dp0, dm1, dp1 = at_rest(fluct, hl, hr, ml, mr, g, dH)
    return np.array([dm0, dm1]), np.array([dp0, dp1]), sL, sR
