"""The single layer's source rate for the method of lines (py-pde's generic solvers) and
its numpy twin: gravity along the bed and basal friction with sgn(u) regularised as
u / max(|u|, mol_eps) (see :mod:`pdeflow.models.two_layer.rates`)."""

from __future__ import annotations

import numpy as np

from ...numerics import layout as L
from ...numerics.compiled import FIELDS, PARAMS, STATE, kernel
from ...numerics.rheology import basal_accel, law_block
from ...numerics.vectorized import at_rest, basal_accel_np, layer_fluctuations, velocity_np
from . import layout as S


@kernel(STATE, FIELDS, PARAMS)
def source_rate_single(q: np.ndarray, rate: np.ndarray, P: np.ndarray) -> None:
    """Add gravity along the bed and regularised basal friction (single layer)."""
    coulomb = int(P[S.LAW + L.LAW_CODE]) == L.FRICTION_COULOMB
    for i in range(q.shape[1]):
        h = max(q[0, i], 0.0)
        if h > P[S.DRY]:
            u = q[1, i] / h
            if coulomb:
                rate[1, i] += P[S.G_X] * h - P[S.G_Z] * h * P[S.TAN_B] * u / max(
                    abs(u), P[S.MOL_EPS])
            else:
                rate[1, i] += P[S.G_X] * h - h * basal_accel(
                    law_block(P, S.LAW), h, P[S.G_Z], h, abs(u)) * u / max(
                        abs(u), P[S.MOL_EPS])


def source_rate_single_np(q: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Gravity along the bed and regularised Coulomb friction of the single layer (the
    numpy twin of :func:`source_rate_single`)."""
    rate = np.zeros_like(q)
    h = np.maximum(q[0], 0.0)
    u = velocity_np(h, q[1], P[S.DRY])
    eps = P[S.MOL_EPS]
    wet = h > P[S.DRY]
    if int(P[S.LAW + L.LAW_CODE]) == L.FRICTION_COULOMB:
        fric = P[S.G_Z] * h * P[S.TAN_B] * u / np.maximum(np.abs(u), eps)
    else:
        fric = h * basal_accel_np(P, S.LAW, h, P[S.G_Z], h, np.abs(u)) * u / np.maximum(
            np.abs(u), eps)
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
