r"""The source stages (31)-(34) of the split scheme on a 2D state (rows h1, h1u1, h1v1,
h2, h2u2, h2v2), cell by cell, and MUSCL's friction predictor in 2D.

The 1D stage (:mod:`.sources`) with vectors:

* exchange (31): closure (25) on the shear vector du = u1 - u2, its magnitude where
  the 1D stage has |du| (:func:`.exchange.exchange_step` reads du only through du^2
  and |du|); the exchanged mass carries the velocity vector of the layer it leaves;
* implicit momentum sources (32): gravity along the plane's steepest descent, (g_x,
  g_y) = g sin(theta) (cos a, sin a) at the slope's azimuth a, the interface stress
  opposing du and the basal friction opposing u2, both set-valued
  (:mod:`.friction_2d`; a rate-dependent basal law: :mod:`.laws_2d`);
* hyperbolicity (33)-(34): F_extra along du. With ``directions`` "all" (the default)
  it brings |du| to F_c1 whenever |du| > F_c1, above the band as inside it: only then
  is the state hyperbolic in every direction (docs/two_d.md); "flow" applies the 1D
  rule to |du| (restores only inside the band along du), the 1D run's behaviour.

Where every velocity of a cell lies along one axis, each piece does the 1D stage's
arithmetic (|du| = sqrt(du^2) is |du| exactly), so a run uniform across a direction
gives the 1D numbers ("all" differs from 1D only in cells above the band).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from ...numerics import layout as L
from ...numerics.compiled import PARAMS, STATE, VECTOR, f8, i8, kernel, specialise
from ...numerics.rheology import BasalLaw
from ...numerics.state import velocity
from . import layout as T
from .exchange import exchange_step
from .friction import COULOMB, friction_kernels
from .friction_2d import coulomb_bed_2d, implicit_friction_2d, restore_2d
from .hyperbolicity import restoration_target, restoration_target_all
from .laws import law_bed
from .laws_2d import law_bed_2d
from .sources import _close_stage

DIRECTIONS = ("all", "flow")
"""where the 2D restoration acts: 'all' (|du| > F_c1), 'flow' (the 1D band along du)"""


@functools.cache
def stage_kernels_2d(law: BasalLaw | None = None,
                     directions: str = "all") -> tuple[Any, Any, Any]:
    """The 2D source-stage kernels with the basal law ``law`` (None: the paper's
    Coulomb friction), compiled with its kernels as constants (as the 1D
    :func:`.sources.stage_kernels`): the stage on the cells lo..hi ``(q, dt, t, P,
    book, fex, lo, hi)`` (booked in ``book``, F_extra/rho1 per cell in ``fex``; a row
    of the loop's box, ``numerics.threads``), on every cell ``(q, dt, t, P, diag)``
    and MUSCL's predictor ``(q, dt, P, lo, hi)``; ``directions`` one of :data:`DIRECTIONS`."""
    if directions not in DIRECTIONS:
        raise ValueError(f"directions must be one of {list(DIRECTIONS)}, got "
                         f"{directions!r}")
    fk = COULOMB if law is None else friction_kernels(*law_bed(law))
    bed = coulomb_bed_2d if law is None else law_bed_2d(law)
    sources = _sources_2d(fk, bed, directions == "all")

    def source_stage_two_layer_2d(q, dt, t, P, diag):
        sources(q, dt, t, P, diag, diag[L.N_DIAG:], 0, q.shape[1] - 1)

    return (sources, specialise(source_stage_two_layer_2d, STATE, f8, f8, PARAMS, VECTOR),
            _predictor_2d(fk, bed))


@kernel(VECTOR, VECTOR)
def fold_two_layer_2d(diag: np.ndarray, book: np.ndarray) -> None:
    """Add a row's booking of the 2D stage (from zeros) to ``diag``: the times of the
    last motion [s] (the latest: never negative), the largest F_extra/rho1 with its cell
    and time if the row's is larger (so the first cell in cell order wins, as in one
    pass), the exchanged depths and the counts (summed)."""
    for slot in (T.D_MOVE_UPPER, T.D_MOVE_LOWER, T.D_FAST_UPPER, T.D_FAST_LOWER):
        diag[slot] = max(diag[slot], book[slot])
    if book[T.D_FEXTRA_MAX] > diag[T.D_FEXTRA_MAX]:
        diag[T.D_FEXTRA_MAX] = book[T.D_FEXTRA_MAX]
        diag[T.D_FEXTRA_CELL] = book[T.D_FEXTRA_CELL]
        diag[T.D_FEXTRA_TIME] = book[T.D_FEXTRA_TIME]
    for slot in (T.D_DEPOSITED, T.D_ERODED, T.D_HYP_EVENTS, T.D_HYP_BISECTIONS):
        diag[slot] += book[slot]


def _exchange_2d(h1, h2, u1x, u1y, u2x, u2y, dt, P):
    """Stage (31) of one cell: (h1, h2, u1x, u1y, u2x, u2y, dh1, phi) after the
    exchange [m, m/s]; ``dh1`` the change of h1 [m], ``phi`` the applied fraction of
    the erosion (0 if none; see :mod:`.exchange`)."""
    r = P[T.R]
    g = P[T.G_Z]
    dry = P[T.DRY]
    closure = int(P[T.CLOSURE])
    tau = P[T.TAU_STAR] * math.sqrt((h1 + h2) / g) if closure == L.CLOSURE_RELAXED \
        else 0.0
    dux = u1x - u2x
    duy = u1y - u2y
    dh1, full = exchange_step(h1, h2, math.sqrt(dux * dux + duy * duy), dt, r, g,
                              P[T.TAN_INT], P[T.K], P[T.C], P[T.DU_REG], P[T.FILM], tau)
    phi = 0.0
    if dh1 == 0.0:
        return h1, h2, u1x, u1y, u2x, u2y, dh1, phi
    momx = h2 * u2x + r * h1 * u1x  # rho-weighted momentum / rho2
    momy = h2 * u2y + r * h1 * u1y
    if dh1 > 0.0:
        u1x = (h1 * u1x + dh1 * u2x) / (h1 + dh1)
        u1y = (h1 * u1y + dh1 * u2y) / (h1 + dh1)
        phi = min(dh1 / full, 1.0) if full > 0.0 else 1.0
    h1 = h1 + dh1
    h2 = max(h2 - r * dh1, 0.0)
    if h1 <= dry:
        h1 = h1 if h1 > 0.0 else 0.0
        u1x = 0.0
        u1y = 0.0
    if h2 > dry:
        u2x = (momx - r * h1 * u1x) / h2
        u2y = (momy - r * h1 * u1y) / h2
    else:
        u2x = 0.0
        u2y = 0.0
        phi = 0.0
        if h1 > dry:
            u1x = momx / (r * h1)
            u1y = momy / (r * h1)
    return h1, h2, u1x, u1y, u2x, u2y, dh1, phi


def _sources_2d(fk: Any, bed: Any, every_direction: bool) -> Any:
    """The 2D stage on a range of cells with the friction kernels ``fk`` and the 2D bed
    ``bed`` of the basal law (:func:`.friction_2d.implicit_friction_2d`)."""
    friction_params = fk.friction_params
    friction = implicit_friction_2d(fk, bed)
    restore = restore_2d(fk, bed)
    exchange = specialise(_exchange_2d, helper=True)
    target = restoration_target_all if every_direction else restoration_target

    def sources_two_layer_2d(q, dt, t, P, book, fex, lo, hi):
        r = P[T.R]
        g = P[T.G_Z]
        gx = P[T.G_X]
        gy = P[T.G_Y]
        dry = P[T.DRY]
        mode = int(P[T.HYPERBOLICITY])
        moving1 = moving2 = fast1 = fast2 = changed = False
        fp = friction_params(P)
        for i in range(lo, hi + 1):
            if fex[i] != 0.0:
                fex[i] = 0.0
            if (q[0, i] == 0.0 and q[3, i] == 0.0 and q[1, i] == 0.0 and q[2, i] == 0.0
                    and q[4, i] == 0.0 and q[5, i] == 0.0):
                continue
            h1 = max(q[0, i], 0.0)
            h2 = max(q[3, i], 0.0)
            u1x = velocity(h1, q[1, i], dry)
            u1y = velocity(h1, q[2, i], dry)
            u2x = velocity(h2, q[4, i], dry)
            u2y = velocity(h2, q[5, i], dry)
            if dt > 0.0:
                k_eff = P[T.K]
                c_eff = P[T.C]
                if h1 > 0.0 and int(P[T.CLOSURE]) != L.CLOSURE_NONE:
                    h1, h2, u1x, u1y, u2x, u2y, dh1, phi = exchange(h1, h2, u1x, u1y, u2x,
                                                                     u2y, dt, P)
                    if dh1 != 0.0:
                        if phi > 0.0:
                            k_eff = P[T.K] + phi * (1.0 - P[T.K])
                            c_eff = (1.0 - phi) * P[T.C]
                        changed = True
                        if dh1 < 0.0:
                            book[T.D_DEPOSITED] -= dh1
                        else:
                            book[T.D_ERODED] += dh1
                b1x = u1x + dt * gx if h1 > dry else 0.0
                b1y = u1y + dt * gy if h1 > dry else 0.0
                b2x = u2x + dt * gx if h2 > dry else 0.0
                b2y = u2y + dt * gy if h2 > dry else 0.0
                v1x, v1y, v2x, v2y = friction(b1x, b1y, b2x, b2y, h1, h2, dt, fp, 0.0, 0.0,
                                              k_eff, c_eff)
                if mode != L.HYPERBOLICITY_NONE and h1 > dry and h2 > dry:
                    dux = v1x - v2x
                    duy = v1y - v2y
                    bad, edge = target(h1, h2, math.sqrt(dux * dux + duy * duy), g, r, mode)
                    if bad:
                        f, v1x, v1y, v2x, v2y, bisected = restore(
                            b1x, b1y, b2x, b2y, h1, h2, v1x, v1y, v2x, v2y, dt, fp, k_eff,
                            c_eff, edge)
                        if bisected:
                            book[T.D_HYP_BISECTIONS] += 1.0
                        fex[i] = f / r
                        book[T.D_HYP_EVENTS] += 1.0
                        if fex[i] > book[T.D_FEXTRA_MAX]:
                            book[T.D_FEXTRA_MAX] = fex[i]
                            book[T.D_FEXTRA_CELL] = i
                            book[T.D_FEXTRA_TIME] = t
                u1x, u1y, u2x, u2y = v1x, v1y, v2x, v2y
            wet1 = h1 > dry
            wet2 = h2 > dry
            m1x = h1 * u1x if wet1 else 0.0
            m1y = h1 * u1y if wet1 else 0.0
            m2x = h2 * u2x if wet2 else 0.0
            m2y = h2 * u2y if wet2 else 0.0
            if m1x != 0.0 or m1y != 0.0:
                moving1 = True
                if h1 > P[T.SLOW_H] and math.sqrt(u1x * u1x + u1y * u1y) >= P[T.SLOW_U]:
                    fast1 = True
            if m2x != 0.0 or m2y != 0.0:
                moving2 = True
                if h2 > P[T.SLOW_H] and math.sqrt(u2x * u2x + u2y * u2y) >= P[T.SLOW_U]:
                    fast2 = True
            q[0, i] = h1
            q[1, i] = m1x
            q[2, i] = m1y
            q[3, i] = h2
            q[4, i] = m2x
            q[5, i] = m2y
        _close_stage(book, t, moving1, fast1, moving2, fast2, changed)

    return specialise(sources_two_layer_2d, STATE, f8, f8, PARAMS, VECTOR, VECTOR, i8, i8)


def _predictor_2d(fk: Any, bed: Any) -> Any:
    """MUSCL's predictor in 2D: zero the momentum of the layers that stage (32) would
    hold at rest (as :func:`.friction.predictor_two_layer`)."""
    friction_params = fk.friction_params
    friction = implicit_friction_2d(fk, bed)

    def predictor_two_layer_2d(q, dt, P, lo, hi):
        dry = P[T.DRY]
        fp = friction_params(P)
        for i in range(lo, hi + 1):
            h1 = max(q[0, i], 0.0)
            h2 = max(q[3, i], 0.0)
            if h1 <= dry and h2 <= dry:
                continue
            wet1 = h1 > dry
            wet2 = h2 > dry
            b1x = velocity(h1, q[1, i], dry) + dt * P[T.G_X] if wet1 else 0.0
            b1y = velocity(h1, q[2, i], dry) + dt * P[T.G_Y] if wet1 else 0.0
            b2x = velocity(h2, q[4, i], dry) + dt * P[T.G_X] if wet2 else 0.0
            b2y = velocity(h2, q[5, i], dry) + dt * P[T.G_Y] if wet2 else 0.0
            u1x, u1y, u2x, u2y = friction(b1x, b1y, b2x, b2y, h1, h2, dt, fp, 0.0, 0.0,
                                          P[T.K], P[T.C])
            if u1x == 0.0 and u1y == 0.0:
                q[1, i] = 0.0
                q[2, i] = 0.0
            if u2x == 0.0 and u2y == 0.0:
                q[4, i] = 0.0
                q[5, i] = 0.0

    return specialise(predictor_two_layer_2d, STATE, f8, PARAMS, i8, i8)
