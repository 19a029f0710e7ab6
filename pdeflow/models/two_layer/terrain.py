r"""The two layers over a bed z_b(x, y) on a 2D grid: their face values.

The global Cartesian form of :mod:`pdeflow.models.single_layer.terrain` for system (24):
depths measured vertically, velocities horizontal, and each layer's momentum gains
-g h_k d(z_b) besides its pressure and coupling terms, so that the upper layer feels
g h1 grad(h1 + h2 + z_b) (the free surface) and the lower one g h2 grad(h2 + r h1 + z_b).
At rest (a lake of two fluids) the free surface and the interface are flat: h2 + z_b
and h1 constant.

The face values (Kurganov & Petrova's reconstruction, layer by layer from the bed up)
keep, in each cell, the interface z_b + h2 and the free surface z_b + h2 + h1 flat: with
d = (z_b^+ - z_b^-)/2 the lower layer's face depths are h2 +- d (the low face first),
the upper layer's then h1, since the interface is flat over a flat-topped lower layer.
Where the lower layer is thinner than half the bed's rise across the cell, its surface
tilts so that one face is dry and the other holds 2 h2, and the upper layer's face
depths are those that keep the free surface flat over the tilted interface, tilted in
turn (0 and 2 h1) where that would make one negative; so every face depth is >= 0 and
each layer's two face depths average to its depth. Face momenta are the face depths
times the cell's velocities. The cell term is the MUSCL cell jump of :mod:`.two_d` with
each layer's share of the bed's slope (:mod:`pdeflow.numerics.bed_slope`).
"""

from __future__ import annotations

from ...numerics import layout as L
from ...numerics.compiled import cached
from ...numerics.state import velocity


@cached(inline="always")
def _tilted(h, hm, hp):
    """(low, high) face depths ``hm``, ``hp`` of a layer of depth ``h``, tilted to (0,
    2h) or (2h, 0) where one is negative."""
    if hm < 0.0:
        return 0.0, 2.0 * h
    if hp < 0.0:
        return 2.0 * h, 0.0
    return hm, hp


@cached(inline="always")
def _put(q, work, i, row, hm, hp, dry):
    """The face values of the layer whose depth is row ``row`` of cell ``i``: depths
    ``hm``, ``hp`` and momenta the depths times the cell's velocities."""
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
    docstring): work[0] on each cell's low face, work[1] on its high face, rows as ``q``
    (h1, h1u1, h1v1, h2, h2u2, h2v2) [m, m^2/s]."""
    z_lo = L.M_BED + 2 * axis
    for i in range(lo, hi + 1):
        h1 = max(q[0, i], 0.0)
        h2 = max(q[3, i], 0.0)
        d = 0.5 * (metric[z_lo + 1, i] - metric[z_lo, i])
        m2, p2 = _tilted(h2, h2 + d, h2 - d)
        if m2 == h2 + d:  # the interface flat: the upper layer uniform across the cell
            m1, p1 = h1, h1
        else:  # keep the free surface flat over the tilted interface where possible
            m1, p1 = _tilted(h1, h1 + h2 + d - m2, h1 + h2 - d - p2)
        _put(q, work, i, 3, m2, p2, dry)
        _put(q, work, i, 0, m1, p1, dry)
