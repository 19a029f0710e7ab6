"""A case as the text of a case file: what the hillside page offers to download, so that
``pdeflow run`` on the file repeats the page's run.

Only what case files hold is written: tables of tables, strings, booleans, integers,
floats and lists of them (TOML 1.0; Python's :mod:`tomllib` reads it back to the same
dictionary, which the tests check).
"""

from __future__ import annotations

import json
import math
from typing import Any


def toml_value(value: Any) -> str:
    """``value`` as a TOML value: floats exactly (``repr``), strings quoted, lists
    inline; ValueError for anything a case file cannot hold."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(float(value))  # numpy's float64 is a float: its repr is not TOML
    if isinstance(value, str):
        # a TOML basic string: JSON's escapes are TOML's, but DEL must be escaped too
        return json.dumps(value, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(value, list | tuple):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if hasattr(value, "item"):  # a numpy scalar
        return toml_value(value.item())
    raise ValueError(f"a case file cannot hold {type(value).__name__} values: {value!r}")


def _table(name: str, table: dict[str, Any], out: list[str]) -> None:
    subtables = {k: v for k, v in table.items() if isinstance(v, dict)}
    out.append(f"[{name}]")
    out.extend(f"{key} = {toml_value(v)}" for key, v in table.items()
               if not isinstance(v, dict))
    out.append("")
    for key, sub in subtables.items():
        _table(f"{name}.{key}", sub, out)


def case_toml(data: dict[str, Any], comment: str = "") -> str:
    """The case dictionary ``data`` (sections of keys, as :attr:`pdeflow.cases.Case.data`)
    as a case file, headed by ``comment`` (lines prefixed with ``#``)."""
    out = [f"# {line}".rstrip() for line in comment.splitlines()]
    if out:
        out.append("")
    for name, table in data.items():
        if not isinstance(table, dict):
            raise ValueError(f"case key {name!r} is not a table")
        _table(name, table, out)
    return "\n".join(out).rstrip() + "\n"
