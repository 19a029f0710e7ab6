"""pdeflow's single layer against the Savage-Hutter similarity solution
(:mod:`pdeflow.analysis.similarity`): the set-up on a 2D grid, the run, and the errors of
a thickness field on any raster, whichever code computed it.

The set-up is AvaFrame's analytic test (``ana1Tests/simiSolTest``, its
``simiSol_com1DFACfg.ini``): a cap L_x = L_y = 80 m, H = 4 m on a 35 deg plane, Coulomb
friction delta = 25 deg, t = 5 s. pdeflow's 2D plane already has x along the slope and h
normal to it (the 1D model's coordinates with theta), so the solution's (x, y, h) are
pdeflow's, shifted by the release's centre; AvaFrame's rasters are horizontal (x_h = x
cos zeta) and are converted before they reach :func:`errors`.

The grid covers x in [-100, 140] m along the slope from the release's centre (at t = 5 s
the cap spans -66..113 m) and the half plane y in [0, 100] m: a wall at y = 0 is a
symmetry plane, which holds the symmetric solution exactly, so half the cells give the
whole run. The other sides are open. The initial state is the case files' ``cap`` shape
(:func:`pdeflow.initial_shapes_2d.total_depth_2d`) at the cell centres, at rest.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from ..initial_shapes_2d import total_depth_2d
from ..models.base import check_range
from .similarity import CapSolution

SLOPE_DEG = 35.0  #: zeta [deg]
FRICTION_DEG = 25.0  #: delta [deg], Coulomb mu = tan(delta)
L_X = L_Y = 80.0  #: initial semi-axes [m]
H = 4.0  #: initial height [m]
T_END = 5.0  #: [s]
X_RANGE = (-100.0, 140.0)  #: along the slope from the release's centre [m]
Y_RANGE = (0.0, 100.0)  #: across, the half plane y >= 0 [m]


def solution(t_end: float = T_END) -> CapSolution:
    """The similarity solution of the set-up, over [0, t_end] [s]."""
    return CapSolution(SLOPE_DEG, FRICTION_DEG, L_X, L_Y, H, t_end)


def initial_state(dx: float, scheme: str = "hll/first-order") -> tuple[Any, Any]:
    """(PDE, initial state) of the set-up with square cells of side dx [m]; dx must
    divide 20 m (so that both ranges hold whole cells)."""
    from pde import CartesianGrid

    from ..models import SingleLayerGranular

    check_range("dx", dx, 0.0, 20.0, low_open=True, unit="m")
    nx, ny = ((hi - lo) / dx for lo, hi in (X_RANGE, Y_RANGE))
    if abs(nx - round(nx)) > 1e-9 * nx or abs(ny - round(ny)) > 1e-9 * ny:
        raise ValueError(f"dx must divide 20 m (e.g. 4, 2, 1, 0.5), got {dx!r}")
    grid = CartesianGrid([list(X_RANGE), list(Y_RANGE)], [round(nx), round(ny)])
    x, y = np.meshgrid(*grid.axes_coords, indexing="ij")
    cap = {"shape": "cap", "x0": 0.0, "y0": 0.0, "semi_x": L_X, "semi_y": L_Y, "H0": H}
    eq = SingleLayerGranular(theta_deg=SLOPE_DEG, phi_b_deg=FRICTION_DEG, scheme=scheme,
                             bc=(("open", "open"), ("wall", "open")))
    return eq, eq.make_state(grid, h=total_depth_2d(cap, x, y))


def run(dx: float, scheme: str = "hll/first-order", t_end: float = T_END
        ) -> dict[str, Any]:
    """pdeflow's run of the set-up to t_end [s] (fv-split at its default Courant
    number 0.3, Lie splitting):
    ``h`` (nx, ny) [m], the cell centres ``x``, ``y`` [m], ``wall`` [s] (the solve
    alone, kernels compiled on first use: call once before timing) and ``steps``."""
    eq, state = initial_state(dx, scheme)
    info: dict[str, Any] = {}
    start = time.perf_counter()
    final = eq.solve(state, t_range=t_end, solver="fv-split", tracker=None,
                     ret_info=True)
    wall = time.perf_counter() - start
    final, info = final if isinstance(final, tuple) else (final, info)
    x, y = np.meshgrid(*state.grid.axes_coords, indexing="ij")
    steps = info.get("solver", {}).get("steps")
    return {"h": final.data[0], "x": x, "y": y, "wall": wall, "steps": steps}


def errors(h: np.ndarray, x: np.ndarray, y: np.ndarray, exact: CapSolution, t: float
           ) -> dict[str, float]:
    """The errors of a slope-normal thickness h [m] on a raster of equal cells whose
    centres are (x, y) [m along and across the slope from the release's centre] at
    time t [s]: relative ``L1``, ``L2`` and ``Lmax`` of h (AvaFrame's relative norms:
    the error's norm over the solution's; equal cells, so the area cancels) and
    ``centre``, the distance [m] along the slope between the thickness' centroid and
    the solution's centre x_c (with the signed ``centre_x`` [m] of the centroid)."""
    ref = exact.depth(x, y, t)
    e = np.abs(np.asarray(h) - ref)
    centroid = float((h * x).sum() / h.sum())
    x_c = exact.state(t)["x_c"]
    return {"L1": float(e.sum() / ref.sum()),
            "L2": math.sqrt(float((e * e).sum() / (ref * ref).sum())),
            "Lmax": float(e.max() / ref.max()),
            "centre": abs(centroid - x_c), "centre_x": centroid}
