"""The unit of each field of a model's parameter dataclass, read from its docstring."""

from __future__ import annotations

import functools


@functools.cache
def field_units(cls: type) -> dict[str, str]:
    """The unit of each field of a parameter dataclass, as its attribute docstring gives
    it: the first bracket without a comma ('[deg]', '[m/s]', '[-]'; a range such as
    '[0, 1)' is no unit); fields without one are left out."""
    import ast
    import inspect
    import re

    out: dict[str, str] = {}
    for klass in reversed(cls.__mro__):
        try:
            tree = ast.parse(inspect.getsource(klass).lstrip())
        except (OSError, TypeError, SyntaxError):
            continue  # builtins, or no source
        body = tree.body[0].body if tree.body and isinstance(tree.body[0], ast.ClassDef) \
            else []
        for stmt, doc in zip(body, body[1:], strict=False):
            if (isinstance(stmt, ast.AnnAssign) and isinstance(stmt.target, ast.Name)
                    and isinstance(doc, ast.Expr) and isinstance(doc.value, ast.Constant)
                    and isinstance(doc.value.value, str)):
                unit = re.search(r"\[([^\],]+)\]", doc.value.value)
                if unit:
                    out[stmt.target.id] = unit.group(1).strip()
    return out
