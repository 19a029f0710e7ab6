"""What the model-independent numerics need of an equation system: its kernels.

The stepping loop (:mod:`.splitting`), the advection stage and the method-of-lines rate
(:mod:`.advection`) are written once for every model; a :class:`ModelKernels` hands them
one model's pieces. An equation system (:class:`pdeflow.systems.EquationSystem`) owns
one; each model builds its own in its package (``pdeflow.models.<name>.kernels``, one per
basal law). Nothing in :mod:`pdeflow.numerics` branches on which model it runs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import layout as L


@dataclass(frozen=True, eq=False)
class ModelKernels:
    """The kernels of one equation system (compared and hashed by identity, so that the
    kernel factories cache one build per bundle).

    State ``q[field, cell]`` holds each layer's depth [m] and then its discharge along
    each axis [m^2/s] (:attr:`layer_rows` rows per layer; cells flattened, see
    :mod:`.geometry`). The scheme reads no field by name: it takes a face's states in
    the face's normal frame from :attr:`face` and puts the fluctuations back into the
    rows :attr:`rows` names.
    """

    fields: int
    """rows of the state"""
    face: Any
    """``face(q, i, axis, sign) -> tuple``: the state of cell (or face value) i in the
    frame of a face normal to ``axis``: each layer's depth, momentum normal to the face
    times ``sign`` (-1: a wall's mirror image), then its tangential momenta"""
    fluctuations: Callable[[int], Any]
    """flux code (layout.FLUX_*) -> ``fluct(left, right, g, r, dry) -> (D^-, D^+, smax)``
    in the face's normal frame (tuples as :attr:`face`'s)"""
    cell_jump: Any
    """MUSCL: ``cell_jump(qm, qp, rate, lo, hi, inv_dx, g, r, dry, axis)`` subtracts the
    flux difference along ``axis`` across the reconstruction inside cells lo..hi"""
    sources: Any
    """source stage on cells lo..hi: ``sources(q, dt, t, P, diag, lo, hi)``; on a 2D
    grid ``sources(q, dt, t, P, book, fex, lo, hi)``: its bookkeeping into ``book`` (a
    row's, :mod:`.threads`), its per-cell diagnostic into ``fex``"""
    source_stage: Any
    """the same on every cell, ``(q, dt, t, P, diag)``: the post-step hook's kernel"""
    predictor: Any
    """MUSCL's friction predictor ``(q, dt, P, lo, hi)`` (see :mod:`.friction`)"""
    mol_sources: Any
    """method of lines: ``mol_sources(q, rate, P)`` adds the regularised source rate"""
    numpy_advection: Callable[..., tuple[np.ndarray, float]]
    """numpy twin of the HLL first-order advection: ``(q, dx, bc, P) -> (rate, smax)``"""
    numpy_sources: Callable[[np.ndarray, np.ndarray], np.ndarray]
    """numpy twin of ``mol_sources``: ``(q, P) -> rate``"""
    constants: Callable[[np.ndarray], tuple[float, float, float]]
    """``P -> (g_z [m/s^2], coupling r [-] (0 without), dry tolerance [m])``: the
    scalars the advection kernels take"""
    fold: Any = None
    """2D: ``fold(diag, book)`` adds a row's booking (:attr:`sources` from zeros) to
    ``diag``'s model slots, called in row order (:func:`.threads.box_kernels`)"""
    terrain: Any = None
    """2D over a bed (layout.GEOMETRY_TERRAIN_2D): the face values of cells lo..hi
    with free surface and interfaces flat, ``reconstruct(q, work, metric, lo, hi, axis,
    dry)`` (the cell term is :attr:`cell_jump` and :mod:`.bed_slope`); None: the model
    does not flow over a bed"""
    layer_rows: int = 2
    """rows per layer: its depth, then its discharge along each axis"""
    rows: tuple[tuple[int, ...], ...] = ()
    """per axis, the row of ``q`` each entry of a fluctuation (a :attr:`face` tuple) goes
    back into (default: one axis, in the order of ``q``)"""

    fluxes: tuple[int, ...] = (L.FLUX_HLL, L.FLUX_RUSANOV, L.FLUX_IFCP)
    """the flux codes :attr:`fluctuations` answers (a flux added by
    :func:`~pdeflow.numerics.scheme.register_flux` runs only on models that list it:
    :func:`check_flux`)"""

    def axis_rows(self, axis: int) -> tuple[int, ...]:
        """:attr:`rows` of ``axis`` (the identity if none are given)."""
        return self.rows[axis] if self.rows else tuple(range(self.fields))


def check_flux(model: ModelKernels, flux: int) -> None:
    """Raise ValueError naming the fluxes ``model`` has fluctuations for unless ``flux``
    (layout.FLUX_*) is one of them: a model does not fall back on another flux."""
    if flux not in model.fluxes:
        names = {code: name for name, code in L.FLUXES.items()}
        raise ValueError(f"flux must be one of {[names[c] for c in model.fluxes]} for "
                         f"this model, got {names.get(flux, flux)!r}")
