"""A model over a bed z_b(x, y): ``GranularPDE(bed=...)`` (docs/terrain.md).

The bed is given at the 2D grid's cell corners, an (nx + 1, ny + 1) array of
elevations [m], or as a function z_b(x, y) [m] of the corners' coordinates
(:func:`pdeflow.numerics.geometry.bed_at_corners`). Over a bed depths are vertical and the
slope is the bed's: theta_deg and slope_azimuth_deg are 0, and the scheme's
reconstruction is first order (:mod:`pdeflow.models.single_layer.terrain`,
:mod:`pdeflow.models.two_layer.terrain`).
"""

from __future__ import annotations

from typing import Any


def check_bed(pde: Any, bed: Any) -> Any:
    """``bed``, or ValueError, one line naming the parameter, unless the model and
    scheme of the granular PDE ``pde`` can flow over it: a model with kernels over a
    bed (both of pdeflow's), theta_deg and slope_azimuth_deg 0 and a first-order
    reconstruction (None passes)."""
    if bed is None:
        return None
    system = pde.system
    kernels_2d = system.kernels_for(pde.parameters, 2) \
        if getattr(system, "kernels_2d", None) is not None else None
    if kernels_2d is None or kernels_2d.terrain is None:
        raise ValueError(f"bed: the {system.label} model does not flow over a bed (it "
                         "has no kernels over one)")
    for name in ("theta_deg", "slope_azimuth_deg"):
        value = getattr(pde.parameters, name)
        if value != 0.0:
            raise ValueError(f"{name} must be 0 over a bed (the bed gives the slope), "
                             f"got {value:g}")
    if pde.scheme.reconstruction != "first-order":
        raise ValueError("reconstruction must be 'first-order' over a bed, got "
                         f"{pde.scheme.reconstruction!r}")
    return bed
