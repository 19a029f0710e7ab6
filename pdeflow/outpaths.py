"""Output paths checked before any computation (issue 28: no work lost after a run).

Every output option of the commands (``--summary``, ``--final``, ``--plot``,
``--outdir``, ``--store``, ``--movie``, ``--frames``, ``export OUT``) is checked here
before the run starts: the directory it goes into exists (a mistyped path must not
create directories anywhere; only the default ``results/<case>`` is created), it is not
a directory where a file is meant (nor a file where a directory is meant), a file can
really be created there (a probe file, removed at once: permissions alone do not tell,
e.g. for /proc or a read-only mount), and a file's suffix is one its writer knows. The
error is an :class:`pdeflow.io.OutputError`: one line naming the option and the path.
"""

from __future__ import annotations

import errno
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

from .io import OutputError

FIGURE_SUFFIXES = (".png", ".pdf", ".svg", ".svgz", ".jpg", ".jpeg", ".tif", ".tiff",
                   ".webp", ".eps", ".ps")
"""figure formats matplotlib writes without extra packages"""
EXPORT_SUFFIXES = (".csv", ".npz", ".nc", ".nc4", ".netcdf")
"""formats of ``pdeflow export`` (:meth:`pdeflow.storage.StoredRun.export`)"""


def _probe(directory: Path, option: str, path: str | Path) -> None:
    """Raise unless a file can be created (and removed) in ``directory``."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".pdeflow-probe.", dir=directory)
    except OSError as err:
        # a directory that exists but refuses new files with ENOENT is a kernel's
        # (/proc, /sys): "No such file or directory" would be the wrong reason
        reason = ("its file system takes no new files" if err.errno == errno.ENOENT
                  and directory.is_dir() else err.strerror or str(err))
        raise OutputError(f"{option} {path}: cannot write in {directory} "
                          f"({reason})") from None
    os.close(fd)
    os.unlink(tmp)


def check_file(path: str | Path | None, option: str,
               suffixes: Iterable[str] | None = None) -> None:
    """Raise :class:`OutputError` unless ``path`` (None: nothing to check) can be
    written as a file: its directory exists and takes files, it is not a directory,
    an existing file there may be replaced, and its suffix is one of ``suffixes``
    (case-insensitive; None: any)."""
    if path is None:
        return
    p = Path(path).expanduser()
    parent = p.parent
    if not parent.is_dir():
        raise OutputError(f"{option} {path}: directory {parent} does not exist (create it "
                          "first)")
    if p.is_dir():
        raise OutputError(f"{option} {path}: is a directory; give a file name")
    if suffixes is not None:
        allowed = tuple(suffixes)
        if p.suffix.lower() not in allowed:
            raise OutputError(f"{option} {path}: unknown file type "
                              f"{p.suffix or '(no suffix)'!r}; use {', '.join(allowed)}")
    if p.exists() and not os.access(p, os.W_OK):
        raise OutputError(f"{option} {path}: the file exists and is not writable")
    _probe(parent, option, path)


def check_dir(path: str | Path | None, option: str, *, create: bool = False) -> None:
    """Raise :class:`OutputError` unless ``path`` (None: nothing to check) is, or can
    be made, a directory that takes files: if it exists it is a directory; else its
    parent exists (with ``create``: the nearest existing ancestor, as for the default
    ``results/<case>``, which is created with its parents)."""
    if path is None:
        return
    p = Path(path).expanduser()
    if p.exists():
        if not p.is_dir():
            raise OutputError(f"{option} {path}: is a file, not a directory")
        _probe(p, option, path)
        return
    base = p.parent
    if create:
        while not base.exists() and base != base.parent:
            base = base.parent
    if not base.is_dir():
        raise OutputError(f"{option} {path}: directory {base} does not exist (create it "
                          "first)")
    _probe(base, option, path)
