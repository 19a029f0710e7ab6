"""The shallow-water kernels: gravity along the bed, nothing else."""

from __future__ import annotations

import numpy as np

from pdeflow.numerics import layout as L
from pdeflow.numerics.compiled import FIELDS, PARAMS, STATE, VECTOR, f8, i8, kernel
from pdeflow.numerics.state import velocity

from . import layout as W


@kernel(STATE, f8, f8, PARAMS, VECTOR, i8, i8)
def sw_sources(q, dt, t, P, diag, lo, hi):  # pragma: no cover - compiled
    """h u <- h (u + dt g_x) in the wet cells lo..hi; dry cells lose their momentum."""
    moving = False
    for i in range(lo, hi + 1):
        h = max(q[0, i], 0.0)
        u = velocity(h, q[1, i], P[W.DRY])
        if h > P[W.DRY]:
            u += dt * P[W.G_X]
        m = h * u if h > P[W.DRY] else 0.0
        moving = moving or m != 0.0
        q[0, i] = h
        q[1, i] = m
    if moving:
        diag[W.D_MOVE] = t
    diag[L.D_T] = t
    diag[L.D_CHANGED] = 1.0 if moving else 0.0
    diag[L.D_STEPS] += 1.0


@kernel(STATE, f8, f8, PARAMS, VECTOR)
def sw_source_stage(q, dt, t, P, diag):  # pragma: no cover - compiled
    sw_sources(q, dt, t, P, diag, 0, q.shape[1] - 1)


@kernel(STATE, f8, PARAMS, i8, i8)
def sw_predictor(q, dt, P, lo, hi):  # pragma: no cover - compiled
    for i in range(lo, hi + 1):
        if q[0, i] > P[W.DRY]:
            q[1, i] += dt * P[W.G_X] * q[0, i]


@kernel(STATE, FIELDS, PARAMS)
def sw_mol_sources(q, rate, P):  # pragma: no cover - compiled
    for i in range(q.shape[1]):
        if q[0, i] > P[W.DRY]:
            rate[1, i] += P[W.G_X] * q[0, i]


def sw_numpy_sources(q: np.ndarray, P: np.ndarray) -> np.ndarray:
    rate = np.zeros_like(q)
    rate[1] = np.where(q[0] > P[W.DRY], P[W.G_X] * q[0], 0.0)
    return rate
