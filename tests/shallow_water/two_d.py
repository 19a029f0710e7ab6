"""Frictionless shallow water in 2D, (h, hu, hv): the kernels a model gives the scheme's
face loop on a 2D grid (tests/test_two_d_loop.py).

The model supplies its state at a face in the face's normal frame (:func:`face`: depth,
normal momentum, tangential momentum), the rows the fluctuations go back into
(:data:`ROWS`, one tuple per axis) and its fluctuations in that frame: the Saint-Venant
ones of the single layer for (h, normal momentum), and the tangential momentum carried
by the mass flux through the face, upwinded (the contact wave of HLLC's star states
reduced to its transport). The scheme names no field. A state with no tangential
momentum gives the 1D fluctuations and zero tangential ones, so a 2D run uniform across
a direction gives the 1D run's numbers. This is the face loop's check, not issue 36's
2D physics: gravity acts along x only (g_x), there is no friction.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from pdeflow.models.single_layer import flux as saint_venant
from pdeflow.numerics import layout as L
from pdeflow.numerics.compiled import (
    FIELDS,
    PARAMS,
    STATE,
    VECTOR,
    cached,
    f8,
    i8,
    kernel,
    specialise,
    types,
)
from pdeflow.numerics.model_kernels import ModelKernels
from pdeflow.numerics.state import velocity

from . import layout as W

ROWS = ((0, 1, 2), (0, 2, 1))
"""per axis: the rows of q that (depth, normal momentum, tangential momentum) go into"""


@cached(inline="always")
def face(q, i, axis, sign):
    """State ``(h, normal momentum times sign, tangential momentum)`` of cell (or face
    value) ``i`` at a face normal to ``axis`` (0: x, 1: y) [m, m^2/s, m^2/s]."""
    if axis == 0:
        return q[0, i], sign * q[1, i], q[2, i]
    return q[0, i], sign * q[2, i], q[1, i]


@functools.cache
def fluctuations(flux: int) -> Any:
    """``fluct(left, right, g, r, dry) -> (D^-, D^+, smax)`` in a face's normal frame,
    (h, normal, tangential) tuples, for one flux (layout.FLUX_*)."""
    normal = saint_venant.fluctuations(flux)

    def fluct_sw2(left, right, g, r, dry):
        hL, mL, tL = left
        hR, mR, tR = right
        dm, dp, smax = normal((hL, mL), (hR, mR), g, r, dry)
        # the tangential velocity rides on the mass flux through the face, from upwind
        fL = velocity(hL, mL, dry) * hL
        fR = velocity(hR, mR, dry) * hR
        vL = velocity(hL, tL, dry)
        vR = velocity(hR, tR, dry)
        mass = fL + dm[0]
        t_minus = mass * (vL if mass > 0.0 else vR) - fL * vL
        t_total = fR * vR - fL * vL
        return (dm[0], dm[1], t_minus), (dp[0], dp[1], t_total - t_minus), smax

    tuple3 = types.UniTuple(types.float64, 3)
    return specialise(fluct_sw2, tuple3, tuple3, f8, f8, f8, helper=True)


@cached
def cell_jump(qm, qp, rate, lo, hi, inv_dx, g, r, dry, axis):
    """MUSCL: subtract the flux difference along ``axis`` across the reconstruction
    inside cells lo..hi (the single layer's for h and the normal momentum)."""
    n = 1 + axis
    t = 2 - axis
    for i in range(lo, hi + 1):
        hl, hr = qm[0, i], qp[0, i]
        ul = velocity(hl, qm[n, i], dry)
        ur = velocity(hr, qp[n, i], dry)
        rate[0, i] -= (ur * hr - ul * hl) * inv_dx
        rate[n, i] -= (ur * ur * hr + 0.5 * g * hr * hr
                       - ul * ul * hl - 0.5 * g * hl * hl) * inv_dx
        vl = velocity(hl, qm[t, i], dry)
        vr = velocity(hr, qp[t, i], dry)
        rate[t, i] -= (ur * hr * vr - ul * hl * vl) * inv_dx


@kernel(STATE, f8, f8, PARAMS, VECTOR, i8, i8)
def sources(q, dt, t, P, diag, lo, hi):  # pragma: no cover - compiled
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
    sources(q, dt, t, P, diag, 0, q.shape[1] - 1)


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
    constants=lambda P: (float(P[W.G_Z]), 0.0, float(P[W.DRY])), layer_rows=3, rows=ROWS)
"""the 2D shallow water's kernels (the parameter vector of :mod:`.layout`)"""


def state(h: np.ndarray, hu: np.ndarray, hv: np.ndarray) -> np.ndarray:
    """q[field, cell] of depth and momenta given on the grid's cells ``[n0, n1]``."""
    return np.stack([h, hu, hv]).reshape(3, -1).astype(float)
