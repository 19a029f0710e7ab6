"""Runs cached point by point in a CSV, for the generators of the docs' pages.

A page's generator runs many points (a case on one grid with one set of parameters);
each row is appended to the CSV as its run ends, so that an interrupted call loses at
most the run under way and the next call runs only the points still missing. Empty
cells read back as None, ``bool_fields`` as booleans, ``text`` fields as strings and
everything else as floats.
"""

from __future__ import annotations

import csv
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


def publish(numbers: dict[str, Any], t0: float, numbers_path: Path, page_path: Path,
            render: Callable[[dict[str, Any]], str]) -> str:
    """Write a page's ``numbers`` (with the generator's wall time since ``t0``
    [perf_counter s]) to ``numbers_path`` and ``render(numbers)`` to ``page_path``;
    returns the page's text."""
    from pdeflow.io import write_json, write_text

    numbers["generator_wall_s"] = round(time.perf_counter() - t0, 1)
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
