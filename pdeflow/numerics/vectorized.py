"""Vectorised numpy implementation of the method-of-lines rate (py-pde's numpy backend).

An independent second implementation of the same formulas as the numba kernels in
:mod:`pdeflow.numerics.hll` and :mod:`pdeflow.numerics.advection`, written over whole
arrays of faces: the driver and the HLL pieces every layer shares; each model's face
fluctuations and source rate have their numpy twins beside its kernels (e.g.
:func:`pdeflow.models.two_layer.rates.fluctuations_np`). It serves py-pde's
``numpy`` backend and, in the tests, as a cross-check of the compiled kernels.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from . import layout as L


def velocity_np(h: np.ndarray, m: np.ndarray, dry: float) -> np.ndarray:
    """Depth-averaged velocity m/h [m/s] where h > dry [m], else 0 (over arrays)."""
    return np.where(h > dry, m / np.where(h > dry, h, 1.0), 0.0)


def _with_ghosts(q: np.ndarray, bc_left: int, bc_right: int) -> np.ndarray:
    """State with one ghost cell per side (walls mirror momenta, open copies)."""
    ext = np.concatenate([q[:, :1], q, q[:, -1:]], axis=1)
    for k in range(1, q.shape[0], 2):
        if bc_left == L.BC_WALL:
            ext[k, 0] = -ext[k, 0]
        if bc_right == L.BC_WALL:
            ext[k, -1] = -ext[k, -1]
    return ext


def hll_split(sL, sR, dq, a):
    """HLL fluctuations D-, D+ for one (mass, momentum) pair over all faces."""
    width = np.where(sR - sL > 0, sR - sL, 1.0)
    dm = np.where(sL >= 0, 0.0, np.where(sR <= 0, a, sL / width * (sR * dq - a)))
    dm = np.where(sR - sL > 0, dm, 0.0)
    dp = np.where(sR - sL > 0, a - dm, 0.0)
    return dm, dp


def layer_fluctuations(hl, hr, ml, mr, ul, ur, a1, sL, sR):
    """HLL fluctuations (D-_h, D+_h, D-_hu, D+_hu) of one layer over all faces: its mass
    flux jump and its momentum jump ``a1`` (the model's, with its pressure and
    coupling), between wave speeds ``sL``, ``sR`` [m/s]."""
    a0 = ur * hr - ul * hl
    dm0, dp0 = hll_split(sL, sR, hr - hl, a0)
    dm1, dp1 = hll_split(sL, sR, mr - ml, a1)
    return dm0, dp0, dm1, dp1


def at_rest(fluct, hl, hr, ml, mr, g, dpress):
    """The at-rest rule of :mod:`pdeflow.numerics.pvm` over all faces: where the layer has
    no momentum on both sides, no mass moves and the hydrostatic jump g h ``dpress`` is
    split by each side's own depth."""
    dm0, dp0, dm1, dp1 = fluct
    rest = (ml == 0.0) & (mr == 0.0)
    return (np.where(rest, 0.0, dm0), np.where(rest, 0.0, dp0),
            np.where(rest, 0.5 * g * hl * dpress, dm1),
            np.where(rest, 0.5 * g * hr * dpress, dp1))


def advection_rate(q: np.ndarray, dx: float, bc: tuple[int, int], fluctuations: Callable,
                   *args: float) -> tuple[np.ndarray, float]:
    """HLL advection rate of a state and the largest wave speed over the faces [m/s] (for
    the CFL condition): ``fluctuations(left, right, *args) -> (D^-, D^+, sL, sR)``, the
    model's over all faces (rows as the state's), between the ghosted states."""
    ext = _with_ghosts(q, *bc)
    dmin, dplus, sL, sR = fluctuations(ext[:, :-1], ext[:, 1:], *args)
    smax = float(np.max(np.maximum(np.abs(sL), np.abs(sR))))
    return -(dplus[:, :-1] + dmin[:, 1:]) / dx, smax
