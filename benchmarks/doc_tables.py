"""Formatting shared by the sections of docs/performance.md: numbers, verdicts, the
machine's conditions and markdown tables."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any


def fmt(v: Any, spec: str = ".3g") -> str:
    """``v`` formatted with ``spec``; "-" for None or a non-finite float."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return format(v, spec)


def verdict(ok: bool | None) -> str:
    """The verdict of a target: met, missed, or n/a (None: not measured)."""
    return "n/a" if ok is None else ("**met**" if ok else "**missed**")


def conditions_text(c: dict[str, Any]) -> str:
    """The date, versions and load of a measurement's ``conditions()``, as a phrase."""
    load = c.get("load_avg_at_start")
    lt = f"{load[0]:.2f}" if load else "?"
    le = c.get("load_avg_at_end")
    lend = f", at the end {le[0]:.2f}" if le else ""
    return (f"{c['date']}, Python {c['python']}, numpy {c['numpy']}, numba {c['numba']}, "
            f"py-pde {c['py-pde']}, {c['cores']} cores shared with other jobs (1-min load "
            f"average at the start {lt}{lend})")


def md_table(columns: Sequence[str], align: str, rows: Iterable[str]) -> list[str]:
    """A markdown table: the header cells ``columns``, ``align`` one letter per column
    ("l" left, "r" right), then the ``rows`` (formatted lines "| a | b |")."""
    rule = "".join("---:|" if a == "r" else "---|" for a in align)
    return ["| " + " | ".join(columns) + " |", "|" + rule, *rows]


def loads_text(v: Any) -> str:
    """A load-average triple (1, 5, 15 min) as text; "-" if not recorded."""
    return "-" if not v else ", ".join(f"{x:.2f}" for x in v)
