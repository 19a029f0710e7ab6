"""Equation systems as objects: what a model is, registered by name.

An :class:`EquationSystem` owns everything that is one model's: its registered name
(the name case files use in ``case.models``), its labels, its layers and
their field names with units, its parameter dataclass and py-pde PDE class, its kernel
bundle (:class:`~pdeflow.numerics.model_kernels.ModelKernels`), its summary keys and
how its layers are split from an initial total depth. The solver, cases, runs, checks,
trackers, storage, plotting, sweeps and the app look the system up here instead of
branching on a model's name (Trixi.jl's equations structs and py-pde's PDE classes are
the models followed).

This module sits on the lowest floor (it imports nothing of pdeflow) so that every
floor may look a system up; the systems themselves are defined and registered by
their models (:mod:`pdeflow.models`), which ``import pdeflow`` imports.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Layer:
    """One layer of a system: its rows of the state are (depth, discharge)."""

    depth: str
    """field name of the depth [m], e.g. 'h1'"""
    discharge: str
    """field name of the discharge h u [m^2/s], e.g. 'h1u1'"""
    velocity: str
    """name of the depth-averaged velocity [m/s] in outputs, e.g. 'u1'"""
    label: str
    """what figures and tables call it, e.g. 'upper layer'"""
    style: str
    """how figures draw it, a key of pdeflow.plotting.LAYER_STYLES, e.g. 'upper'"""
    discharge_y: str | None = None
    """field name of the cross-slope discharge h v [m^2/s] on a 2D grid, e.g. 'hv'
    (None: the model is 1D)"""
    velocity_y: str | None = None
    """name of the cross-slope velocity [m/s] on a 2D grid, e.g. 'v'"""


@dataclass(frozen=True)
class Quantity:
    """A number of a run's summary that belongs to one system."""

    key: str
    """summary key, e.g. 'lower_stop_time'"""
    label: str
    """what tables call it"""
    unit: str
    """unit ('' if none)"""


@dataclass(frozen=True, eq=False)
class EquationSystem:
    """One model: see the module docstring. Compared and hashed by identity."""

    name: str
    """registered name (case files' ``case.models``, summaries, stored runs)"""
    label: str
    """noun for figures and tables, e.g. 'two layers'"""
    adjective: str
    """for messages, e.g. 'two-layer'"""
    layers: tuple[Layer, ...]
    """the layers, top first, in the order of their rows in the state"""
    parameters_class: type
    """the parameter dataclass (units, defaults, ranges; ``from_dict``, ``to_array``)"""
    pde_class: type
    """the py-pde PDE class (:class:`pdeflow.models.base.GranularPDE` subclass)"""
    kernels: Any
    """its :class:`~pdeflow.numerics.model_kernels.ModelKernels`"""
    densities: Callable[[Any], tuple[float, ...]]
    """parameters -> density of each layer relative to the densest [-] (weights of the
    mass)"""
    layer_depths: Callable[[np.ndarray, np.ndarray, dict, Any], tuple[np.ndarray, ...]]
    """``(h, x, initial, parameters) -> depth of each layer`` [m]: how an initial total
    depth ``h`` at ``x`` [m from the domain's start] is split into the layers
    (``initial``: the case's [initial] table)"""
    summarize: Callable[[Any, float, bool, np.ndarray, np.ndarray, Any], dict[str, Any]]
    """``(diagnostics, t_final, at_rest, x, state data, metric) -> dict``: the system's
    own summary numbers from the fv-split solver's diagnostics (keys :attr:`quantities`;
    ``metric``: the grid's :class:`~pdeflow.numerics.geometry.Metric`)"""
    quantities: tuple[Quantity, ...] = ()
    """the keys :attr:`summarize` adds to the common summary"""
    has_fextra: bool = False
    """whether F_extra (the hyperbolicity-restoring exchange) is part of the model"""
    cell_diagnostic: str | None = None
    """the name of the model's per-cell diagnostic of the last step (what its source
    stage writes after the scheme's slots of the diagnostics array, e.g.
    'fextra_over_rho1'), as :class:`~pdeflow.solvers.diagnostics.SplitDiagnostics` reads
    it; None: the model writes none (the values stay 0)"""
    bytes_per_cell: int = 200
    """peak memory of a run per cell [bytes] (see pdeflow.checks): tracemalloc's peak
    over a run on 200,000 cells without snapshots, rounded up (312 bytes two layers,
    168 one layer)"""
    paper_runout_law: tuple[float, float] | None = None
    """(prefactor, exponent) of the run-out law r = p a^e of the paper's test 5.2"""
    bed_layer: int | None = None
    """index in :attr:`layers` of the layer an erodible bed at rest belongs to (the
    initial shape ``column_on_bed`` adds its bed there); None: the model has no erodible
    layer and runs such cases on the rigid bed"""
    law_kernels: Callable[[Any], Any] | None = None
    """``basal law -> its kernels``: the :attr:`kernels` compiled with the
    rate-dependent basal law that parameters name as their ``basal_law`` (None: the
    model has no such choice)"""
    kernels_2d: Callable[[Any, Any], Any] | None = None
    """``(basal law (None: Coulomb's), parameters) -> the kernels on a 2D grid`` (state:
    each layer's depth, discharge along x and :attr:`Layer.discharge_y`; the parameters
    name the model's compile-time 2D choices); None: the model is 1D and refuses a 2D
    grid"""
    diagnostics: Mapping[str, int] = field(default_factory=dict)
    """the model's own slots of the fv-split diagnostics array, name -> index (named in
    its layout, from :data:`pdeflow.numerics.layout.MODEL_SLOTS`): what its source stage
    books and :attr:`summarize` reads as ``diagnostics.<name>``; ``eroded`` and
    ``deposited`` (exchanged depth summed over cells [m]), if booked, also feed the
    erosion series"""

    def kernels_for(self, parameters: Any, axes: int = 1) -> Any:
        """The kernel bundle for ``parameters`` on a grid of ``axes`` axes:
        :attr:`law_kernels` of their ``basal_law`` if they choose a rate-dependent one,
        else :attr:`kernels` (so that a run compiles its own law's code only); on a 2D
        grid :attr:`kernels_2d` of the law."""
        law = getattr(parameters, "basal_law", None)
        if axes == 2:
            if self.kernels_2d is None:
                raise ValueError(f"the {self.adjective} model has no 2D kernels: it runs "
                                 "on a 1D CartesianGrid or a PolarSymGrid")
            return self.kernels_2d(law, parameters)
        if self.law_kernels is not None and law is not None:
            return self.law_kernels(law)
        return self.kernels

    @property
    def field_names(self) -> tuple[str, ...]:
        """Labels of the state's fields, in order: depth, discharge of each layer."""
        return self.field_names_on(1)

    @property
    def profile_names(self) -> tuple[str, ...]:
        """Names of the depth and velocity profiles (``make_state``, ``--final`` files)."""
        return self.profile_names_on(1)

    def field_names_on(self, axes: int) -> tuple[str, ...]:
        """:attr:`field_names` on a grid of ``axes`` axes (2: each layer's depth,
        discharge along x and :attr:`Layer.discharge_y`)."""
        return tuple(n for layer in self.layers
                     for n in (layer.depth, layer.discharge, layer.discharge_y)[:1 + axes])

    def profile_names_on(self, axes: int) -> tuple[str, ...]:
        """:attr:`profile_names` on a grid of ``axes`` axes (2: each layer's depth,
        velocity along x and :attr:`Layer.velocity_y`)."""
        return tuple(n for layer in self.layers
                     for n in (layer.depth, layer.velocity, layer.velocity_y)[:1 + axes])

    @property
    def summary_keys(self) -> tuple[str, ...]:
        """The system's own summary keys."""
        return tuple(q.key for q in self.quantities)


_REGISTRY: dict[str, EquationSystem] = {}


def register(system: EquationSystem) -> EquationSystem:
    """Register ``system`` under its name (a second system of one name is an error);
    returns it."""
    old = _REGISTRY.get(system.name)
    if old is not None and old is not system:
        raise ValueError(f"an equation system named {system.name!r} is registered already")
    _REGISTRY[system.name] = system
    return system


def unregister(name: str) -> None:
    """Remove the system ``name`` (tests that register a system of their own)."""
    _REGISTRY.pop(name, None)


def names() -> tuple[str, ...]:
    """The registered names, in registration order."""
    return tuple(_REGISTRY)


def get(name: str) -> EquationSystem:
    """The system registered as ``name``; ValueError naming the allowed ones."""
    try:
        return _REGISTRY[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown model {name!r}; allowed: {list(_REGISTRY)}") from None


def of_fields(labels: Any) -> EquationSystem:
    """The system whose state has the field labels ``labels`` (a state or stored run
    without the model's name; on a 1D or a 2D grid): the first registered one, so the
    shipped models win over a later system with the same fields; ValueError if none
    has them."""
    labels = tuple(labels)
    for system in _REGISTRY.values():
        if labels in (system.field_names, system.field_names_on(2)):
            return system
    raise ValueError(f"no model has the state fields {list(labels)}; models: "
                     f"{[(s.name, s.field_names) for s in _REGISTRY.values()]}")
