"""Output files that are complete or absent: write to a temporary name, then rename.

Every temporary file or directory (:class:`PendingFile`, :class:`PendingDir`) is
registered until it is committed or discarded, so that a command that is interrupted
anywhere, even while a writer is being set up, can remove them all
(:func:`discard_pending`); SIGINT and SIGTERM are blocked while a temporary is created and
registered, renamed or removed (:func:`signals_blocked`), so none is left unregistered or
half-renamed.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np


class OutputError(ValueError):
    """An output path that cannot be written as given (names the option and the path)."""


_PENDING: dict[int, PendingFile | PendingDir] = {}
"""the temporaries not yet committed or discarded, by id"""


@contextmanager
def signals_blocked() -> Iterator[None]:
    """Hold SIGINT and SIGTERM back (at the operating system) inside the block: a
    handler that raises runs after it, not half-way through (main thread only; elsewhere
    signals do not reach Python code anyway)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    sigs = {signal.SIGINT, signal.SIGTERM}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, sigs)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def discard_pending() -> int:
    """Discard every temporary of this process not yet committed (an interrupted or
    failed command); returns how many there were. Targets are left as they were."""
    with signals_blocked():
        left = list(_PENDING.values())
        for pending in left:
            pending.discard()
    return len(left)


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
        self.done = False
        with signals_blocked():
            fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}.",
                                       suffix=f".part{self.path.suffix}",
                                       dir=self.path.parent)
            os.close(fd)
            self.tmp = Path(tmp)
            _PENDING[id(self)] = self

    def commit(self) -> Path:
        """Rename the temporary file onto the target; return the target.

        The file gets the permissions of a file created normally (mkstemp makes
        temporary files private to the user; results are ordinary files).
        """
        with signals_blocked():
            os.chmod(self.tmp, 0o666 & ~_umask())
            os.replace(self.tmp, self.path)
            self.done = True
            _PENDING.pop(id(self), None)
        return self.path

    def discard(self) -> None:
        """Remove the temporary file (the target is left as it was)."""
        with signals_blocked():
            self.tmp.unlink(missing_ok=True)
            self.done = True
            _PENDING.pop(id(self), None)


class PendingDir:
    """A directory filled under a temporary name next to ``path``
    (``.NAME.XXXX.part``) and swapped onto ``path`` on :meth:`commit`: whatever
    ``path`` held before (a previous run's files) is replaced as a whole, so that no
    file of an older run stays beside the new ones, and no reader sees a half-filled
    ``path``. Write into :attr:`tmp`."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.done = False
        with signals_blocked():
            self.tmp = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.", suffix=".part",
                                             dir=self.path.parent))
            _PENDING[id(self)] = self

    def commit(self) -> Path:
        """Move the old ``path`` (if any) aside, rename the temporary directory onto it,
        remove the old one; return ``path``. In between, ``path`` is briefly absent,
        never half old and half new."""
        with signals_blocked():
            os.chmod(self.tmp, 0o777 & ~_umask())
            old = None
            if self.path.exists() or self.path.is_symlink():
                old = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.",
                                            suffix=".part-old", dir=self.path.parent))
                os.replace(self.path, old / "old")
            os.replace(self.tmp, self.path)
            self.done = True
            _PENDING.pop(id(self), None)
            if old is not None:
                shutil.rmtree(old, ignore_errors=True)
        return self.path

    def discard(self) -> None:
        """Remove the temporary directory and everything in it (``path`` is left as it
        was)."""
        with signals_blocked():
            shutil.rmtree(self.tmp, ignore_errors=True)
            self.done = True
            _PENDING.pop(id(self), None)


def _umask() -> int:
    """The process's umask (the permissions a file created normally would get)."""
    umask = os.umask(0)
    os.umask(umask)
    return umask


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


def json_text(data: Any) -> str:
    """``data`` as the indented JSON text of pdeflow's files (see :func:`jsonable`)."""
    return json.dumps(jsonable(data), indent=2) + "\n"


def write_json(path: str | Path, data: Any) -> Path:
    """Write ``data`` as indented JSON, atomically."""
    return write_text(path, json_text(data))


def write_npz(path: str | Path, arrays: dict[str, np.ndarray]) -> Path:
    """Write arrays to an ``.npz`` file, atomically."""
    with atomic_path(path) as tmp, tmp.open("wb") as fh:
        np.savez(fh, **arrays)
    return Path(path)
