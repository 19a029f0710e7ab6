"""What the hillside page runs: a terrain case file with the page's release, models,
friction and grid (:class:`HillsideSetup`), checked before any work.

The page starts from a case file with a ``[terrain]`` bed named by a topography
(:data:`pdeflow.terrain.topographies.TOPOGRAPHIES`; a DEM's path is relative to its
case file, so a downloaded copy would not find it) and replaces

* ``[initial]`` by the drawn release: shape ``polygon`` with the vertices [m from the
  grid's corner] and the thickness H0 [m] measured normal to the slope;
* ``case.models`` by the chosen models;
* the grid by ``cells`` cells down the path and as many across as keep them nearly
  square (``grid.cells``, ``grid.cells_y``);
* each model's basal friction: the law ``friction_law`` and its angle
  ``friction_deg`` [deg] (Coulomb's phi_b, Pouliquen's and mu(I)'s delta1 with delta2
  kept as many degrees above it as in the case; Voellmy's mu = tan(angle)).

Everything else (the domain, the boundaries, t_end, the other parameters) is the case
file's. :meth:`HillsideSetup.case` is the case ``pdeflow run`` gets from
:meth:`HillsideSetup.toml`, the file the page offers to download, so the page's numbers
are the command line's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from .. import systems
from ..cases import Case, CaseError, load_case
from ..models.base import check_range
from ..models.friction_laws import LAWS
from ..terrain.topographies import TOPOGRAPHIES
from .case_file import case_toml

DEFAULT_CASE = "hillside_plane.toml"
"""The case the page opens with: a plane at 34 deg and a flat run-out."""
MAX_CELLS = 40_000
"""The largest grid a run may have (200 x 200): a class's runs stay seconds long."""
CELLS_RANGE = (20, 200)
"""Cells down the path [-]: the coarsest that still shows a tongue, the finest allowed."""
THICKNESS_RANGE = (0.1, 10.0)
"""Release thickness, normal to the slope [m]."""
FRICTION_RANGE = (5.0, 50.0)
"""Friction angle [deg]: from a very mobile flow to one that hardly leaves a 34 deg slope."""
MAX_T_END_S = 600.0
"""The longest simulated time a run may ask for [s]."""
MAX_VERTICES = 64
"""The most vertices a release polygon may have."""
HILLSIDE_MODELS = ("single_layer", "two_layer")
"""The models that flow over a bed."""
LAW_ANGLES = {"coulomb": "phi_b_deg", "pouliquen": "delta1_deg", "mu_i": "delta1_deg"}
"""The key a law's angle sets (Voellmy has none: its mu is tan of the angle)."""
HILLSIDE_LAWS = tuple(law for law in (*LAW_ANGLES, "voellmy") if law in LAWS)
"""The laws the page offers: those with an angle, and Voellmy's."""


def is_hillside_case(case: Case) -> bool:
    """A 2D case over a named topography (not a DEM file): the page can run it and a
    downloaded copy runs anywhere."""
    terrain = case.data.get("terrain") or {}
    return case.is_2d and terrain.get("bed") in TOPOGRAPHIES


def hillside_cases(case_dir: Path) -> dict[str, Path]:
    """The case files of ``case_dir`` the page offers (:func:`is_hillside_case`), by
    file name, the default first."""
    out = {}
    for path in sorted(case_dir.glob("*.toml")):
        try:
            case = load_case(path)
        except CaseError:
            continue
        if is_hillside_case(case):
            out[path.name] = path
    first = {DEFAULT_CASE: out.pop(DEFAULT_CASE)} if DEFAULT_CASE in out else {}
    return first | out


def _in_range(name: str, value: float, bounds: tuple[float, float], unit: str) -> None:
    check_range(name, value, *bounds, unit=unit)


@dataclass(frozen=True)
class HillsideSetup:
    """A run of the hillside page (see the module's docstring for what each sets)."""

    case_path: Path
    vertices: tuple[tuple[float, float], ...]
    """the release polygon [m from the grid's corner], >= 3 vertices"""
    thickness: float = 1.0
    """release thickness normal to the slope [m]"""
    models: tuple[str, ...] = HILLSIDE_MODELS
    friction_law: str = "coulomb"
    friction_deg: float = 25.0
    """the law's angle [deg]"""
    cells: int = 120
    """cells down the path (x) [-]"""
    extra: dict[str, Any] = field(default_factory=dict, compare=False)
    """more keys ``section.key`` -> value (tests, benchmarks), set last"""

    def check(self) -> None:
        """One-line ValueError naming the parameter and its allowed range, before any
        work (the case's own checks follow in :meth:`case`)."""
        _in_range("thickness", self.thickness, THICKNESS_RANGE, "m")
        _in_range("friction_deg", self.friction_deg, FRICTION_RANGE, "deg")
        if not isinstance(self.cells, int) or not CELLS_RANGE[0] <= self.cells <= CELLS_RANGE[1]:
            raise ValueError(f"cells must be an integer in [{CELLS_RANGE[0]}, "
                             f"{CELLS_RANGE[1]}], got {self.cells!r}")
        if not self.models or any(m not in HILLSIDE_MODELS for m in self.models):
            raise ValueError(f"models must be one or both of {list(HILLSIDE_MODELS)}, got "
                             f"{list(self.models)}")
        if self.friction_law not in HILLSIDE_LAWS:
            raise ValueError(f"friction_law must be one of {list(HILLSIDE_LAWS)}, got "
                             f"{self.friction_law!r}")
        if not 3 <= len(self.vertices) <= MAX_VERTICES:
            raise ValueError(f"the release polygon must have 3 to {MAX_VERTICES} vertices, "
                             f"got {len(self.vertices)}")

    def _grid(self, grid: dict[str, Any]) -> dict[str, Any]:
        length, width = float(grid["length"]), float(grid["width"])
        cells_y = max(1, round(self.cells * width / length))
        if self.cells * cells_y > MAX_CELLS:
            most = math.isqrt(int(MAX_CELLS * length / width))
            while most > 1 and most * max(1, round(most * width / length)) > MAX_CELLS:
                most -= 1  # cells_y is rounded up at times: the count must fit too
            raise ValueError(f"cells: {self.cells} x {cells_y} cells exceed the page's "
                             f"limit of {MAX_CELLS}; choose at most {most} cells")
        out = {k: v for k, v in grid.items() if k not in ("dx", "dy", "cells", "cells_y")}
        return out | {"cells": self.cells, "cells_y": cells_y}

    def _friction(self, base: dict[str, Any], model: str) -> dict[str, Any]:
        params = dict(base.get(model, {}))
        params["friction_law"] = self.friction_law
        if self.friction_law == "voellmy":
            params["voellmy_mu"] = math.tan(math.radians(self.friction_deg))
        else:
            key = LAW_ANGLES[self.friction_law]
            if key == "delta1_deg":  # delta2 keeps its distance above delta1
                own = systems.get(model).parameters_class.from_dict(base.get(model, {}))
                params["delta2_deg"] = self.friction_deg + (own.delta2_deg - own.delta1_deg)
            params[key] = self.friction_deg
        return params

    def data(self) -> dict[str, Any]:
        """The case dictionary of this run (the case file's, with the page's keys)."""
        self.check()
        base = load_case(self.case_path).data
        data = {k: dict(v) if isinstance(v, dict) else v for k, v in base.items()}
        data["case"] = data["case"] | {
            "models": list(self.models),
            # the case file's own description names its own release
            "description": f"a drawn release of {self.thickness:g} m (slope-normal) on "
                           f"{Path(self.case_path).name}'s terrain, {self.friction_law} "
                           f"{self.friction_deg:g} deg, {self.cells} cells down the path"}
        data["grid"] = self._grid(base["grid"])
        data["initial"] = {"shape": "polygon", "H0": float(self.thickness),
                           "vertices": [[float(x), float(y)] for x, y in self.vertices],
                           "measured": "slope_normal"}
        for m in self.models:
            data[m] = self._friction(base, m)
        terrain = dict(base.get("terrain", {}))
        terrain.pop("release", None)  # the drawn polygon is the release
        data["terrain"] = terrain
        for key, value in self.extra.items():
            section, name = key.split(".", 1)
            data.setdefault(section, {})[name] = value
        return data

    def case(self) -> Case:
        """The checked case (one-line CaseError or ValueError before any work)."""
        data = self.data()
        if float(data["case"].get("t_end", 10.0)) > MAX_T_END_S:
            raise ValueError(f"case.t_end must be at most {MAX_T_END_S:g} s on this page, "
                             f"got {data['case']['t_end']}")
        return Case.from_dict(data, source=self.file_name)

    @property
    def file_name(self) -> str:
        """The downloaded case file's name."""
        return f"hillside_{Path(self.case_path).stem.removeprefix('hillside_')}.toml"

    def toml(self) -> str:
        """The case file that repeats this run with ``pdeflow run``."""
        self.case()  # checked first: no file for a run that cannot run
        comment = (f"The hillside page's run on {Path(self.case_path).name}: a drawn "
                   f"release of {self.thickness:g} m\n(normal to the slope), "
                   f"{self.friction_law} friction at {self.friction_deg:g} deg, "
                   f"{self.cells} cells down the path.\n  {self.command()}")
        return case_toml(self.data(), comment)

    def command(self) -> str:
        """The command that runs the downloaded file."""
        return f"pdeflow run {self.file_name}"

    def with_(self, **changes: Any) -> HillsideSetup:
        """A copy with ``changes``."""
        return replace(self, **changes)


def release_polygon(case: Case, corners: int = 16) -> tuple[tuple[float, float], ...]:
    """The case's own release as a polygon [m from the grid's corner]: a polygon's
    vertices, a box's four corners, an ellipse's or cylinder's ``corners`` points."""
    initial = case.initial
    shape = initial.get("shape")
    if shape == "polygon":
        return tuple((float(x), float(y)) for x, y in initial["vertices"])
    x0, y0 = float(initial["x0"]), float(initial["y0"])
    if shape == "box":
        a, b = float(initial["semi_x"]), float(initial["semi_y"])
        return ((x0 - a, y0 - b), (x0 + a, y0 - b), (x0 + a, y0 + b), (x0 - a, y0 + b))
    if "radius" in initial:
        a = b = float(initial["radius"])
    else:
        a, b = float(initial.get("semi_x", 1.0)), float(initial.get("semi_y", 1.0))
    return tuple((x0 + a * math.cos(2 * math.pi * k / corners),
                  y0 + b * math.sin(2 * math.pi * k / corners)) for k in range(corners))
