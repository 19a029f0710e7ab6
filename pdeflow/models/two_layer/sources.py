r"""The source stages (31)-(34) of the split scheme, cell by cell.

One step of length dt (Lie splitting, as in the paper) advects (29) and then applies,
in every wet cell:

2. exchange (31): limited closure (25), see :func:`.exchange.exchange_step`;
   the exchanged mass carries the velocity of the layer it leaves;
3. implicit momentum sources (32): gravity along the bed, Voellmy interface stress
   (t1 - M du where the step eroded, see :mod:`.exchange`), Coulomb basal
   friction, solved for both layers together (:mod:`.friction`);
4. hyperbolicity (33)-(34): where the inner eigenvalues are complex, stage 3 is
   repeated with the smallest extra exchange F_extra that restores hyperbolicity.

Stages 2-4 form ``source_stage``, which is also what the PDE's post-step hook runs; with
dt = 0 it only cleans up (non-negative depths, zero velocity in dry cells), which is what
a method-of-lines solver needs. The stepping loop of the ``fv-split`` solver
(:mod:`pdeflow.numerics.splitting`) calls the same stage on the wet cells only
(``sources``). Both are built per basal law by :func:`stage_kernels` (Coulomb's
closed form at the bed, or a rate-dependent law's, :mod:`.laws`), with the law's kernels
as constants; :data:`source_stage_two_layer` and :data:`sources_two_layer` are the
paper's (Coulomb).
"""

from __future__ import annotations

import functools
import math
from typing import Any

from ...numerics import layout as L
from ...numerics.compiled import PARAMS, STATE, VECTOR, cached, f8, i8, specialise
from ...numerics.rheology import BasalLaw
from ...numerics.state import velocity
from . import layout as T
from .exchange import exchange_step
from .friction import FrictionKernels, bed_under_both, bed_under_lower, friction_kernels
from .friction import friction_params as coulomb_params
from .hyperbolicity import restoration_target
from .laws import law_bed


@functools.cache
def stage_kernels(law: BasalLaw | None) -> tuple[Any, Any, Any]:
    """The two layers' source-stage kernels with the basal law ``law`` (None: the
    paper's Coulomb friction, tan(phi_B)), compiled with the law's kernels as
    constants: stages (31)-(34) on the cells lo..hi ``(q, dt, t, P, diag, lo, hi)`` (the
    others must be dry and at rest, where the stage changes nothing), the same on every
    cell ``(q, dt, t, P, diag)`` (the post-step hook's kernel) and MUSCL's friction
    predictor ``(q, dt, P, lo, hi)``."""
    coulomb = law is None
    bed = (coulomb_params, bed_under_both, bed_under_lower) if coulomb else law_bed(law)
    fk = friction_kernels(*bed, coulomb=coulomb)
    sources = _sources(fk, coulomb)

    def source_stage_two_layer(q, dt, t, P, diag):
        """Stages (31)-(34) on the two-layer state ``q`` in place, for a step ``dt``
        [s]: ``t`` is the time at the end of the step [s]; ``diag`` receives the
        bookkeeping listed in :mod:`pdeflow.numerics.layout` and, from index N_DIAG on,
        F_extra/rho1 per cell [m^2/s^2]."""
        sources(q, dt, t, P, diag, 0, q.shape[1] - 1)

    return sources, specialise(
        source_stage_two_layer, STATE, f8, f8, PARAMS, VECTOR,
        name="source_stage_two_layer" if coulomb else None), fk.predictor


def _sources(fk: FrictionKernels, coulomb: bool) -> Any:
    """The stage on a range of cells with the friction kernels ``fk`` (``coulomb``:
    named as the module's name it is bound to, which a new interpreter imports)."""
    friction_params = fk.friction_params
    implicit_friction = fk.implicit_friction
    restore_to_edge = fk.restore_to_edge

    def sources_two_layer(q, dt, t, P, diag, lo, hi):
        """Stages (31)-(34) on the cells ``lo..hi``."""
        r = P[T.R]
        g = P[T.G_Z]
        gx = P[T.G_X]
        dry = P[T.DRY]
        slow_u = P[T.SLOW_U]
        slow_h = P[T.SLOW_H]
        mode = int(P[T.HYPERBOLICITY])
        closure = int(P[T.CLOSURE])
        moving1 = False
        moving2 = False
        fast1 = False
        fast2 = False
        changed = False
        fex = diag[L.N_DIAG:]
        fp = friction_params(P)
        for i in range(lo, hi + 1):
            h1 = q[0, i]
            m1 = q[1, i]
            h2 = q[2, i]
            m2 = q[3, i]
            if fex[i] != 0.0:
                fex[i] = 0.0
            if h1 == 0.0 and h2 == 0.0 and m1 == 0.0 and m2 == 0.0:
                continue
            h1 = max(h1, 0.0)
            h2 = max(h2, 0.0)
            u1 = velocity(h1, m1, dry)
            u2 = velocity(h2, m2, dry)
            if dt > 0.0:
                # interface stress of (32): the paper's t1 (22) unless erosion rewrites it
                k_eff = P[T.K]
                c_eff = P[T.C]
                # --- (31) mass exchange; the exchanged mass carries the velocity of the layer
                # it leaves (upwind): u1 when depositing, u2 when eroding ------------------
                if h1 > 0.0 and closure != L.CLOSURE_NONE:
                    # exchange_step takes the relaxation time; 0 selects the paper's closure
                    tau = P[T.TAU_STAR] * math.sqrt((h1 + h2) / g) \
                        if closure == L.CLOSURE_RELAXED else 0.0
                    du = u1 - u2
                    dh1, full = exchange_step(h1, h2, du, dt, r, g, P[T.TAN_INT], P[T.K],
                                              P[T.C], P[T.DU_REG], P[T.FILM], tau)
                    if dh1 != 0.0:
                        mom = h2 * u2 + r * h1 * u1  # rho-weighted momentum / rho2
                        phi = 0.0
                        if dh1 > 0.0:
                            u1 = (h1 * u1 + dh1 * u2) / (h1 + dh1)
                            phi = min(dh1 / full, 1.0) if full > 0.0 else 1.0
                        h1 = h1 + dh1
                        h2 = max(h2 - r * dh1, 0.0)
                        if h1 <= dry:
                            h1 = h1 if h1 > 0.0 else 0.0
                            u1 = 0.0
                        # lower layer takes the rest of the (rho-weighted) momentum
                        if h2 > dry:
                            u2 = (mom - r * h1 * u1) / h2
                            if phi > 0.0:
                                # t1 - M du = phi t2 + (1 - phi) t1 (see the module docstring)
                                k_eff = P[T.K] + phi * (1.0 - P[T.K])
                                c_eff = (1.0 - phi) * P[T.C]
                        else:
                            u2 = 0.0
                            if h1 > dry:
                                u1 = mom / (r * h1)
                        changed = True
                        if dh1 < 0.0:
                            diag[T.D_DEPOSITED] -= dh1
                        else:
                            diag[T.D_ERODED] += dh1
                # --- (32) implicit momentum sources ------------------------------------------
                b1 = u1 + dt * gx if h1 > dry else 0.0
                b2 = u2 + dt * gx if h2 > dry else 0.0
                v1, v2 = implicit_friction(b1, b2, h1, h2, dt, fp, 0.0, k_eff, c_eff)
                # --- (33)-(34) hyperbolicity --------------------------------------------------
                if mode != L.HYPERBOLICITY_NONE and h1 > dry and h2 > dry:
                    bad, edge = restoration_target(h1, h2, v1 - v2, g, r, mode)
                    if bad:
                        f, v1, v2, bisected = restore_to_edge(b1, b2, h1, h2, v1, v2, dt, fp,
                                                              k_eff, c_eff, edge)
                        if bisected:
                            diag[T.D_HYP_BISECTIONS] += 1.0
                        fex[i] = abs(f) / r
                        diag[T.D_HYP_EVENTS] += 1.0
                        if fex[i] > diag[T.D_FEXTRA_MAX]:
                            diag[T.D_FEXTRA_MAX] = fex[i]
                            diag[T.D_FEXTRA_CELL] = i
                            diag[T.D_FEXTRA_TIME] = t
                u1 = v1
                u2 = v2
            m1 = h1 * u1 if h1 > dry else 0.0
            m2 = h2 * u2 if h2 > dry else 0.0
            if m1 != 0.0:
                moving1 = True
                if h1 > slow_h and abs(u1) >= slow_u:
                    fast1 = True
            if m2 != 0.0:
                moving2 = True
                if h2 > slow_h and abs(u2) >= slow_u:
                    fast2 = True
            q[0, i] = h1
            q[1, i] = m1
            q[2, i] = h2
            q[3, i] = m2
        _close_stage(diag, t, moving1, fast1, moving2, fast2, changed)

    return specialise(sources_two_layer, STATE, f8, f8, PARAMS, VECTOR, i8, i8,
                      name="sources_two_layer" if coulomb else None)


@cached(inline="always")
def _close_stage(diag, t, moving1, fast1, moving2, fast2, changed):
    """Book a source stage ending at ``t`` [s] in ``diag``: the times of the last motion
    (``moving``: a layer has momentum; ``fast``: faster than SLOW_U where deeper than
    SLOW_H) of layer 1 and 2, whether it changed anything."""
    if moving1:
        diag[T.D_MOVE_UPPER] = t
    if moving2:
        diag[T.D_MOVE_LOWER] = t
    if fast1:
        diag[T.D_FAST_UPPER] = t
    if fast2:
        diag[T.D_FAST_LOWER] = t
    diag[L.D_CHANGED] = 1.0 if (changed or moving1 or moving2) else 0.0
    diag[L.D_T] = t
    diag[L.D_STEPS] += 1.0


sources_two_layer, source_stage_two_layer, predictor_two_layer = stage_kernels(None)
"""the paper's stage kernels (Coulomb friction at the bed)"""
