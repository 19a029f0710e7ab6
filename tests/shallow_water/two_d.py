"""Frictionless shallow water in 2D, (h, hu, hv): the kernels a model gives the scheme's
face loop on a 2D grid (tests/test_two_d_loop.py).

The model supplies its state at a face in the face's normal frame (depth, normal
momentum, tangential momentum), the rows the fluctuations go back into (one tuple per
axis) and its fluctuations in that frame: the single layer's 2D ones
(:mod:`pdeflow.models.single_layer.two_d`: the Saint-Venant ones for (h, normal
momentum), and the tangential momentum carried by the mass flux through the face,
upwinded). The scheme names no field. A state with no tangential
momentum gives the 1D fluctuations and zero tangential ones, so a 2D run uniform across
a direction gives the 1D run's numbers. This is the face loop's check, not issue 36's
2D physics: gravity acts along x only (g_x), there is no friction.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pdeflow.models.single_layer.two_d import ROWS, cell_jump, face, fluctuations
from pdeflow.numerics import layout as L
from pdeflow.numerics.compiled import (
    FIELDS,
    PARAMS,
    STATE,
    VECTOR,
    f8,
    i8,
    kernel,
)
from pdeflow.numerics.model_kernels import ModelKernels
from pdeflow.numerics.state import velocity

from . import layout as W


@kernel(STATE, f8, f8, PARAMS, VECTOR, VECTOR, i8, i8)
def sources(q, dt, t, P, diag, fex, lo, hi):  # pragma: no cover - compiled
    """h u <- h (u + dt g_x), h v <- h v in the wet cells lo..hi (the arithmetic of
    :func:`tests.shallow_water.sources.sw_sources`); dry cells lose their momentum."""
    moving = False
    for i in range(lo, hi + 1):
        h = max(q[0, i], 0.0)
        u = velocity(h, q[1, i], P[W.DRY])
        v = velocity(h, q[2, i], P[W.DRY])
        if h > P[W.DRY]:
            u += dt * P[W.G_X]
        m = h * u if h > P[W.DRY] else 0.0
        m2 = h * v if h > P[W.DRY] else 0.0
        moving = moving or m != 0.0 or m2 != 0.0
        q[0, i] = h
        q[1, i] = m
        q[2, i] = m2
    if moving:
        diag[W.D_MOVE] = t
    diag[L.D_T] = t
    diag[L.D_CHANGED] = 1.0 if moving else 0.0
    diag[L.D_STEPS] += 1.0


@kernel(STATE, f8, f8, PARAMS, VECTOR)
def source_stage(q, dt, t, P, diag):  # pragma: no cover - compiled
    sources(q, dt, t, P, diag, diag[L.N_DIAG:], 0, q.shape[1] - 1)


@kernel(VECTOR, VECTOR)
def fold(diag, book):  # pragma: no cover - compiled
    """A row's booking (the time of the last motion) added to ``diag``."""
    diag[W.D_MOVE] = max(diag[W.D_MOVE], book[W.D_MOVE])


@kernel(STATE, f8, PARAMS, i8, i8)
def predictor(q, dt, P, lo, hi):  # pragma: no cover - compiled
    for i in range(lo, hi + 1):
        if q[0, i] > P[W.DRY]:
            q[1, i] += dt * P[W.G_X] * q[0, i]


@kernel(STATE, FIELDS, PARAMS)
def mol_sources(q, rate, P):  # pragma: no cover - compiled
    for i in range(q.shape[1]):
        if q[0, i] > P[W.DRY]:
            rate[1, i] += P[W.G_X] * q[0, i]


def _no_numpy_twin(*args: Any) -> Any:
    raise NotImplementedError("the 2D shallow water has no numpy twin")


KERNELS = ModelKernels(
    fields=3, face=face, fluctuations=fluctuations, cell_jump=cell_jump, sources=sources,
    source_stage=source_stage, predictor=predictor, mol_sources=mol_sources,
    numpy_advection=_no_numpy_twin, numpy_sources=_no_numpy_twin,
    constants=lambda P: (float(P[W.G_Z]), 0.0, float(P[W.DRY])), fold=fold, layer_rows=3,
    rows=ROWS)
"""the 2D shallow water's kernels (the parameter vector of :mod:`.layout`)"""


def state(h: np.ndarray, hu: np.ndarray, hv: np.ndarray) -> np.ndarray:
    """q[field, cell] of depth and momenta given on the grid's cells ``[n0, n1]``."""
    return np.stack([h, hu, hv]).reshape(3, -1).astype(float)
