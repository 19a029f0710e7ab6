"""Output files that are complete or absent: write to a temporary name, then rename."""

from __future__ import annotations

import json
import math
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np


class OutputError(ValueError):
    """An output path that cannot be written as given (names the option and the path)."""


def check_output(path: str | Path | None, option: str) -> None:
    """Raise :class:`OutputError` unless the directory that ``path`` goes into exists
    (as ``cp`` does: a mistyped path must not create directories anywhere)."""
    if path is None:
        return
    parent = Path(path).expanduser().parent
    if not parent.is_dir():
        raise OutputError(f"{option} {path}: directory {parent} does not exist (create it "
                          "first)")


class PendingFile:
    """A file written under a temporary name next to ``path`` and renamed onto ``path``
    on :meth:`commit`, so that a reader never sees a truncated file under the final name.

    The temporary name keeps the suffix (``.NAME.XXXX.part.SUFFIX``), so that writers
    that choose a format by the file name (movies, NetCDF) still do so. For a file
    written in one block use :func:`atomic_path`; a writer that stays open across calls
    (a tracker's HDF5 file or movie) keeps a ``PendingFile`` and commits when done.
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}.",
                                   suffix=f".part{self.path.suffix}", dir=self.path.parent)
        os.close(fd)
        self.tmp = Path(tmp)
        self.done = False

    def commit(self) -> Path:
        """Rename the temporary file onto the target; return the target.

        The file gets the permissions of a file created normally (mkstemp makes
        temporary files private to the user; results are ordinary files).
        """
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(self.tmp, 0o666 & ~umask)
        os.replace(self.tmp, self.path)
        self.done = True
        return self.path

    def discard(self) -> None:
        """Remove the temporary file (the target is left as it was)."""
        self.tmp.unlink(missing_ok=True)
        self.done = True


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path next to ``path`` (a :class:`PendingFile`); rename it onto
    ``path`` on success.

    If the body raises, the temporary file is removed and ``path`` is left untouched,
    so a reader never sees a truncated file under the final name.
    """
    pending = PendingFile(path)
    try:
        yield pending.tmp
        pending.commit()
    except BaseException:
        pending.discard()
        raise


def jsonable(value: Any) -> Any:
    """``value`` with numpy scalars/arrays, tuples and paths turned into JSON types;
    non-finite floats become None (JSON has no NaN or inf)."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, np.generic):
        return jsonable(value.item())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Path):
        return str(value)
    return value


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path``, atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return Path(path)


def write_json(path: str | Path, data: Any) -> Path:
    """Write ``data`` as indented JSON, atomically."""
    return write_text(path, json.dumps(jsonable(data), indent=2) + "\n")


def write_npz(path: str | Path, arrays: dict[str, np.ndarray]) -> Path:
    """Write arrays to an ``.npz`` file, atomically."""
    with atomic_path(path) as tmp, tmp.open("wb") as fh:
        np.savez(fh, **arrays)
    return Path(path)
