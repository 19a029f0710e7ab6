r"""The single layer over a bed z_b(x, y) on a 2D grid: face values and the cell term.

The global Cartesian form of the shallow-layer equations (docs/terrain.md): depth h
measured vertically [m], velocity (u, v) horizontal [m/s], gravity g vertical, the
bed's elevation z_b [m] at the cell corners (:func:`pdeflow.numerics.geometry.face_beds`
gives each cell's bed at the middle of its faces):

.. math::
   \partial_t h + \nabla\cdot(h\mathbf{u}) &= 0 \\
   \partial_t(h\mathbf{u}) + \nabla\cdot(h\mathbf{u}\otimes\mathbf{u})
     + g h \nabla(h + z_b) &= -\frac{\mathbf{u}}{|\mathbf{u}|}\, g h \tan\varphi_B

(the basal law's deceleration in place of Coulomb's, :mod:`.sources_2d`). The scheme is
Kurganov & Petrova's (2007, Commun. Math. Sci. 5, 133) positivity-preserving
well-balanced reconstruction with the polynomial-viscosity fluctuations of :mod:`.two_d`:
the bed is continuous across faces, so a face's Riemann problem sees no bed step. In
each cell the free surface w = h + z_b rises by 2s across the cell, s the minmod of its
one-sided differences with the neighbours along the axis, halved, and then clamped
between 0 (a flat surface) and the bed's half rise b = (z_b^+ - z_b^-)/2 (a surface
parallel to the bed); s = 0 in a dry cell and at the axis' ends. The face depths are

.. math:: h^\mp = h \pm d, \qquad d = b - s,

and where that would make one negative (a layer thinner than |d|: at a shore, or a
layer thinner than the bed's half rise with its surface flat) the surface is tilted
so that that face is dry and the other face holds 2h. Face momenta are the face depths
times the cell's velocity. A lake at rest has s = 0 (flat: well balanced); a
flowing layer whose surface follows the bed has s = b, face depths h on both sides, so
the faces pass the mass the momentum carries, d/dt sum h x = sum hu (up to the ends of
the layer); on a horizontal bed s = 0 and the scheme is the plane's first-order one.
(With s = 0 everywhere, as first built, a layer thinner than the bed's half rise had
face depths 0 and 2h in every cell: the mass moved at twice its velocity, (1 + |b|/h)
times it when thicker, and a thin avalanche's energy line was lost.) The cell term, the
total jump across the reconstruction inside the cell along an axis, is

.. math:: \mathcal{A} = f(q^+) - f(q^-) + g \bar h\,(z_b^+ - z_b^-),
          \qquad \bar h = (h^- + h^+)/2 = h,

whose pressure and bed parts together are g h ((h^+ + z_b^+) - (h^- + z_b^-)): zero to
round-off for a lake at rest (h + z_b constant, u = 0), and g h times the bed's rise
for a layer thinner than the relief, so that a thin layer on a steep coarse grid feels
the slope (the hydrostatic reconstruction of Audusse et al. 2004 loses it there:
Delestre et al. 2012). With the face depths non-negative and averaging to h, the update
keeps h >= 0 for a Courant number sum up to 1/2 (the solver's ``cfl`` is checked).
"""

from __future__ import annotations

from ...numerics import layout as L
from ...numerics.compiled import cached
from ...numerics.state import velocity


@cached(inline="always")
def _surface(q, metric, i, z_lo):
    """The free surface h + z_b [m] of cell ``i``, its bed the mean of its faces'."""
    return max(q[0, i], 0.0) + 0.5 * (metric[z_lo, i] + metric[z_lo + 1, i])


@cached(inline="always")
def _half_rise(q, metric, i, z_lo, stride, k, count, dry):
    """Half the rise of the surface across cell ``i`` (the ``k``-th of ``count`` along
    the axis, neighbours ``stride`` apart) [m]: the minmod of its one-sided differences
    with the neighbours; 0 at the axis' ends and in a dry cell."""
    if k == 0 or k == count - 1 or q[0, i] <= dry:
        return 0.0
    w = _surface(q, metric, i, z_lo)
    a = w - _surface(q, metric, i - stride, z_lo)
    b = _surface(q, metric, i + stride, z_lo) - w
    if a * b <= 0.0:
        return 0.0
    return 0.5 * (a if abs(a) < abs(b) else b)


@cached
def reconstruct_bed(q, work, metric, lo, hi, axis, dry):
    """Face values along ``axis`` (0: x, 1: y) of cells lo..hi over the bed (module
    docstring): work[0] on each cell's low face, work[1] on its high face, (h, hu, hv)
    [m, m^2/s, m^2/s]."""
    z_lo = L.M_BED + 2 * axis
    stride = int(metric[L.M_AXES, 3 * axis])
    count = int(metric[L.M_AXES, 3 * axis + 1])
    for i in range(lo, hi + 1):
        h = max(q[0, i], 0.0)
        bed = 0.5 * (metric[z_lo + 1, i] - metric[z_lo, i])  # the bed's half rise
        s = _half_rise(q, metric, i, z_lo, stride, (i // stride) % count, count, dry)
        s = min(max(s, min(bed, 0.0)), max(bed, 0.0))  # between flat and the bed's
        d = bed - s
        hm = h + d
        hp = h - d
        if hm < 0.0:  # thinner than the bed's half rise: the surface tilts, dry at the top
            hm = 0.0
            hp = 2.0 * h
        elif hp < 0.0:
            hm = 2.0 * h
            hp = 0.0
        u = velocity(h, q[1, i], dry)
        v = velocity(h, q[2, i], dry)
        work[0, 0, i] = hm
        work[0, 1, i] = hm * u
        work[0, 2, i] = hm * v
        work[1, 0, i] = hp
        work[1, 1, i] = hp * u
        work[1, 2, i] = hp * v


@cached
def bed_jump(qm, qp, rate, metric, lo, hi, inv_dx, g, dry, axis):
    """Subtract the cell term along ``axis`` (module docstring) from ``rate`` in cells
    lo..hi: the flux difference across the face values ``qm`` (low face), ``qp`` (high
    face) with the pressure and the bed's slope as g h d(h + z_b); ``inv_dx`` [1/m]."""
    n = 1 + axis
    t = 2 - axis
    z_lo = L.M_BED + 2 * axis
    for i in range(lo, hi + 1):
        hl, hr = qm[0, i], qp[0, i]
        if hl == 0.0 and hr == 0.0:
            continue
        ul = velocity(hl, qm[n, i], dry)
        ur = velocity(hr, qp[n, i], dry)
        vl = velocity(hl, qm[t, i], dry)
        vr = velocity(hr, qp[t, i], dry)
        rise = metric[z_lo + 1, i] - metric[z_lo, i]
        rate[0, i] -= (ur * hr - ul * hl) * inv_dx
        rate[n, i] -= (ur * ur * hr - ul * ul * hl
                       + g * 0.5 * (hl + hr) * ((hr - hl) + rise)) * inv_dx
        rate[t, i] -= (ur * hr * vr - ul * hl * vl) * inv_dx
