"""Case files: TOML schema, validation, and the built-in initial shapes.

A case file is data, never code: it is parsed with ``tomllib`` and every key is
checked against the schema below; an unknown key or a wrong type is an error that
names the key and the file. Sections (all optional except ``[initial]``)::

    [case]        name, description, t_end [s], models = ["two_layer", "single_layer"]
    [grid]        length [m], dx [m] (or cells), x_start [m]; a 2D grid: width [m],
                  dy [m] (or cells_y), y_start [m]
    [boundaries]  left, right = "wall" | "open"; on a 2D grid y_low, y_high too
    [initial]     shape = "column" | "column_on_bed" | "dam_break" | "heap" | "file"
                  and its keys
    [numerics]    solver = "fv-split" | any py-pde solver name, cfl, dt (py-pde solvers),
                  flux = "hll" | "rusanov" | "ifcp", reconstruction = "first-order" |
                  "muscl", limiter = "minmod" | "mc", splitting = "lie" | "strang"
    [two_layer]   any field of TwoLayerParameters
    [single_layer] any field of SingleLayerParameters
    [output]      snapshot_times [s], front_threshold [m], runout_mass_fraction
    [sweep]       aspect_ratios = [a, ...] (H0 = a L0; see pdeflow.analysis.sweep)
    [terrain]     a 2D single-layer case over a bed: bed = a topography's name or a DEM's
                  path, x0, y0 [m], release = a shapefile's outline (the polygon shape),
                  [terrain.topography] the topography's parameters
                  (pdeflow.case_terrain); initial.measured = "slope_normal" | "vertical"

Initial shapes (x measured from the left end of the domain; the 2D shapes cylinder,
elliptic_column, cap, box and polygon are those of :mod:`pdeflow.initial_shapes_2d`):

* ``column``: a column of length L0 [m] and height H0 [m] against the left end. For
  two layers the lower layer is the wedge h2 = min(H0, (L0 - x) tan(alpha)) under the
  upper layer h1 = H0 - h2, alpha = ``wedge_angle_deg`` (default 45 + phi_int/2, the
  Rankine active failure plane; the paper's text says pi/4 + phi_int, see docs).
* ``column_on_bed``: the column on an erodible bed: a layer of ``bed_thickness`` [m]
  at rest from x = L0 over ``bed_length`` [m] (default: to the domain's end). For two
  layers the bed is part of the lower layer (under the column's wedge it is absent);
  the single layer has no erodible layer and runs on the rigid bed (its summary says
  ``bed = 'rigid'``).
* ``dam_break``: depth h_left for x < x_dam and h_right beyond (single layer; for two
  layers ``upper_fraction`` of each depth is put in the upper layer).
* ``heap``: a symmetric triangular heap of height ``height`` [m] with flanks at
  ``slope_deg`` [deg] centred at ``center`` [m] (split like dam_break for two layers).
* ``file``: an ``.npz`` with arrays h1, u1, h2, u2 (two layers) or h, u (single layer)
  on the case's grid (same number of cells), ``path`` relative to the case file.
"""

from __future__ import annotations

import copy
import math
import sys
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from . import systems
from .case_2d import GridAcross
from .case_schema import CaseError
from .case_terrain import release_vertices
from .case_validation import validate as _validate
from .initial_shapes import (
    bed_depth,
    bed_region,
    has_bed,
    profiles_from_file,
    total_depth,
)
from .metrics import RUNOUT_MASS_FRACTION
from .variant import Variant, variant_of

PAPER_MODEL = "two_layer"
"""the registered name of the paper's two-layer model"""
BASELINE_MODEL = "single_layer"
"""the registered name of the single-layer Coulomb baseline (exact solutions are its)"""
DEFAULT_MODELS = [PAPER_MODEL]
"""case.models when a case names none"""
SERIES_FRAMES = 200
"""frames of the erosion time series by default (output.series_every = t_end / this): the
memory stays that of 200 states whatever t_end, and a flow of t_end / 4 still gets 50"""


@dataclass
class Case(GridAcross):
    """A validated case: everything needed to set up and run the models (the y-axis of
    a 2D grid: :class:`~pdeflow.case_2d.GridAcross`)."""

    data: dict[str, dict[str, Any]]
    source: str = "<dict>"
    base_dir: Path = field(default_factory=Path.cwd)

    # --- construction ---------------------------------------------------------------------
    @classmethod
    def from_file(cls, path: str | Path, overrides: list[str] | None = None) -> Case:
        """Read a TOML case file, apply ``section.key=value`` overrides, validate."""
        path = Path(path)
        data = read_toml(path, "case file")
        case = cls(data, str(path), path.resolve().parent)
        for item in overrides or []:
            case.set(item)
        case.validate()
        return case

    @classmethod
    def from_dict(cls, data: dict, source: str = "<dict>") -> Case:
        case = cls(copy.deepcopy(data), source)
        case.validate()
        return case

    def set(self, item: str) -> None:
        """Apply an override ``section.key=value`` (value parsed as a TOML value); a key
        of a sub-table as ``section.table.key=value`` (``terrain.topography.z0=2000``)."""
        if "=" not in item or "." not in item.split("=", 1)[0]:
            raise CaseError(f"override {item!r} must look like section.key=value")
        key, raw = item.split("=", 1)
        try:
            value = tomllib.loads(f"v = {raw.strip()}")["v"]
        except tomllib.TOMLDecodeError:
            value = raw.strip()  # bare strings such as open or column
        try:
            set_key(self.data, key.strip(), value)
        except ValueError as err:
            raise CaseError(f"override {item!r}: {err}") from None

    def copy(self) -> Case:
        return Case(copy.deepcopy(self.data), self.source, self.base_dir)

    # --- validation -----------------------------------------------------------------------
    def _err(self, msg: str) -> CaseError:
        return CaseError(f"{self.source}: {msg}")

    def validate(self) -> None:
        """Check sections, keys, types and ranges; raise CaseError naming the key
        (:func:`pdeflow.case_validation.validate`)."""
        _validate(self)

    # --- accessors ------------------------------------------------------------------------
    def _get(self, section: str, key: str, default: Any) -> Any:
        return self.data.get(section, {}).get(key, default)

    @property
    def name(self) -> str:
        return self._get("case", "name", Path(self.source).stem)

    @property
    def models(self) -> list[str]:
        return list(self._get("case", "models", DEFAULT_MODELS))

    @property
    def t_end(self) -> float:
        return float(self._get("case", "t_end", 10.0))

    @property
    def length(self) -> float:
        return float(self._get("grid", "length", 1.0))

    @property
    def geometry(self) -> str:
        """'planar' (a slope, per unit width; the default) or 'axisymmetric' (radial flow
        on a horizontal plane, r in [0, grid.length])."""
        return self._get("grid", "geometry", "planar")

    @property
    def x_start(self) -> float:
        return float(self._get("grid", "x_start", 0.0))

    @property
    def dx(self) -> float:
        if "cells" in self.data.get("grid", {}):
            return self.length / int(self.data["grid"]["cells"])
        return float(self._get("grid", "dx", self.length / 100))

    @property
    def cells(self) -> int:
        if "cells" in self.data.get("grid", {}):
            return int(self.data["grid"]["cells"])
        return max(1, round(self.length / self.dx))

    @property
    def bc(self) -> tuple:
        """(left, right) boundaries along x; on a 2D grid one pair per axis,
        ((left, right), (y_low, y_high)), as the models take them."""
        b = self.data.get("boundaries", {})
        along_x = (b.get("left", "wall"), b.get("right", "open"))
        if not self.is_2d:
            return along_x
        # walls across by default: a channel's side walls, and nothing leaves unseen
        return along_x, (b.get("y_low", "wall"), b.get("y_high", "wall"))

    @property
    def cfl(self) -> float:
        return float(self._get("numerics", "cfl", 0.3))

    @property
    def solver(self) -> str:
        return self._get("numerics", "solver", "fv-split")

    @property
    def initial(self) -> dict[str, Any]:
        """The ``[initial]`` table; with ``terrain.release``, a copy holding the
        shapefile's outline as the ``polygon`` shape's ``vertices`` [m from the grid's
        corner] (:func:`pdeflow.case_terrain.release_vertices`)."""
        initial = self.data.get("initial", {})
        vertices = release_vertices(self)
        return initial if vertices is None else {**initial, "vertices": vertices}

    @property
    def L0(self) -> float | None:
        v = self.initial.get("L0")
        return None if v is None else float(v)

    @property
    def snapshot_times(self) -> list[float]:
        """``output.snapshot_times`` up to ``t_end`` [s]: a short check of a case
        (``--set case.t_end=0.1``) keeps its snapshots before t_end and drops the later
        ones (:attr:`dropped_snapshot_times`)."""
        return [t for t in self._all_snapshot_times() if t <= self.t_end]

    @property
    def dropped_snapshot_times(self) -> list[float]:
        """``output.snapshot_times`` past ``t_end`` [s]: not taken (the run ends first)."""
        return [t for t in self._all_snapshot_times() if t > self.t_end]

    def _all_snapshot_times(self) -> list[float]:
        return [float(t) for t in self._get("output", "snapshot_times", [])]

    @property
    def frames(self) -> str:
        """What a snapshot at time t holds (fv-split): 'interpolate' (the state at t,
        linear between the steps around it; the default) or 'step' (the state after the
        first step at or past t, at its own time: a state of the scheme, e.g.
        hyperbolic after the restoration)."""
        return self._get("output", "frames", "interpolate")

    @property
    def front_threshold(self) -> float:
        return float(self._get("output", "front_threshold", 1e-3))

    @property
    def runout_mass_fraction(self) -> float:
        """The fraction of the mass within the mass-quantile front (0 < f < 1; default
        :data:`pdeflow.metrics.RUNOUT_MASS_FRACTION`, 0.99)."""
        return float(self._get("output", "runout_mass_fraction", RUNOUT_MASS_FRACTION))

    @property
    def erosion_series(self) -> bool:
        """Whether the runs record the erosion time series (pdeflow.erosion):
        ``output.erosion_series`` 'on', 'off', or 'auto' (the default: on for the cases
        that lay a bed, so that no other case pays for frames nobody asked for)."""
        choice = self._get("output", "erosion_series", "auto")
        return choice == "on" or (choice == "auto" and has_bed(self.initial))

    @property
    def series_every(self) -> float:
        """Simulation time between two frames of the erosion series [s] (default
        t_end / :data:`SERIES_FRAMES`)."""
        return float(self._get("output", "series_every", self.t_end / SERIES_FRAMES))

    @property
    def series_frames(self) -> int:
        """Frames the erosion series keeps (0 without it): every ``series_every`` from
        t = 0, and the final state."""
        if not self.erosion_series:
            return 0
        return int(math.floor(self.t_end / self.series_every + 1e-9)) + 2

    @property
    def variant(self) -> Variant:
        """How the case is solved: the :class:`~pdeflow.variant.Variant` its
        ``[numerics]`` and the models' ``hyperbolicity`` parameter select."""
        return variant_of(self.data.get("numerics", {}), self._hyperbolicity())

    def _hyperbolicity(self) -> str:
        """The ``hyperbolicity`` parameter of the first model that has one ('exact', the
        paper's, by default)."""
        for name in _hyperbolicity_sections():
            if "hyperbolicity" in self.data.get(name, {}):
                return self.data[name]["hyperbolicity"]
        return "exact"

    def with_variant(self, variant: Variant) -> Case:
        """A copy solved with ``variant`` (its other numerics, e.g. cfl and dt, kept);
        the models' ``hyperbolicity`` parameter is set unless it is the case's own."""
        c = self.copy()
        num = c.data.setdefault("numerics", {})
        for key in ("flux", "reconstruction", "limiter", "splitting", "solver"):
            num.pop(key, None)
        num.update(variant.numerics())
        if variant.hyperbolicity != c._hyperbolicity():
            for name in _hyperbolicity_sections():
                c.data.setdefault(name, {})["hyperbolicity"] = variant.hyperbolicity
        c.validate()
        return c

    # --- model set-up ---------------------------------------------------------------------
    def make_grid(self):
        """py-pde's grid of the case: a ``CartesianGrid`` (planar; 2D with
        ``grid.width``) or a ``PolarSymGrid`` on [0, length] (axisymmetric)."""
        from pde import CartesianGrid, PolarSymGrid

        if self.geometry == "axisymmetric":
            return PolarSymGrid((0.0, self.length), self.cells)
        if self.is_2d:
            return CartesianGrid([[self.x_start, self.x_start + self.length],
                                  [self.y_start, self.y_start + self.width]],
                                 [self.cells, self.cells_y])
        return CartesianGrid([[self.x_start, self.x_start + self.length]], self.cells)

    def make_pde(self, model: str):
        """The PDE of the registered model ``model`` with this case's parameters,
        boundaries and scheme; over a ``[terrain]`` bed, the bed at the cell corners
        (:meth:`terrain_corners`) as its ``bed``."""
        system = systems.get(model)
        corners = self.terrain_corners()
        bed = {} if corners is None else {"bed": corners}  # no bed: the PDE as before
        try:
            return system.pde_class(self.data.get(model, {}), bc=self.bc,
                                    scheme=self.variant.scheme, **bed)
        except ValueError as err:
            raise self._err(f"[numerics] {err}") from None

    @property
    def splitting(self) -> str:
        return self._get("numerics", "splitting", "lie")

    def initial_profiles(self, model: str, grid=None) -> dict[str, np.ndarray]:
        """Depth and velocity profiles of the initial state for ``model`` (at rest; the
        model's system splits the shape's total depth into its layers)."""
        system = systems.get(model)
        grid = grid or self.make_grid()
        if self.is_2d:
            return self._initial_profiles_2d(model, grid)
        x = grid.axes_coords[0] - self.x_start
        ini = self.initial
        if ini["shape"] == "file":
            try:
                return profiles_from_file(self.base_dir / ini["path"], system.profile_names,
                                          x.size, system.name)
            except ValueError as err:
                raise self._err(str(err)) from None
        params = system.parameters_class.from_dict(self.data.get(model, {}))
        depths = list(system.layer_depths(total_depth(ini, x), x, ini, params))
        bed = self.bed(model, x)
        if bed is not None:
            depths[system.bed_layer] = depths[system.bed_layer] + bed
        out: dict[str, np.ndarray] = {}
        for layer, depth in zip(system.layers, depths, strict=True):
            out[layer.depth] = depth
            out[layer.velocity] = np.zeros_like(x)
        return out

    def bed(self, model: str, x: np.ndarray | None = None) -> np.ndarray | None:
        """The erodible bed [m] ``model`` starts with at the cell centres ``x`` [m from
        the domain's start; default: the case's grid]: the shape's bed if the model has
        an erodible layer, else None (no bed, or the model runs on the rigid bed)."""
        if systems.get(model).bed_layer is None:
            return None
        return bed_depth(self.initial, self._cell_x(x))

    def bed_region(self, x: np.ndarray | None = None) -> np.ndarray | None:
        """The cells (a mask over ``x`` [m from the domain's start; default: the case's
        grid]) where the shape lays its bed, None if it lays none."""
        return bed_region(self.initial, self._cell_x(x))

    def _cell_x(self, x: np.ndarray | None) -> np.ndarray:
        """``x``, or the case's cell centres [m from the domain's start]."""
        return self.make_grid().axes_coords[0] - self.x_start if x is None else x

    def bed_kind(self, model: str) -> str | None:
        """'erodible' or 'rigid' if the case lays a bed ('rigid': ``model`` has no
        erodible layer and runs without it); None if it lays none."""
        if not has_bed(self.initial):
            return None
        return "rigid" if systems.get(model).bed_layer is None else "erodible"

    def make_state(self, model: str):
        """PDE, grid and initial FieldCollection for ``model``."""
        grid = self.make_grid()
        eq = self.make_pde(model)
        try:
            state = eq.make_state(grid, **self.initial_profiles(model, grid))
        except ValueError as err:
            if isinstance(err, CaseError):
                raise
            raise self._err(f"initial state: {err}") from None
        return eq, state


def set_key(data: dict[str, Any], key: str, value: Any) -> None:
    """Set ``key`` = ``value`` in a case's ``data``: ``section.key``, or the key of a
    sub-table ``section.table.key`` (``terrain.topography.z0``), the tables made as
    needed; ValueError (one line) where a part of the path is a value, not a table."""
    *tables, name = key.split(".")
    table = data
    for part in tables:
        table = table.setdefault(part, {})
        if not isinstance(table, dict):
            raise ValueError(f"{part} is a value, not a table")
    table[name] = value


def _hyperbolicity_sections() -> list[str]:
    """Models whose parameters have a ``hyperbolicity`` treatment (a Variant's choice)."""
    return [name for name in systems.names()
            if "hyperbolicity" in {f.name for f in fields(systems.get(name).parameters_class)}]


def read_text(path: str | Path, what: str,
              error: type[Exception] = CaseError) -> str:
    """The text of the file ``path`` (``what``: 'case file', 'study file', for the
    messages); a missing file, a directory or bytes that are not UTF-8 (TOML is UTF-8)
    raise ``error`` with one line."""
    path = Path(path)
    if path.is_dir():
        raise error(f"{path} is a directory; give a {what} (e.g. cases/*.toml)")
    if not path.is_file():
        raise error(f"{what} {path} does not exist")
    try:
        raw = path.read_bytes()
    except OSError as err:
        raise error(f"{what} {path} cannot be read ({err.strerror or err})") from None
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as err:
        line = raw[:err.start].count(b"\n") + 1
        raise error(f"{path}: not UTF-8 text (byte {raw[err.start]:#04x} on line "
                    f"{line}); save the file as UTF-8") from None


def read_toml(path: str | Path, what: str) -> dict[str, Any]:
    """The TOML table of the file ``path`` (:func:`read_text`; invalid TOML is a
    one-line :class:`CaseError` too)."""
    try:
        return tomllib.loads(read_text(path, what))
    except tomllib.TOMLDecodeError as err:
        raise CaseError(f"{path}: not valid TOML: {err}") from None


def load_case(path: str | Path, overrides: list[str] | None = None) -> Case:
    """Read and validate a case file (see module docstring)."""
    return Case.from_file(path, overrides)
