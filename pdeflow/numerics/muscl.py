"""MUSCL's face values: each layer's depth and velocities reconstructed linearly in every
cell along an axis with a limited slope (minmod or monotonised central), for the
advection stage of :mod:`pdeflow.numerics.advection`."""

from __future__ import annotations

import functools
from typing import Any

from . import layout as L
from .compiled import STATE, WORK, cached, f8, i8, specialise
from .state import velocity


@cached
def _limited(a: float, b: float, limiter: int) -> float:
    if a * b <= 0.0:
        return 0.0
    s = 1.0 if a > 0.0 else -1.0
    a = abs(a)
    b = abs(b)
    if limiter == L.LIMITER_MC:
        return s * min(2.0 * a, 2.0 * b, 0.5 * (a + b))
    return s * min(a, b)


@functools.cache
def reconstruction(width: int, normal: int) -> Any:
    """MUSCL's face values along one axis for a model with ``width`` rows per layer whose
    momentum normal to the axis' faces is row ``normal`` of a layer (compiled for these
    constants: the loops over a layer's rows unroll):

    ``reconstruct_muscl(q, work, lo, hi, stride, count, bc_lo, bc_hi, dry, limiter)``
    writes the face values of cells lo..hi along the axis (``stride`` in the cell index,
    ``count`` cells) into work[0] (the face on the low side) and work[1] (the high
    side): each layer's depth and velocities linearly with limited slopes; ghost
    neighbours from the boundary codes of the axis' sides (a wall mirrors the normal
    velocity)."""

    def reconstruct_muscl(q, work, lo, hi, stride, count, bc_lo, bc_hi, dry, limiter):
        block = stride * count
        c0 = (lo // block) * block
        while c0 <= hi:
            for i in range(max(c0, lo), min(c0 + block - 1, hi) + 1):
                has_l = i - c0 >= stride
                has_r = i - c0 < block - stride
                il = i - stride if has_l else i
                ir = i + stride if has_r else i
                for k in range(0, q.shape[0], width):
                    h = q[k, i]
                    hl = q[k, il]
                    hr = q[k, ir]
                    # next to a dry cell (a front or a heap's edge): first order, so that
                    # the face depth weighting the hydrostatic jump is the cell's own
                    flat = hl <= dry or hr <= dry
                    if not flat:
                        # at rest with its neighbours: first order as well. A limited
                        # slope of h can make the hydrostatic force at a kink of a heap
                        # steeper than any slope of the data, so that friction no longer
                        # holds a heap the first-order scheme keeps exactly at rest;
                        # nothing moves here to gain accuracy on
                        flat = True
                        for j in range(k + 1, k + width):
                            if q[j, i] != 0.0 or q[j, il] != 0.0 or q[j, ir] != 0.0:
                                flat = False
                    sh = 0.0 if flat else _limited(h - hl, hr - h, limiter)
                    hm = h - 0.5 * sh
                    hp = h + 0.5 * sh
                    work[0, k, i] = hm
                    work[1, k, i] = hp
                    for j in range(k + 1, k + width):
                        u = velocity(h, q[j, i], dry)
                        mirror = -u if j == k + normal else u
                        if has_l:
                            ul = velocity(hl, q[j, il], dry)
                        else:
                            ul = mirror if bc_lo == L.BC_WALL else u
                        if has_r:
                            ur = velocity(hr, q[j, ir], dry)
                        else:
                            ur = mirror if bc_hi == L.BC_WALL else u
                        su = 0.0 if flat else _limited(u - ul, ur - u, limiter)
                        work[0, j, i] = hm * (u - 0.5 * su) if hm > dry else 0.0
                        work[1, j, i] = hp * (u + 0.5 * su) if hp > dry else 0.0
            c0 += block

    return specialise(reconstruct_muscl, STATE, WORK, i8, i8, i8, i8, i8, i8, f8, i8,
                      helper=True)
