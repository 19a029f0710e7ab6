"""A stored run on a 2D grid (issue 36): :class:`StoredRun2D`, what
:func:`pdeflow.stored_runs.open_run` returns for a file of ``pdeflow run CASE2D --store``.

The file is the 1D store's (:mod:`pdeflow.storage`) on py-pde's 2D ``CartesianGrid``:
each frame is the state h1, h1u1, h1v1, h2, h2u2, h2v2 (two layers) or h, hu, hv (one
layer) followed by ``fextra_over_rho1``, every field of shape (nx, ny) (x down the
slope, y across; depths in m, discharges in m^2/s, F_extra/rho1 in m^2/s^2). The
metadata adds the y-axis: ``dimensions`` (2), ``dy``, ``width``, ``y_start`` and
``cells_y``.

Exports (``pdeflow export RUN.h5 OUT``, by the suffix):

* ``.nc``: NetCDF (through xarray; NetCDF3 via scipy unless netCDF4 or h5netcdf is
  installed) with dimensions ``time`` [s], ``x`` and ``y`` [m] (cell centres), and per
  layer its depth and velocities along x and y (``h1``, ``u1``, ``v1``, ... or ``h``,
  ``u``, ``v``) and, for two layers, ``fextra_over_rho1``, each of shape
  (time, x, y) with CF-style ``units`` and ``long_name``;
* ``.npz``: arrays ``t``, ``x``, ``y`` and each quantity as (time, nx, ny), plus
  ``metadata_json``;
* ``.csv``: one row per (time, x, y) cell, header ``t,x,y,h1,u1,v1,...``.

Velocities are zero where a layer is not thicker than the model's dry tolerance, as in
the solver.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .io import atomic_path
from .numerics.state import velocity_profile
from .storage import StorageError, StoredRun, units
from .trackers.frames import FEXTRA_LABEL

AXIS_NAMES = {"t": "time", "x": "x", "y": "y"}
"""the NetCDF dimension of each axis (CF's usual ``time`` for the simulation time)"""


def long_names(system: Any) -> dict[str, str]:
    """CF-style ``long_name`` of every exported quantity of ``system``'s 2D runs."""
    out = {FEXTRA_LABEL: "extra momentum exchange F_extra over rho1 that restores "
                         "hyperbolicity (last step)"}
    for layer in system.layers:
        out[layer.depth] = f"depth of the {layer.label} (normal to the bed)"
        out[layer.velocity] = f"velocity of the {layer.label} along x (down the slope)"
        out[layer.velocity_y] = f"velocity of the {layer.label} along y (across the slope)"
    return out


@dataclass
class StoredRun2D(StoredRun):
    """A stored run on a 2D grid, loaded into memory: :attr:`data` has the shape
    (nt, 6 or 3, nx, ny) (h1, h1u1, h1v1, h2, h2u2, h2v2 or h, hu, hv), :attr:`fextra`
    (nt, nx, ny) [m^2/s^2], :attr:`x` the cell centres along x [m] (nx,), :attr:`y`
    those along y [m] (ny,)."""

    y: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """cell centres along y (across the slope) [m], shape (ny,)"""

    dimensions = 2

    def describe(self) -> str:
        """The 1D line (:meth:`StoredRun.describe`) and the grid's cells."""
        return f"{super().describe()}, 2D grid {self.x.size} x {self.y.size} cells"

    def profiles(self, i: int) -> dict[str, np.ndarray]:
        """Depths [m], velocities along x and y [m/s] and F_extra/rho1 [m^2/s^2] of frame
        i, each of shape (nx, ny)."""
        d = self.data[i]
        out: dict[str, np.ndarray] = {}
        for k, layer in enumerate(self.system.layers):
            h = d[3 * k]  # a 2D layer's rows: depth, discharge along x, along y
            out[layer.depth] = h.copy()
            out[layer.velocity] = velocity_profile(h, d[3 * k + 1], self.dry_tolerance)
            out[layer.velocity_y] = velocity_profile(h, d[3 * k + 2], self.dry_tolerance)
        if self.system.has_fextra:
            out[FEXTRA_LABEL] = self.fextra[i].copy()
        return out

    def columns(self) -> list[str]:
        """Names of the exported quantities (after t, x and y)."""
        return [*self.system.profile_names_on(2),
                *([FEXTRA_LABEL] if self.system.has_fextra else [])]

    def _stacked(self) -> dict[str, np.ndarray]:
        """Every quantity of :meth:`columns` over all frames, shape (nt, nx, ny)."""
        per = [self.profiles(i) for i in range(len(self.times))]
        return {name: np.stack([p[name] for p in per]) for name in self.columns()}

    def table(self) -> np.ndarray:
        """Long table: one row per (time, x, y) cell (y fastest), columns t, x, y, then
        :meth:`columns`."""
        nt, cells = len(self.times), self.x.size * self.y.size
        X, Y = np.meshgrid(self.x, self.y, indexing="ij")  # the state's (nx, ny) order
        cols = [np.repeat(self.times, cells), np.tile(X.ravel(), nt),
                np.tile(Y.ravel(), nt)]
        cols += [v.reshape(-1) for v in self._stacked().values()]
        return np.column_stack(cols)

    def table_axes(self) -> list[str]:
        """The names of :meth:`table`'s leading columns: t, x and y (CSV header)."""
        return ["t", "x", "y"]

    def to_npz(self, path: str | Path) -> Path:
        """Write t [s], x and y [m] and each quantity as a (nt, nx, ny) array, plus the
        metadata as JSON."""
        arrays = {"t": self.times, "x": self.x, "y": self.y, **self._stacked(),
                  "metadata_json": np.array(json.dumps(self.metadata))}
        with atomic_path(path) as tmp, tmp.open("wb") as fh:
            np.savez(fh, **arrays)
        return Path(path)

    def to_xarray(self) -> Any:
        """An ``xarray.Dataset`` with dimensions (time, x, y), CF-style ``units`` and
        ``long_name`` on every variable and coordinate; needs xarray."""
        try:
            import xarray as xr
        except ImportError:
            raise StorageError("exporting to xarray/NetCDF needs xarray: "
                               "pip install 'pdeflow[export]'") from None
        dims = (AXIS_NAMES["t"], AXIS_NAMES["x"], AXIS_NAMES["y"])
        unit, names = units(self.system), long_names(self.system)
        data_vars = {name: (dims, values, {"units": unit[name], "long_name": names[name]})
                     for name, values in self._stacked().items()}
        coords = {
            dims[0]: (dims[0], self.times, {"units": "s", "long_name": "simulation time",
                                            "axis": "T"}),
            dims[1]: (dims[1], self.x, {"units": "m", "axis": "X", "long_name":
                                        "x, down the slope (cell centres)"}),
            dims[2]: (dims[2], self.y, {"units": "m", "axis": "Y", "long_name":
                                        "y, across the slope (cell centres)"}),
        }
        # CF-style, no Conventions claim: CF's time coordinate wants 'seconds since ...',
        # and a run's time is simulation time (in s, as the 1D export)
        attrs = {"pdeflow_metadata": json.dumps(self.metadata), "model": self.model,
                 "source": str(self.path)}
        for key in ("case_name", "pdeflow_version", "variant"):
            if self.metadata.get(key) is not None:
                attrs[key] = str(self.metadata[key])
        return xr.Dataset(data_vars, coords=coords, attrs=attrs)


__all__ = ["StoredRun2D", "long_names"]
