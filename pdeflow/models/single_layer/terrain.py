r"""The single layer over a bed z_b(x, y) on a 2D grid: its face values.

The global Cartesian form of the shallow-layer equations (docs/terrain.md): depth h
measured vertically [m], velocity (u, v) horizontal [m/s], gravity g vertical, the
bed's elevation z_b [m] at the cell corners (:func:`pdeflow.numerics.geometry.face_beds`
gives each cell's bed at the middle of its faces):

.. math::
   \partial_t h + \nabla\cdot(h\mathbf{u}) &= 0 \\
   \partial_t(h\mathbf{u}) + \nabla\cdot(h\mathbf{u}\otimes\mathbf{u})
     + g h \nabla(h + z_b) &= -\frac{\mathbf{u}}{|\mathbf{u}|}\, g h \tan\varphi_B

(the basal law's deceleration in place of Coulomb's, :mod:`.sources_2d`). The scheme
follows Kurganov & Petrova (2007, Commun. Math. Sci. 5, 133), with the
polynomial-viscosity fluctuations of :mod:`.two_d`: the bed is continuous across faces,
so a face's Riemann problem sees no bed step. In each cell, along an axis, the free
surface w = h + z_b rises by 2s across the cell, s half the minmod of its differences
with the two neighbours (0 in a dry cell and at the axis' ends), clamped between 0 (a
flat surface) and the bed's half rise b = (z_b^+ - z_b^-)/2 (a surface parallel to the
bed). The face depths are

.. math:: h^\mp = h \pm d, \qquad d = b - s,

and where one would be negative (a shore: a layer thinner than |d|) the surface tilts so
that that face is dry and the other holds 2h. Face momenta are the face depths times the
cell's velocity. A lake at rest has s = 0 (flat: well balanced); a layer whose surface
follows the bed has s = b and face depths h on both sides, so the faces pass the mass
its momentum carries (d/dt sum h x = sum hu up to the layer's ends) and a thin layer on
a steep coarse grid feels the whole slope; on a horizontal bed the scheme is the
plane's. The cell term is the MUSCL cell jump (:func:`.two_d.cell_jump`) and the bed's
slope (:mod:`pdeflow.numerics.bed_slope`),

.. math:: \mathcal{A} = f(q^+) - f(q^-) + g \bar h\,(z_b^+ - z_b^-),
          \qquad \bar h = (h^- + h^+)/2 = h,

whose pressure and bed parts together are g h ((h^+ + z_b^+) - (h^- + z_b^-)): zero to
round-off for a lake at rest. The hydrostatic reconstruction of Audusse et al. (2004)
gives a layer thinner than the relief of a cell a fraction of the slope (Delestre et
al. 2012), and so does a flat surface in every cell (face depths 0 and 2h: the mass
then runs ahead of its momentum). With the face depths non-negative and averaging to h,
the update keeps h >= 0 for a Courant number sum up to 1/2 (the solver's ``cfl`` is
checked).
"""

from __future__ import annotations

from ...numerics import layout as L
from ...numerics.bed_slope import clamped, surface_half_rise, tilted
from ...numerics.compiled import cached
from ...numerics.state import velocity


@cached(inline="always")
def surface(q, metric, i, z_lo, row):
    """The top [m] of the layer whose depth is row ``row`` of cell ``i`` and of all
    below it, over the cell's bed (the mean of its faces' along the axis whose low-face
    row of the metric is ``z_lo``); ``row`` 0 of the single layer."""
    top = 0.5 * (metric[z_lo, i] + metric[z_lo + 1, i])
    for k in range(row, q.shape[0], 3):
        top += max(q[k, i], 0.0)
    return top


@cached(inline="always")
def half_rise(q, metric, i, z_lo, row, stride, count, dry):
    """:func:`~pdeflow.numerics.bed_slope.surface_half_rise` of :func:`surface` across
    cell ``i`` along the axis (``stride``, ``count`` cells); 0 at the axis' ends and
    where the layer of row ``row`` is dry."""
    k = (i // stride) % count
    if k == 0 or k == count - 1 or q[row, i] <= dry:
        return 0.0
    return surface_half_rise(surface(q, metric, i, z_lo, row),
                             surface(q, metric, i - stride, z_lo, row),
                             surface(q, metric, i + stride, z_lo, row))


@cached(inline="always")
def put_faces(q, work, i, row, hm, hp, dry):
    """Face values of the layer whose depth is row ``row`` of cell ``i``: depths ``hm``,
    ``hp`` and momenta the depths times the cell's velocities."""
    h = max(q[row, i], 0.0)
    u = velocity(h, q[row + 1, i], dry)
    v = velocity(h, q[row + 2, i], dry)
    work[0, row, i] = hm
    work[0, row + 1, i] = hm * u
    work[0, row + 2, i] = hm * v
    work[1, row, i] = hp
    work[1, row + 1, i] = hp * u
    work[1, row + 2, i] = hp * v


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
        b = 0.5 * (metric[z_lo + 1, i] - metric[z_lo, i])
        d = b - clamped(half_rise(q, metric, i, z_lo, 0, stride, count, dry), b)
        hm, hp = tilted(h, h + d, h - d)
        put_faces(q, work, i, 0, hm, hp, dry)
