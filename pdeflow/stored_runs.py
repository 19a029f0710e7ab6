"""Reading a run file back: :func:`open_run` gives a :class:`~pdeflow.storage.StoredRun`
(a 1D or axisymmetric grid) or a :class:`~pdeflow.storage_2d.StoredRun2D` (a 2D grid),
by the file's grid. It sits above both, so that the 1D store need not know the 2D one.

Example::

    from pdeflow.stored_runs import open_run
    run = open_run("out.h5")                                # -> StoredRun
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import systems
from .storage import StorageError, StoredRun, open_storage
from .storage_2d import StoredRun2D
from .trackers.frames import FEXTRA_LABEL


def open_run(path: str | Path) -> StoredRun:
    """Load a stored run (written by :class:`~pdeflow.storage.RunStorageTracker` or
    ``--store``): depths [m], discharges [m^2/s], F_extra/rho1 [m^2/s^2] per frame.

    Plain py-pde storages of a granular state (2 or 4 fields, no F_extra, no metadata)
    are read as well.
    """
    path = Path(path)
    storage = open_storage(path)
    try:
        times = np.array(storage.times[:], dtype=float)
        data = np.array(storage.data[:], dtype=float)
        grid = storage.grid
        meta = dict(storage.info.get("pdeflow") or {})
    except (OSError, KeyError, RuntimeError) as err:
        raise StorageError(f"{path}: cannot read the stored run ({err})") from None
    finally:
        storage.close()
    if times.size == 0 or data.ndim not in (3, 4) or grid is None:
        raise StorageError(f"{path}: holds no frames of a 1D or 2D run")
    axes = data.ndim - 2  # (frames, fields, cells along x[, cells along y])
    x = np.asarray(grid.axes_coords[0], dtype=float)
    rows = data.shape[1]
    # with F_extra/rho1 a frame has one row more than the state: 2 or 4 rows per 1D
    # state, 3 or 6 per 2D state
    if meta.get("fields", [None])[-1] == FEXTRA_LABEL or rows in ((3, 5), (4, 7))[axes - 1]:
        state, fextra = data[:, :-1], data[:, -1]
    else:
        state, fextra = data, np.zeros((data.shape[0], *data.shape[2:]))
    if "model" not in meta:
        fields = meta.get("fields", [])[:state.shape[1]]
        try:
            meta["model"] = systems.of_fields(fields).name
        except ValueError:
            raise StorageError(f"{path}: {rows} fields per frame {fields} are no granular "
                               "run of a registered model") from None
    if axes == 2:
        y = np.asarray(grid.axes_coords[1], dtype=float)
        return StoredRun2D(path, times, x, state, fextra, meta, y=y)
    return StoredRun(path, times, x, state, fextra, meta)


__all__ = ["open_run"]
