"""Stored runs: py-pde ``FileStorage`` (HDF5) with F_extra and metadata, reopening, export.

Writing (``pdeflow run CASE --store out.h5 [--store-every DT]``, or in Python)::

    from pdeflow.storage import RunStorageTracker, run_metadata
    from pdeflow.stored_runs import open_run
    tracker = RunStorageTracker("out.h5", interrupts=0.05,
                                metadata=run_metadata(case, PAPER_MODEL))
    run_model(case, PAPER_MODEL, tracker=tracker)          # or eq.solve(..., tracker=...)
    run = open_run("out.h5")                                # -> StoredRun
    run.times, run.x, run.profiles(-1)["h1"], run.metadata["parameters"]
    run.to_csv("out.csv"); run.to_netcdf("out.nc")          # NetCDF needs xarray

:class:`RunStorageTracker` is py-pde's ``StorageTracker`` on a ``FileStorage`` (through
:class:`pdeflow.trackers.FextraStorageTracker`): each stored frame is a py-pde
``FieldCollection`` of the state (h1, h1u1, h2, h2u2 or h, hu; depths in m, discharges
in m^2/s) followed by the field ``fextra_over_rho1`` [m^2/s^2] read from the
``fv-split`` solver's post-step data (zeros for other solvers and for one layer).
Frames are taken at the tracker's interrupts (simulation time, s) and once more at the
end of the run (the rest time when the solver stops at rest). The file is therefore
also readable with plain py-pde: ``pde.FileStorage(path)``.

Metadata (JSON in the HDF5 attribute ``pdeflow``): the format tag, pdeflow and py-pde
versions, case name, file and data (all sections, after overrides), the overrides,
the model, its variant, its parameters, and at the end t_final, the stop reason and
(when written by the CLI) the run's summary. Beside it, py-pde stores its own
attributes (the controller's information, the field attributes).
Velocities (in :meth:`StoredRun.profiles` and the exports) are zero where a layer is
not thicker than the model's dry tolerance, as in the solver.

A run on a 2D grid (a 2D case, issue 36) is stored the same way, each field of shape
(nx, ny) (h1, h1u1, h1v1, h2, h2u2, h2v2 or h, hu, hv, then ``fextra_over_rho1``), and
:func:`pdeflow.stored_runs.open_run` reads it back as a
:class:`pdeflow.storage_2d.StoredRun2D` (its export has dimensions time, x, y).

Files are complete or absent: the run writes to a temporary name next to the target
(``.NAME.XXXX.part.h5``) and renames it once the run has finished; a run that fails
leaves no file behind. HDF5 needs ``h5py`` (``pip install 'pdeflow[storage]'``).
"""

from __future__ import annotations

import datetime
import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from pde.trackers.base import InfoDict

from . import __version__, systems
from .io import PendingFile, atomic_path, jsonable
from .numerics.geometry import COORDINATES
from .numerics.state import DRY_TOLERANCE, velocity_profile
from .trackers.frames import (
    FEXTRA_LABEL,
    FextraStorageTracker,
    show_final_state,
    state_labels,
)

FORMAT = "pdeflow-run/1"


def units(system: systems.EquationSystem) -> dict[str, str]:
    """Units of the stored fields and exported columns of ``system``'s runs (1D and 2D:
    the cross-slope velocity and discharge of a 2D grid too)."""
    out = {"x": "m", "y": "m", "t": "s", FEXTRA_LABEL: "m^2/s^2"}
    for layer in system.layers:
        out.update({layer.depth: "m", layer.velocity: "m/s", layer.discharge: "m^2/s"})
        if layer.velocity_y is not None:
            out.update({layer.velocity_y: "m/s", layer.discharge_y: "m^2/s"})
    return out


class StorageError(ValueError):
    """A stored run that cannot be written or read; the message names the file."""


def require_h5py() -> None:
    """Raise StorageError with the install hint if h5py is missing."""
    try:
        import h5py  # noqa: F401
    except ImportError:  # pragma: no cover - h5py is installed with the test extra
        raise StorageError("storing runs in HDF5 needs h5py: "
                           "pip install 'pdeflow[storage]'") from None


# --- metadata -----------------------------------------------------------------------------
def _variant_parts(case: Any, eq: Any) -> list[str]:
    """What distinguishes this run's numerics and closure from the paper's defaults:
    the PDE's scheme (``eq.scheme.spatial``, e.g. 'hll/first-order'), the splitting, for
    two layers the exchange closure and the hyperbolicity mode, and a basal friction
    law other than Coulomb's."""
    num = case.data.get("numerics", {})
    parts = [case.solver]
    if getattr(eq, "scheme", None):
        parts.append(eq.scheme.spatial)
    else:
        parts += [f"{k}={num[k]}" for k in ("flux", "reconstruction", "limiter") if k in num]
    splitting = getattr(case, "splitting", num.get("splitting"))
    if splitting and case.solver == "fv-split":
        parts.append(f"{splitting} splitting")
    params = eq.parameters.to_dict()
    for key in ("exchange_closure", "hyperbolicity"):
        if key in params:
            parts.append(f"{key}={params[key]}")
    if getattr(eq.parameters, "rate_dependent_law", False):
        parts.append(f"friction_law={params['friction_law']}")  # Coulomb: as before
    return parts


def run_metadata(case: Any, model: str, *, overrides: Sequence[str] = (),
                 case_file: str | None = None, **extra: Any) -> dict[str, Any]:
    """Metadata of one model run of a :class:`pdeflow.cases.Case` for the stored file."""
    eq = case.make_pde(model)
    variant = ", ".join([model, *_variant_parts(case, eq)])
    meta = {
        "case_name": case.name,
        "case_file": case_file if case_file is not None else case.source,
        "case": case.data,
        # the folder its files (a DEM, a shapefile, profiles) are relative to
        "case_dir": str(Path(case.base_dir).resolve()),
        "overrides": list(overrides),
        "model": model,
        "variant": variant,
        "parameters": eq.parameters.to_dict(),
        "solver": case.solver,
        "cfl": case.cfl,
        "boundaries": list(case.bc),
        "dx": case.dx,
        "geometry": case.geometry,
        "coordinate": COORDINATES[case.geometry],
        "pdeflow_version": __version__,
    }
    if case.is_2d:  # the y-axis [m]; a 1D file keeps the keys it always had
        meta.update({"dimensions": 2, "dy": case.dy, "width": case.width,
                     "y_start": case.y_start, "cells_y": case.cells_y})
    meta.update(extra)
    return jsonable(meta)


# --- writing ------------------------------------------------------------------------------
class RunStorageTracker(FextraStorageTracker):
    """py-pde ``StorageTracker`` writing a run to an HDF5 file (py-pde's ``FileStorage``):
    the frames of :class:`~pdeflow.trackers.FextraStorageTracker`, the metadata, and
    the final state.

    Args:
        path: the HDF5 file to create (replaced only once the run has finished).
        interrupts: when to store, in simulation time: a number is an interval [s]
            (starting at t = 0), a list gives the times; anything py-pde accepts.
        metadata: JSON-able run description (see :func:`run_metadata`).
        autocommit: rename the file into place when the run finishes; with False, call
            :meth:`commit` (which can add metadata such as the summary) or
            :meth:`discard`.
        compression: gzip the datasets.

    py-pde does not finalize trackers when a run raises (a blow-up, a failing tracker):
    call :meth:`discard` then, as ``pdeflow run`` does, to remove the temporary file.
    """

    def __init__(self, path: str | Path, interrupts: Any = 0.05, *,
                 metadata: dict[str, Any] | None = None, autocommit: bool = True,
                 compression: bool = True):
        super().__init__(interrupts)
        self.storage = None  # a FileStorage on a temporary file, made when the run starts
        self.path = Path(path)
        self.metadata = dict(metadata or {})
        self.autocommit = autocommit
        self.compression = compression
        self._pending: PendingFile | None = None
        self.frames = 0

    def initialize(self, field: Any, info: InfoDict | None = None) -> float:
        import pde
        from pde import FileStorage

        require_h5py()
        system = (systems.get(self.metadata["model"]) if "model" in self.metadata
                  else systems.of_fields(state_labels(field)))
        meta = {"format": FORMAT, "model": system.name, **self.metadata}
        meta.setdefault("pdeflow_version", __version__)
        meta["py_pde_version"] = pde.__version__
        meta["created"] = datetime.datetime.now(datetime.timezone.utc).isoformat(
            timespec="seconds")
        # a 2D state has each layer's discharge across (y) after the one along x
        meta["fields"] = [*system.field_names_on(field.grid.num_axes), FEXTRA_LABEL]
        meta["units"] = {k: units(system)[k] for k in meta["fields"]}
        self._pending = PendingFile(self.path)
        self.storage = FileStorage(self._pending.tmp, info={"pdeflow": jsonable(meta)},
                                   write_mode="truncate_once",
                                   compression=self.compression)
        return super().initialize(field, info)

    def keep(self, field: Any, t: float) -> None:
        super().keep(field, t)
        self.frames += 1

    def finalize(self, info: InfoDict | None = None) -> None:
        if self.storage is None:
            return
        info = info or {}
        t_end = show_final_state(self, info)
        controller = info.get("controller", {})
        self.storage.info["pdeflow"].update(jsonable({
            "t_final": t_end,
            "stop_reason": controller.get("stop_reason"),
            "successful": controller.get("successful"),
            "at_rest": "rest_time" in info.get("solver", {}),
            "frames": self.frames,
        }))
        super().finalize(info)  # py-pde writes the metadata and closes the file
        if self.autocommit:
            self.commit()

    def commit(self, extra: dict[str, Any] | None = None) -> Path:
        """Add ``extra`` to the metadata, then rename the file into place."""
        if self._pending is None or self._pending.done:
            raise StorageError(f"{self.path}: nothing to commit (no run written)")
        if extra:
            import h5py

            with h5py.File(self._pending.tmp, "r+") as fh:
                meta = json.loads(fh.attrs["pdeflow"])
                meta.update(jsonable(extra))
                fh.attrs["pdeflow"] = json.dumps(meta)
        return self._pending.commit()

    def discard(self) -> None:
        """Abandon the run's file (used when a run fails): nothing is left behind."""
        if self.storage is not None:
            try:
                self.storage.close()
            except Exception:  # pragma: no cover - closing a broken file
                pass
        if self._pending is not None and not self._pending.done:
            self._pending.discard()


# --- reading ------------------------------------------------------------------------------
@dataclass
class StoredRun:
    """A stored run loaded into memory (see :func:`pdeflow.stored_runs.open_run`)."""

    path: Path
    times: np.ndarray
    """stored times [s], shape (nt,)"""
    x: np.ndarray
    """cell centres [m], shape (n,)"""
    data: np.ndarray
    """state rows per time, shape (nt, 4 or 2, n): h1, h1u1, h2, h2u2 or h, hu"""
    fextra: np.ndarray
    """F_extra/rho1 per time and cell [m^2/s^2], shape (nt, n)"""
    metadata: dict[str, Any] = field(default_factory=dict)

    dimensions = 1
    """the grid's axes (:class:`pdeflow.storage_2d.StoredRun2D`: 2)"""

    @property
    def model(self) -> str:
        return self.metadata["model"]

    @property
    def system(self) -> systems.EquationSystem:
        """The run's equation system."""
        return systems.get(self.model)

    @property
    def dry_tolerance(self) -> float:
        """The model's dry tolerance [m] (from the metadata; the default without it)."""
        return float(self.metadata.get("parameters", {}).get("dry_tolerance",
                                                             DRY_TOLERANCE))

    def describe(self) -> str:
        """One line: file, case, model, frames and their times, end time [s], largest
        stored F_extra/rho1 [m^2/s^2]."""
        m = self.metadata
        t_final = m.get("t_final")
        rest = " (at rest)" if m.get("at_rest") else ""
        fmax = float(self.fextra.max()) if self.fextra.size else 0.0
        return (f"{self.path}: {m.get('case_name', '?')}, {self.model}, "
                f"{len(self.times)} frames t = {self.times[0]:g}..{self.times[-1]:.4g} s, "
                f"end {'-' if t_final is None else f'{t_final:.4g} s'}{rest}, "
                f"max stored F_extra/rho1 {fmax:.3g} m2/s2")

    @property
    def label(self) -> str:
        """File name and model, for legends."""
        return f"{self.path.name} ({self.model.replace('_', ' ')})"

    def index(self, t: float | None = None) -> int:
        """Index of the stored time nearest to t [s] (None: the last one)."""
        if t is None:
            return len(self.times) - 1
        return int(np.argmin(np.abs(self.times - float(t))))

    def profiles(self, i: int) -> dict[str, np.ndarray]:
        """Depths [m], velocities [m/s] and F_extra/rho1 [m^2/s^2] of frame i."""
        d = self.data[i]
        out: dict[str, np.ndarray] = {}
        for k, layer in enumerate(self.system.layers):
            out[layer.depth] = d[2 * k].copy()
            out[layer.velocity] = velocity_profile(d[2 * k], d[2 * k + 1],
                                                   self.dry_tolerance)
        if self.system.has_fextra:
            out[FEXTRA_LABEL] = self.fextra[i].copy()
        return out

    def columns(self) -> list[str]:
        """Names of the exported quantities (after t and x)."""
        return [*self.system.profile_names,
                *([FEXTRA_LABEL] if self.system.has_fextra else [])]

    def table(self) -> np.ndarray:
        """Long table: one row per (time, cell), columns t, x, then :meth:`columns`."""
        nt, n = len(self.times), self.x.size
        cols = [np.repeat(self.times, n), np.tile(self.x, nt)]
        per = [self.profiles(i) for i in range(nt)]
        for name in self.columns():
            cols.append(np.concatenate([p[name] for p in per]))
        return np.column_stack(cols)

    @property
    def coordinate(self) -> str:
        """Name of the grid's coordinate: 'x' (planar) or 'r' (axisymmetric) [m]."""
        return str(self.metadata.get("coordinate", "x"))

    def table_axes(self) -> list[str]:
        """The names of :meth:`table`'s leading columns: t and the coordinate."""
        return ["t", self.coordinate]

    def to_csv(self, path: str | Path) -> Path:
        """Write the long table as CSV (header t,x,... or t,r,...; units in
        docs/user_guide.md)."""
        header = ",".join([*self.table_axes(), *self.columns()])
        with atomic_path(path) as tmp:
            np.savetxt(tmp, self.table(), delimiter=",", header=header, comments="",
                       fmt="%.10g")
        return Path(path)

    def to_npz(self, path: str | Path) -> Path:
        """Write t, the coordinate (x or r) and each quantity as a (nt, n) array, plus the
        metadata as JSON."""
        arrays: dict[str, np.ndarray] = {"t": self.times, self.coordinate: self.x}
        per = [self.profiles(i) for i in range(len(self.times))]
        for name in self.columns():
            arrays[name] = np.stack([p[name] for p in per])
        arrays["metadata_json"] = np.array(json.dumps(self.metadata))
        with atomic_path(path) as tmp, tmp.open("wb") as fh:
            np.savez(fh, **arrays)
        return Path(path)

    def to_xarray(self) -> Any:
        """An ``xarray.Dataset`` with dimensions (t, x) or (t, r); needs xarray."""
        try:
            import xarray as xr
        except ImportError:
            raise StorageError("exporting to xarray/NetCDF needs xarray: "
                               "pip install 'pdeflow[export]'") from None
        per = [self.profiles(i) for i in range(len(self.times))]
        c = self.coordinate
        data_vars = {name: (("t", c), np.stack([p[name] for p in per]),
                            {"units": units(self.system)[name]}) for name in self.columns()}
        attrs = {"pdeflow_metadata": json.dumps(self.metadata),
                 "model": self.model, "source": str(self.path)}
        for key in ("case_name", "pdeflow_version", "variant"):
            if self.metadata.get(key) is not None:
                attrs[key] = str(self.metadata[key])
        return xr.Dataset(data_vars,
                          coords={"t": ("t", self.times, {"units": "s"}),
                                  c: (c, self.x, {"units": "m"})},
                          attrs=attrs)

    def to_netcdf(self, path: str | Path) -> Path:
        """Write :meth:`to_xarray` as NetCDF (engine chosen by xarray)."""
        ds = self.to_xarray()
        with atomic_path(path) as tmp:
            ds.to_netcdf(tmp)
        return Path(path)

    def export(self, path: str | Path) -> Path:
        """Export by suffix: .csv, .npz, .nc (NetCDF, needs xarray)."""
        suffix = Path(path).suffix.lower()
        if suffix == ".csv":
            return self.to_csv(path)
        if suffix == ".npz":
            return self.to_npz(path)
        if suffix in (".nc", ".nc4", ".netcdf"):
            return self.to_netcdf(path)
        raise StorageError(f"{path}: unknown export format {suffix!r}; "
                           "use .csv, .npz or .nc")


def open_storage(path: str | Path) -> Any:
    """The stored run as a read-only py-pde ``FileStorage`` (for py-pde's own tools)."""
    from pde import FileStorage

    require_h5py()
    path = Path(path)
    if path.is_dir():
        raise StorageError(f"{path} is a directory; give a stored run (.h5)")
    if not path.is_file():
        raise StorageError(f"stored run {path} does not exist")
    import h5py

    if not h5py.is_hdf5(path):
        raise StorageError(f"{path}: not an HDF5 file (stored runs are written by "
                           "pdeflow run --store)")
    try:
        storage = FileStorage(path, write_mode="readonly")
        _ = storage.times  # fails if the file is no py-pde storage
    except (OSError, KeyError) as err:
        raise StorageError(f"{path}: not a readable HDF5 run file ({err})") from None
    return storage


def stored_axes(path: str | Path) -> int:
    """The axes of a stored run's grid (1 or 2), read from the file's grid alone (no
    frames loaded): what a command checks before any work."""
    storage = open_storage(path)
    try:
        return int(storage.grid.num_axes)
    except (OSError, KeyError, RuntimeError, AttributeError) as err:
        raise StorageError(f"{path}: cannot read the stored run's grid ({err})") from None
    finally:
        storage.close()


__all__ = ["FORMAT", "RunStorageTracker", "StorageError", "StoredRun", "open_storage",
           "run_metadata", "stored_axes"]
