"""Runs cached point by point in a CSV, for the generators of the docs' pages.

A page's generator runs many points (a case on one grid with one set of parameters);
each row is appended to the CSV as its run ends, so that an interrupted call loses at
most the run under way and the next call runs only the points still missing. Empty
cells read back as None, ``bool_fields`` as booleans, ``text`` fields as strings and
everything else as floats.
"""

from __future__ import annotations

import csv
import json
import math
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

Row = dict[str, Any]


def read_rows(path: Path, text: Iterable[str],
              bool_fields: Iterable[str] = ("at_rest",)) -> list[Row]:
    """The stored rows of ``path`` (none if it does not exist), values parsed."""
    if not path.is_file():
        return []
    text, bool_fields = set(text), set(bool_fields)
    rows = []
    with path.open() as f:
        for raw in csv.DictReader(f):
            row: Row = {}
            for k, v in raw.items():
                if k in text:
                    row[k] = v
                elif k in bool_fields:
                    row[k] = v == "True"
                else:
                    row[k] = float(v) if v not in ("", "None") else None
            rows.append(row)
    return rows


def write_rows(path: Path, fields: Sequence[str], rows: list[Row]) -> None:
    """``path`` with exactly ``rows`` (a header of ``fields``)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)


ROUND_OFF_REL = 1e-9
"""relative difference below which two computed numbers of a page are the same: the
pages print at most 4 significant digits, and a fit or a sum on another processor (other
SIMD paths in numpy, scipy, numba) moves the last few of 16 digits"""
ROUND_OFF_ABS = 1e-14
"""absolute difference below which two numbers are the same: quantities that are zero
but for round-off (relative mass errors, 1e-16 and below) have no relative scale"""


def same_numbers(a: Any, b: Any, rel: float = ROUND_OFF_REL,
                 abs_tol: float = ROUND_OFF_ABS) -> bool:
    """Whether the JSON-like values ``a`` and ``b`` are equal but for round-off: the same
    keys, lengths, strings and booleans, and floats within ``rel`` (relative) or
    ``abs_tol``."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_numbers(a[k], b[k], rel, abs_tol) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(
            same_numbers(x, y, rel, abs_tol) for x, y in zip(a, b, strict=True))
    numbers = (int, float)
    if (isinstance(a, numbers) and isinstance(b, numbers)
            and not isinstance(a, bool) and not isinstance(b, bool)):
        return a == b or math.isclose(a, b, rel_tol=rel, abs_tol=abs_tol)
    return type(a) is type(b) and a == b


def snapshot(paths: Iterable[Path]) -> dict[Path, bytes]:
    """The bytes of the files ``paths`` that exist (the figures before a generator
    redraws them, for :func:`publish`)."""
    return {p: p.read_bytes() for p in paths if p.is_file()}


def publish(numbers: dict[str, Any], t0: float, numbers_path: Path, page_path: Path,
            render: Callable[[dict[str, Any]], str],
            figures: dict[Path, bytes] | None = None) -> str:
    """Write a page's ``numbers`` (with the generator's wall time since ``t0``
    [perf_counter s]) to ``numbers_path`` and ``render(numbers)`` to ``page_path``;
    returns the page's text.

    Where the stored numbers are the same but for round-off (:func:`same_numbers`; the
    generator's wall time aside) and the page is their rendering, neither file is
    rewritten, and the ``figures`` (:func:`snapshot` before they were redrawn) get their
    bytes back (a line moved by round-off redraws a few anti-aliased pixels):
    re-rendering from the cache on another processor leaves the tracked files as they
    are."""
    from pdeflow.io import atomic_path, jsonable, write_json, write_text

    numbers["generator_wall_s"] = round(time.perf_counter() - t0, 1)
    stored = json.loads(numbers_path.read_text()) if numbers_path.is_file() else None
    if stored is not None and page_path.is_file():
        ours = {k: v for k, v in json.loads(json.dumps(jsonable(numbers))).items()
                if k != "generator_wall_s"}
        theirs = {k: v for k, v in stored.items() if k != "generator_wall_s"}
        text = page_path.read_text()
        if same_numbers(ours, theirs) and render(stored) == text:
            for path, data in (figures or {}).items():
                if path.read_bytes() != data:
                    with atomic_path(path) as tmp:
                        tmp.write_bytes(data)
            print(f"unchanged: {numbers_path.name}, {page_path.name} and its figures "
                  "(round-off only)", file=sys.stderr)
            return text
    write_json(numbers_path, numbers)
    text = render(numbers)
    write_text(page_path, text)
    return text


def fill_rows(points: Sequence[Any], path: Path, fields: Sequence[str], rows: list[Row],
              key: Callable[[Any], Any], row_key: Callable[[Row], Any],
              measure: Callable[[Any], Row],
              describe: Callable[[Any, Row, float], str] | None = None,
              log: Any = sys.stderr) -> list[Row]:
    """Run every point of ``points`` whose ``key(point)`` is not that of a row of
    ``rows`` (``row_key``; the rows ``path`` holds), appending each new row to ``path``
    as its run ends, and a line ``describe(point, row, seconds)`` to ``log``; returns
    all rows."""
    done = {row_key(r) for r in rows}
    path.parent.mkdir(parents=True, exist_ok=True)
    new = not path.is_file()
    with path.open("a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        if new:
            w.writeheader()
        for p in points:
            if key(p) in done:
                continue
            t0 = time.perf_counter()
            row = measure(p)
            w.writerow(row)
            f.flush()
            rows.append(row)
            done.add(key(p))
            if log and describe is not None:
                print(describe(p, row, time.perf_counter() - t0), file=log, flush=True)
    return rows
