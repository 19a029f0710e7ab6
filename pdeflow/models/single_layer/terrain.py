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
the bed is continuous across faces, so a face's Riemann problem sees no bed step; in
each cell the free surface h + z_b is taken flat, so the face depths are

.. math:: h^\mp = h \pm d, \qquad d = (z_b^+ - z_b^-)/2,

and where that would make one negative (a layer thinner than half the bed's rise across
the cell) the surface is tilted so that that face is dry and the other face holds 2h.
The face deeper than the cell carries the cell's momentum (hu, hv), its velocity
scaled by h / h^\pm (Kurganov & Petrova's first order: the momentum is not
reconstructed); the shallower face the cell's velocity. So no face sends more mass
than the cell's momentum and the mass centre moves with the momentum, d/dt sum h x =
sum hu (with the face depths times the cell's velocity it moved at (1 + |d|/h) u,
twice u in the tilted regime: a thin avalanche ran ahead of its momentum). The cell term, the total
jump across the reconstruction inside the cell along an axis, is

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


@cached
def reconstruct_bed(q, work, metric, lo, hi, axis, dry):
    """Face values along ``axis`` (0: x, 1: y) of cells lo..hi over the bed (module
    docstring): work[0] on each cell's low face, work[1] on its high face, (h, hu, hv)
    [m, m^2/s, m^2/s]."""
    z_lo = L.M_BED + 2 * axis
    for i in range(lo, hi + 1):
        h = max(q[0, i], 0.0)
        d = 0.5 * (metric[z_lo + 1, i] - metric[z_lo, i])
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
        um = u * h / hm if hm > h else u  # the thicker face: the cell's momentum
        vm = v * h / hm if hm > h else v
        up = u * h / hp if hp > h else u
        vp = v * h / hp if hp > h else v
        work[0, 0, i] = hm
        work[0, 1, i] = hm * um
        work[0, 2, i] = hm * vm
        work[1, 0, i] = hp
        work[1, 1, i] = hp * up
        work[1, 2, i] = hp * vp


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
