"""Common shell of the granular PDE classes: boundaries, rates, post-step hook.

A model owns its physics (parameters, state layout, kernels); the py-pde class here
only assembles the kernels into what py-pde expects:

* :meth:`evolution_rate` - vectorised numpy method-of-lines rate;
* :meth:`make_evolution_rate` - the same rate from compiled numba kernels;
* :meth:`make_post_step_hook` - the operator-split source stage (31)-(34). It reads
  the time step from ``post_step_data[0]``, which the ``fv-split`` solver writes; a
  generic py-pde solver leaves it at 0 and the hook only keeps depths non-negative and
  velocities zero in dry cells.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np
from pde import CartesianGrid, FieldCollection
from pde.pdes.base import PDEBase

from ..numerics import layout as L
from ..numerics.geometry import Metric, bed_at_corners, geometry_of, metric_of
from ..numerics.scheme import Scheme
from ..numerics.state import DRY_TOLERANCE
from .bed import check_bed
from .cells import boundaries, cell_name, flat_hook, flat_rate, layer_fields

BC_NAMES = L.BOUNDARIES


def check_range(name: str, value: Any, low: float, high: float, *,
                low_open: bool = False, high_open: bool = False, unit: str = "") -> float:
    """Return ``float(value)`` or raise ValueError naming the parameter and its range.

    Only real numbers are accepted: strings (even ``"0.5"``) and booleans are rejected
    as wrong types, NaN and inf as out of range.
    """
    if isinstance(value, (str, bytes, bool, np.bool_)):
        raise ValueError(f"{name} must be a number, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    lo_ok = v > low if low_open else v >= low
    hi_ok = v < high if high_open else v <= high
    if not (math.isfinite(v) and lo_ok and hi_ok):
        lb = "(" if low_open else "["
        rb = ")" if high_open else "]"
        u = f" {unit}" if unit else ""
        raise ValueError(f"{name} must lie in {lb}{low}, {high}{rb}{u}, got {value!r}")
    return v


def _named_progress(tracker: Any, t_range: Any) -> Any:
    """``tracker`` with the trackers named 'progress' (also inside 'auto') replaced by
    :class:`pdeflow.trackers.ProgressBar` at 1/100 of the time range."""
    names = ["progress", "consistency"] if tracker == "auto" else tracker
    if isinstance(names, str):
        names = [names]
    if not isinstance(names, (list, tuple)) or "progress" not in names:
        return tracker
    from ..trackers.progress import ProgressBar

    t0, t1 = (0.0, t_range) if np.isscalar(t_range) else t_range
    bar = ProgressBar((float(t1) - float(t0)) / 100)
    return [bar if t == "progress" else t for t in names]


def stop_time(last_moving: float, t_final: float, at_rest: bool) -> float | None:
    """Stop time [s] from the last time a layer moved: None if still moving at the end."""
    if last_moving >= t_final and not at_rest:
        return None
    return float(last_moving)


class ParametersBase:
    """Shared behaviour of the parameter dataclasses: validation on construction,
    construction from a mapping that rejects unknown keys by name, and export."""

    kind = "model"  #: used in error messages, e.g. "two-layer"

    def __post_init__(self) -> None:
        self.validate()

    def validate(self) -> None:  # pragma: no cover - overridden
        raise NotImplementedError

    @classmethod
    def from_dict(cls, data: dict[str, Any]):
        """Build from a mapping, rejecting unknown keys by name."""
        names = {f.name for f in fields(cls)}  # type: ignore[arg-type]
        unknown = sorted(set(data) - names)
        if unknown:
            raise ValueError(f"unknown {cls.kind} parameter(s) {unknown}; "
                             f"allowed: {sorted(names)}")
        return cls(**data)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)  # type: ignore[call-overload]


@dataclass
class SharedParameters(ParametersBase):
    """The parameters both models have: gravity, slope, the dry and rest tolerances
    and the regularisation of the method-of-lines rate. A model's class adds its own
    and checks them in :meth:`validate_model`."""

    g: float = 9.81
    """gravitational acceleration [m/s^2]"""
    theta_deg: float = 0.0
    """bed slope [deg], down-slope along x (a 2D grid: along slope_azimuth_deg)"""
    slope_azimuth_deg: float = 0.0
    """on a 2D grid, the steepest descent's direction from x towards y [deg]; 1D: 0"""
    dry_tolerance: float = DRY_TOLERANCE
    """layers thinner than this have zero velocity [m]"""
    rest_speed: float = 0.01
    """speed below which a layer counts as practically at rest [m/s]"""
    rest_depth: float = 1e-3
    """depth above which the practical-rest test looks at a cell [m]"""
    mol_eps: float = 1e-3
    """velocity scale regularising sgn() in the method-of-lines rate [m/s]"""

    def validate(self) -> None:
        """Raise ValueError naming the first parameter outside its allowed range."""
        check_range("g", self.g, 0, math.inf, low_open=True, unit="m/s^2")
        check_range("theta_deg", self.theta_deg, -90, 90, low_open=True,
                    high_open=True, unit="deg")
        check_range("slope_azimuth_deg", self.slope_azimuth_deg, -180, 180, unit="deg")
        self.validate_model()
        check_range("dry_tolerance", self.dry_tolerance, 0, 1, low_open=True, unit="m")
        check_range("rest_speed", self.rest_speed, 0, math.inf, low_open=True,
                    unit="m/s")
        check_range("rest_depth", self.rest_depth, 0, math.inf, unit="m")
        check_range("mol_eps", self.mol_eps, 0, math.inf, low_open=True, unit="m/s")

    def validate_model(self) -> None:  # pragma: no cover - overridden
        """Check the model's own parameters (see :meth:`validate`)."""

    @property
    def basal_friction_deg(self) -> float:
        """The Coulomb friction angle of the bed [deg] (its ``phi_b_deg``; 0 for a model
        without basal friction)."""
        return float(getattr(self, "phi_b_deg", 0.0))


class GranularPDE(PDEBase):
    """Base of the models' PDE classes (:class:`TwoLayerGranular`,
    :class:`SingleLayerGranular`, ...): a model (its class's :attr:`system`, an
    :class:`~pdeflow.systems.EquationSystem`, and its :attr:`parameters`) assembled
    with a :attr:`scheme` (:class:`~pdeflow.numerics.scheme.Scheme`) and boundaries."""

    explicit_time_dependence = False
    check_implementation = False
    #: the model's equation system (set by each model's class)
    system: Any = None
    #: the parameter dataclass of the model
    parameters_class: type[SharedParameters] = SharedParameters

    @property
    def field_names(self) -> tuple[str, ...]:
        """Names of the fields of the state, in order."""
        return self.system.field_names

    @property
    def kernels(self) -> Any:
        """The model's :class:`~pdeflow.numerics.model_kernels.ModelKernels` for its
        parameters (:meth:`~pdeflow.systems.EquationSystem.kernels_for`) on a 1D grid."""
        return self.system.kernels_for(self.parameters)

    def kernels_of(self, metric: Metric) -> Any:
        """:attr:`kernels` on the grid of ``metric`` (2D kernels on a 2D grid)."""
        return self.system.kernels_for(self.parameters, len(metric.axes))

    def boundary_codes(self, axes: int) -> tuple[int, int]:
        """The low and the high sides' boundary codes the kernels take on a grid of
        ``axes`` axes (:func:`~pdeflow.numerics.layout.sides`; 1D: :attr:`bc_codes`)."""
        if axes == 1:
            return self.bc_codes
        pairs = self.bc_axes * axes if len(self.bc_axes) == 1 else self.bc_axes
        return (L.sides(tuple(BC_NAMES[p[0]] for p in pairs)),
                L.sides(tuple(BC_NAMES[p[1]] for p in pairs)))

    def __init__(self, parameters: SharedParameters | dict | None = None, *,
                 bc: Sequence[str] = ("wall", "open"), scheme: Scheme | str | None = None,
                 flux: str | None = None, reconstruction: str | None = None,
                 limiter: str | None = None, splitting: str | None = None,
                 bed: Any = None, **kwargs: Any):
        """
        Args:
            parameters: the model's parameters (a :attr:`parameters_class` or a dict of
                its fields).
            bc: boundary at (left, right): 'wall' (reflective) or 'open' (transmissive)
                (on a 2D grid: of both axes), or on a 2D grid one such pair per axis,
                ((x low, x high), (y low, y high)).
            scheme: how fv-split discretises it (a
                :class:`~pdeflow.numerics.scheme.Scheme` or its name, e.g.
                'hll/muscl/mc+strang'); default: the paper's, 'hll/first-order'.
            flux, reconstruction, limiter, splitting: the scheme's fields, instead of
                ``scheme`` (a convenience): flux 'hll' (the paper's), 'rusanov' or
                'ifcp' (sharper; Roe's scheme for one layer); reconstruction
                'first-order' (the paper's) or 'muscl' (second order in space,
                advected with SSP-RK2); limiter of 'muscl' 'minmod' or 'mc'; splitting
                'lie' (the paper's) or 'strang'.
            bed: a bed z_b(x, y) under a 2D grid to flow over (:mod:`.bed`); None:
                the plane of theta_deg.
            **kwargs: individual parameters overriding ``parameters``.
        """
        super().__init__()
        self.bc_axes = boundaries(bc)
        """(low, high) boundary names per axis (one pair: every axis)"""
        self.bc = tuple(bc) if len(self.bc_axes) == 1 else self.bc_axes
        self.bc_codes = (BC_NAMES[self.bc_axes[0][0]], BC_NAMES[self.bc_axes[0][1]])
        self.scheme: Scheme = _scheme_of(scheme, flux=flux, reconstruction=reconstruction,
                                         limiter=limiter, splitting=splitting)
        if isinstance(parameters, self.parameters_class):
            parameters = parameters.to_dict()
        self.parameters = self.parameters_class.from_dict({**(parameters or {}),
                                                           **kwargs})
        self.bed = check_bed(self, bed)
        """the bed under a 2D grid (corners' elevations [m] or a function), or None"""

    def __repr__(self) -> str:
        return (f"{type(self).__name__}({self.parameters}, bc={self.bc}, "
                f"scheme={self.scheme.name!r})")

    # --- parameters -----------------------------------------------------------------------
    def parameter_array(self) -> np.ndarray:
        """Flat float64 parameter vector read by the kernels (see numerics.layout)."""
        return self.parameters.to_array()

    # --- solving --------------------------------------------------------------------------
    def solve(self, state: Any, t_range: Any, dt: float | None = None,
              tracker: Any = "auto", **kwargs: Any) -> Any:
        """py-pde's :meth:`~pde.pdes.base.PDEBase.solve`, except that the progress bar
        asked for by name (``tracker="auto"``, the default, or ``"progress"``) is
        :class:`pdeflow.trackers.ProgressBar`: updated at 1/100 of ``t_range`` in
        simulation time, it fills up and says so when ``fv-split`` ends a run at rest
        (py-pde's own bar would stop where the run stopped). ``fv-split`` is told the
        end of the run, the only time at which it shortens a step (observers do not
        change the steps: :mod:`pdeflow.solvers.outputs`)."""
        if kwargs.get("solver") == "fv-split":
            kwargs.setdefault("t_end", float(t_range if np.isscalar(t_range)
                                             else t_range[1]))
        return super().solve(state, t_range, dt, _named_progress(tracker, t_range),
                             **kwargs)

    # --- states ---------------------------------------------------------------------------
    @staticmethod
    def check_grid(grid: Any) -> float:
        """Return dx [m] of a uniform non-periodic 1D grid (a ``CartesianGrid``, or a
        ``PolarSymGrid`` from the axis), else raise."""
        geometry_of(grid)
        return float(grid.discretization[0])

    def geometry(self, grid: Any) -> str:
        """The geometry of ``grid`` (:func:`~pdeflow.numerics.geometry.geometry_of`; a
        2D ``CartesianGrid`` for a model with 2D kernels), checked against the
        boundaries (:meth:`_check_geometry`); cheap, no arrays."""
        two_d = getattr(self.system, "kernels_2d", None) is not None
        return self._check_geometry(geometry_of(grid, two_d=two_d))

    def _check_geometry(self, geometry: str) -> str:
        """``geometry``, or ValueError: on an axisymmetric grid the left boundary is the
        axis and must be 'wall'; boundaries per axis and a slope azimuth need a 2D grid."""
        if len(self.bc_axes) == 2 and geometry != "planar-2d":
            raise ValueError(f"bc gives a pair per axis, {self.bc!r}: a {geometry} grid "
                             "takes one pair (left, right)")
        if geometry != "planar-2d" and self.parameters.slope_azimuth_deg != 0.0:
            raise ValueError("slope_azimuth_deg must be 0 on a 1D grid (the slope is along "
                             f"its axis), got {self.parameters.slope_azimuth_deg:g}")
        if geometry == "axisymmetric" and self.bc[0] != "wall":
            raise ValueError(f"on an axisymmetric grid the left boundary is the axis: "
                             f"bc[0] must be 'wall', got {self.bc[0]!r}")
        return geometry

    def metric(self, grid: Any) -> Metric:
        """The finite-volume metric of ``grid`` (:func:`~pdeflow.numerics.geometry.metric_of`),
        checked against the boundaries; derived once per grid (the last grid's is kept:
        a run, its solver and its summary share it)."""
        last = self.__dict__.get("_metric")
        if last is None or last[0] is not grid:
            self.geometry(grid)  # a 1D model refuses a 2D grid
            self._metric = (grid, metric_of(grid, bed_at_corners(grid, self.bed)))
        return self._metric[1]

    def make_state(self, grid: CartesianGrid, **profiles: np.ndarray) -> FieldCollection:
        """State from depth and velocity profiles (names: the system's
        :meth:`~pdeflow.systems.EquationSystem.profile_names_on` the grid, e.g. h1, u1,
        h2, u2; on a 2D grid h, u, v: arrays of the grid's shape [m, m/s])."""
        axes = 2 if self.geometry(grid) == "planar-2d" else 1
        if self.bed is not None:
            self.metric(grid)  # the bed on this grid, checked before any work
        return layer_fields(self.system, grid, axes, type(self).__name__, profiles)

    def check_state(self, state: FieldCollection) -> Metric:
        """Validate a state for this model and return its grid's :meth:`metric`."""
        metric = self.metric(state.grid)
        names = self.system.field_names_on(len(metric.axes))
        if state.data.shape[0] != len(names):
            raise ValueError(f"state must have {len(names)} fields "
                             f"{names}, got {state.data.shape[0]}")
        # each field as py-pde holds it (a view: flattening a 2D state would copy it);
        # np.flatnonzero numbers its cells as the kernels do
        for k, name in enumerate(names):
            if np.isfinite(state.data[k]).all():
                continue
            bad = np.flatnonzero(~np.isfinite(state.data[k]))
            raise ValueError(f"{name} must be finite (no NaN or inf), got "
                             f"{state.data[k].flat[bad[0]]} in "
                             f"{cell_name(state.grid, bad[0])} and {bad.size - 1} more")
        for k in range(0, len(names), len(names) // len(self.system.layers)):
            if state.data[k].min() >= 0:
                continue
            bad = np.flatnonzero(state.data[k] < 0)
            raise ValueError(f"{names[k]} must be >= 0 m, got "
                             f"{state.data[k].flat[bad[0]]:g} in "
                             f"{cell_name(state.grid, bad[0])} and {bad.size - 1} more")
        return metric

    # --- rates ----------------------------------------------------------------------------
    def evolution_rate(self, state: FieldCollection, t: float = 0) -> FieldCollection:
        """Method-of-lines rate: HLL flux divergence (29) plus sources (26)-(27)."""
        self._require_numpy_variant(state.grid)
        dx = float(state.grid.discretization[0])
        P = self.parameter_array()
        q = state.data
        rate, _ = self.kernels.numpy_advection(q, dx, self.bc_codes, P)
        rate += self.kernels.numpy_sources(q, P)
        out = state.copy()
        out.data[...] = rate
        return out

    def _require_numpy_variant(self, grid: Any) -> None:
        if self.scheme.spatial != "hll/first-order":
            raise NotImplementedError(
                f"the numpy backend implements hll/first-order only, not "
                f"{self.scheme.spatial}; use the numba backend")
        if self.geometry(grid) != "planar":
            raise NotImplementedError("the numpy backend implements the planar geometry "
                                      "only; use the numba backend")

    def make_evolution_rate(self, state: FieldCollection, backend: Any) -> Callable:
        """Compiled method-of-lines rate (numba backend): the advection rate of this
        model's scheme (only that scheme is compiled) plus the sources (26)-(27)."""
        name = getattr(backend, "name", str(backend))
        if name not in ("numba",):
            raise NotImplementedError(f"no compiled rate for backend {name}")
        from numba import njit

        from ..numerics.advection import rate_kernel
        from ..numerics.compiled import ready

        metric = self.metric(state.grid)
        dx, M = metric.dx, metric.array()
        P = self.parameter_array()
        kernels = self.kernels_of(metric)
        bcl, bcr = self.boundary_codes(len(metric.axes))
        g, r, dry = kernels.constants(P)
        advect = ready(rate_kernel(kernels, *self.scheme.codes, metric.code))
        sources = ready(kernels.mol_sources)
        if len(metric.axes) > 1:
            return flat_rate(advect, sources, state.data.shape, dx, M, bcl, bcr, g, r,
                             dry, P)
        shape = (2, *state.data.shape)  # closure arrays are read-only in numba

        @njit
        def rate(state_data, t):  # pragma: no cover - compiled
            out = np.empty_like(state_data)
            work = np.empty(shape)
            advect(state_data, out, work, dx, M, bcl, bcr, g, r, dry)
            sources(state_data, out, P)
            return out

        return rate

    # --- operator splitting ---------------------------------------------------------------
    def new_diagnostics(self, n_cells: int) -> np.ndarray:
        """Fresh post-step data: bookkeeping followed by F_extra/rho1 per cell."""
        return np.zeros(L.N_DIAG + n_cells)

    def source_kernel(self) -> Callable:
        """The compiled source stage ``(q, dt, t, P, diag) -> None`` of this model."""
        return self.kernels.source_stage

    def make_post_step_hook(self, state: FieldCollection, backend: Any = "numpy"):
        """Post-step hook applying the split source stage with dt = data[0].

        Every py-pde solver builds this hook before its first step, so the initial
        state is validated here (:meth:`check_state`) whatever the solver. A step that
        left a non-finite value or a depth below -1e-12 m is counted in
        ``data[D_BAD_STEPS]`` before the kernel clips it (generic solvers have no other
        check; fv-split rejects such steps itself).
        """
        from ..numerics.compiled import ready

        metric = self.check_state(state)
        P = self.parameter_array()
        kernel = self.kernels_of(metric).source_stage
        name = getattr(backend, "name", str(backend))
        kernel = kernel.py_func if name == "numpy" else ready(kernel)
        if len(metric.axes) > 1:
            return (flat_hook(kernel, state.data.shape, P),
                    self.new_diagnostics(state.grid.num_cells))

        def post_step_hook(state_data, t, post_step_data):
            dt = post_step_data[0]
            if not (np.all(np.isfinite(state_data)) and np.all(state_data[::2] >= -1e-12)):
                post_step_data[L.D_BAD_STEPS] += 1.0  # the kernel clips what it counts
            kernel(state_data, dt, t + dt, P, post_step_data)
            return state_data, post_step_data

        return post_step_hook, self.new_diagnostics(state.grid.shape[0])


def _scheme_of(scheme: Scheme | str | None, **fields: str | None) -> Scheme:
    """The scheme of ``GranularPDE(scheme=..., flux=..., ...)``: ``scheme`` (a
    :class:`Scheme` or its name) or the scheme of the given ``fields`` (the others the
    paper's), not both (ValueError)."""
    given = {k: v for k, v in fields.items() if v is not None}
    if scheme is not None and given:
        raise ValueError(f"give the scheme or its fields, not both: scheme={scheme!r} "
                         f"and {', '.join(f'{k}={v!r}' for k, v in given.items())}")
    if isinstance(scheme, Scheme):
        return scheme
    if scheme is not None:
        return Scheme.parse(scheme)
    return Scheme(**given)
