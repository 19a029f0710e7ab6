"""The points of the analysis studies, and copies of a case on other grids.

A :class:`Point` is one run of a :class:`~pdeflow.study.core.Study`: a case, a model, a
:class:`~pdeflow.variant.Variant` and the labels that place it in the study (level,
aspect ratio, ...). Convergence, work-precision, validation and aspect-ratio sweeps
build their points from a case with the helpers here (:func:`refined`,
:func:`on_grid`, :func:`case_on_grid`, :func:`with_sets`).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..cases import Case, load_case
from ..simulate import Run
from ..variant import Variant


@dataclass
class Point:
    """One run of a study: a case, a model, a variant, and the labels of its row."""

    case: Case
    model: str
    variant: Variant | None = None
    """None: the variant the case file selects"""
    labels: dict[str, Any] = field(default_factory=dict)

    def run(self) -> Run:
        """The point's run, set up (PDE, initial state, solver arguments)."""
        return Run(self.case, self.model, self.variant)


def on_grid(case: Case, *, cells: int | None = None, dx: float | None = None) -> Case:
    """Copy of ``case`` on another grid: ``cells`` cells, or spacing ``dx`` [m] (which
    must divide the domain into whole cells, as in a case file)."""
    c = case.copy()
    grid = c.data.setdefault("grid", {})
    grid.pop("cells", None)
    grid.pop("dx", None)
    if cells is not None:
        grid["cells"] = int(cells)
    elif dx is not None:
        grid["dx"] = float(dx)
    c.validate()
    return c


def refined(case: Case, level: int) -> Case:
    """Copy of ``case`` with dx = (the case's dx) / 2**level; on a 2D grid dy too (a
    ``grid.dy`` halved, ``grid.cells_y`` doubled, per level; a dy by default follows
    dx), so that the cells keep their shape."""
    c = case
    grid = case.data.get("grid", {})
    if case.is_2d and ("dy" in grid or "cells_y" in grid):
        c = case.copy()
        if "cells_y" in grid:
            c.data["grid"]["cells_y"] = int(grid["cells_y"]) * 2**level
        else:
            c.data["grid"]["dy"] = case.dy / 2**level
    return on_grid(c, dx=case.dx / 2**level)


def with_sets(case: Case, items: Iterable[str], validate: bool = True) -> Case:
    """Copy of ``case`` with ``section.key=value`` overrides applied (validated unless
    the caller changes more before validating once)."""
    c = case.copy()
    for item in items:
        c.set(item)
    if validate:
        c.validate()
    return c


def resolve_case(case_path: str | Path | Case) -> Case:
    """A :class:`~pdeflow.cases.Case` from a case file path or a Case (copied)."""
    if isinstance(case_path, Case):
        return case_path.copy()
    return load_case(case_path)


def case_on_grid(case: Case, grid: float | int, variant: Variant,
                 cfl: float | None = None) -> Case:
    """Copy of ``case`` on the grid ``grid`` (int: cells, float: dx [m], rounded to a
    whole number of cells) solved with ``variant`` (and ``cfl`` if given), without
    snapshots. On a 2D grid ``grid`` is along x; the cells along y scale with it (as
    many per cell along x as the case has: the cells keep their shape)."""
    if isinstance(grid, (int, np.integer)) and not isinstance(grid, bool):
        cells = int(grid)
    else:  # nearest whole number of cells (case files require length/dx integral)
        cells = max(1, round(case.length / float(grid)))
    sets = [f"grid.cells={cells}", "output.snapshot_times=[]"]
    if case.is_2d:
        sets.append(f"grid.cells_y={max(1, round(cells * case.cells_y / case.cells))}")
    if cfl is not None:
        sets.append(f"numerics.cfl={float(cfl)!r}")
    c = with_sets(case, sets, validate=False)
    c.data["grid"].pop("dx", None)
    c.data["grid"].pop("dy", None)  # a 2D grid's: cells_y says it
    c.data.get("numerics", {}).pop("dt", None)
    return c.with_variant(variant)  # validates once, with every change made
