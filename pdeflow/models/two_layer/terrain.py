r"""The two layers over a bed z_b(x, y) on a 2D grid: their face values.

The global Cartesian form of :mod:`pdeflow.models.single_layer.terrain` for system (24):
depths measured vertically, velocities horizontal, and each layer's momentum gains
-g h_k d(z_b) besides its pressure and coupling terms, so that the upper layer feels
g h1 grad(h1 + h2 + z_b) (the free surface) and the lower one g h2 grad(h2 + r h1 + z_b).
At rest (a lake of two fluids) the interface z_b + h2 and the free surface are flat.

The face values are the single layer's reconstruction applied from the bed up: the
lower layer's over the bed (its top, the interface, rising by the clamped minmod of the
neighbours' between flat and the bed's rise; tilted where a face would be negative),
then the upper layer's over the interface's face values I^-, I^+ the same way (the free
surface's rise between flat and the interface's, e = (I^+ - I^-)/2), so that every
face depth is >= 0 and each layer's two face depths average to its depth. A lake of
both layers keeps both surfaces flat (well balanced); layers flowing parallel to the
bed have face depths equal to their depths; the upper layer alone over the bare bed is
the single layer. The cell term is the MUSCL cell jump of :mod:`.two_d` with each
layer's share of the bed's slope (:mod:`pdeflow.numerics.bed_slope`).
"""

from __future__ import annotations

from ...numerics import layout as L
from ...numerics.bed_slope import clamped, tilted
from ...numerics.compiled import cached
from ..single_layer.terrain import half_rise, put_faces


@cached
def reconstruct_bed(q, work, metric, lo, hi, axis, dry):
    """Face values along ``axis`` (0: x, 1: y) of cells lo..hi over the bed (module
    docstring): work[0] on each cell's low face, work[1] on its high face, rows as ``q``
    (h1, h1u1, h1v1, h2, h2u2, h2v2) [m, m^2/s]."""
    z_lo = L.M_BED + 2 * axis
    stride = int(metric[L.M_AXES, 3 * axis])
    count = int(metric[L.M_AXES, 3 * axis + 1])
    for i in range(lo, hi + 1):
        h1 = max(q[0, i], 0.0)
        h2 = max(q[3, i], 0.0)
        b = 0.5 * (metric[z_lo + 1, i] - metric[z_lo, i])
        d2 = b - clamped(half_rise(q, metric, i, z_lo, 3, stride, count, dry), b)
        m2, p2 = tilted(h2, h2 + d2, h2 - d2)
        e = b + 0.5 * (p2 - m2)  # the interface's half rise across the cell
        d1 = e - clamped(half_rise(q, metric, i, z_lo, 0, stride, count, dry), e)
        m1, p1 = tilted(h1, h1 + d1, h1 - d1)
        put_faces(q, work, i, 3, m2, p2, dry)
        put_faces(q, work, i, 0, m1, p1, dry)
