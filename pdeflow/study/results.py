"""A study directory: the study file, its metadata and the results table.

``DIR/results.csv`` gets one line per finished evaluation, appended with a single
``write`` in append mode and flushed to disk, so a killed study leaves every finished
row intact; a line cut short by a crash mid-write (no final newline) is dropped when the
directory is opened again, and its evaluation is redone. ``DIR/study.toml`` is a copy of
the study file and ``DIR/meta.json`` records pdeflow's version, the study's fingerprint
(the study file and the case files it reads), a digest of the code of pdeflow's models
and numerics, and every execution's timing; reopening a directory with a changed study
file is an error, with changed models or numerics a warning (``ResultsTable.other_code``:
its rows were computed by other code).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import os
from pathlib import Path
from typing import Any

from .. import __version__
from ..io import atomic_path, write_json
from .spec import StudyError, StudySpec

FIXED_COLUMNS = ("id", "status", "message", "wall_s")


def numerics_digest() -> str:
    """Digest of the source of pdeflow's models and numerics: what a study's numbers
    depend on besides its study and case files (16 hex digits)."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for path in sorted([*root.glob("models/*.py"), *root.glob("numerics/*.py")]):
        h.update(path.name.encode() + b"\0" + path.read_bytes())
    return h.hexdigest()[:16]


class ResultsTable:
    """The results of one study in ``directory`` (created if absent)."""

    def __init__(self, directory: str | Path, spec: StudySpec) -> None:
        self.dir = Path(directory)
        self.spec = spec
        self.columns = [*FIXED_COLUMNS, *spec.keys, *spec.columns()]
        self.csv = self.dir / "results.csv"
        self.meta_path = self.dir / "meta.json"
        if self.meta_path.exists():
            self.meta = json.loads(self.meta_path.read_text())
            if self.meta.get("fingerprint") != spec.fingerprint:
                raise StudyError(
                    f"{self.dir} holds the results of another version of the study "
                    f"(its study.toml or a case file it reads has changed since); use a "
                    f"new --out directory or remove {self.dir}")
            self._repair()
            # rows computed by other models or numerics (or by a version that did not
            # record them) are kept; run_study says so
            self.other_code = self.meta.get("numerics") != numerics_digest()
        else:
            self.other_code = False
            if self.dir.exists() and any(self.dir.iterdir()):
                raise StudyError(f"--out {self.dir} exists and is not a study directory "
                                 "(no meta.json); give a new or empty directory")
            if not self.dir.parent.is_dir():
                raise StudyError(f"--out {self.dir}: the parent directory "
                                 f"{self.dir.parent} does not exist")
            self.dir.mkdir(exist_ok=True)
            with atomic_path(self.dir / "study.toml") as tmp:
                tmp.write_text(spec.text)
            with atomic_path(self.csv) as tmp:
                tmp.write_text(self._lines([dict(zip(self.columns, self.columns,
                                                     strict=True))]))
            self.meta = {"pdeflow_version": __version__, "study": str(spec.path),
                         "fingerprint": spec.fingerprint, "numerics": numerics_digest(),
                         "design": spec.design, "executions": []}
            write_json(self.meta_path, self.meta)

    def _lines(self, rows: list[dict[str, Any]]) -> str:
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        for row in rows:
            writer.writerow(["" if row.get(c) is None else row[c] for c in self.columns])
        return buf.getvalue()

    def _repair(self) -> None:
        """Drop a last line cut short by a crash (it has no newline)."""
        data = self.csv.read_bytes()
        if data and not data.endswith(b"\n"):
            with self.csv.open("r+b") as fh:
                fh.truncate(data.rfind(b"\n") + 1)

    def append(self, rows: list[dict[str, Any]]) -> None:
        """Append finished rows: one write, flushed to disk before returning."""
        if not rows:
            return
        fd = os.open(self.csv, os.O_WRONLY | os.O_APPEND)
        try:
            os.write(fd, self._lines(rows).encode())
            os.fsync(fd)
        finally:
            os.close(fd)

    def rows(self) -> list[dict[str, Any]]:
        """Every finished row, values parsed (numbers as int/float, empty as None)."""
        with self.csv.open(newline="") as fh:
            return [{k: _parse(v) for k, v in row.items()} for row in csv.DictReader(fh)]

    def frame(self) -> Any:
        """The table as a pandas DataFrame sorted by id."""
        return read_frame(self.csv)

    def record_execution(self, info: dict[str, Any]) -> None:
        self.meta.setdefault("executions", []).append(info)
        write_json(self.meta_path, self.meta)


def read_frame(path: str | Path) -> Any:
    """A results.csv as a pandas DataFrame sorted by id (empty fields are missing values,
    the string "NA" stays a string)."""
    import pandas as pd

    df = pd.read_csv(path, keep_default_na=False, na_values=[""])
    return df.sort_values("id").reset_index(drop=True)


def _parse(text: str) -> Any:
    if text == "":
        return None
    for cast in (int, float):
        try:
            return cast(text)
        except ValueError:
            pass
    return text
