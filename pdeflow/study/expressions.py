"""Expressions of a study file (``[derived]``, ``[objectives]``): arithmetic over
numbers, quantities (``two_layer.runout``, ``sweep.two_layer.exponent``), derived names
and a few functions, checked once when the file is read and evaluated per row."""

from __future__ import annotations

import ast
import math
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any


class StudyError(ValueError):
    """An invalid study file or study directory; the message names the key."""


def _fill(x: float, default: float) -> float:
    return default if x is None or (isinstance(x, float) and math.isnan(x)) else x


FUNCTIONS = {"abs": abs, "min": min, "max": max, "sqrt": math.sqrt, "log": math.log,
             "log10": math.log10, "exp": math.exp, "fill": _fill}
_NODES = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Call, ast.Name, ast.Attribute,
          ast.Constant, ast.Load, ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.USub,
          ast.UAdd)


def _dotted(node: ast.AST) -> str | None:
    """``a.b.c`` of an Attribute/Name chain, else None."""
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        head = _dotted(node.value)
        return None if head is None else f"{head}.{node.attr}"
    return None


@dataclass(frozen=True)
class Expression:
    """An arithmetic expression of quantities, checked on construction."""

    name: str
    text: str
    code: Any = field(repr=False, compare=False)
    names: tuple[str, ...] = ()
    """the dotted quantity names and plain (derived) names it reads"""

    @classmethod
    def parse(cls, name: str, text: Any) -> Expression:
        if not isinstance(text, str):
            raise StudyError(f"{name} must be an expression string, got {text!r}")
        try:
            tree = ast.parse(text, mode="eval")
        except SyntaxError as err:
            raise StudyError(f"{name}: not an expression: {text!r} ({err.msg})") from None
        for node in ast.walk(tree):
            if not isinstance(node, _NODES):
                raise StudyError(f"{name}: {type(node).__name__} is not allowed in "
                                 f"{text!r} (arithmetic, quantities and "
                                 f"{sorted(FUNCTIONS)} only)")
            if isinstance(node, ast.Call):
                if not (isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS) \
                        or node.keywords:
                    raise StudyError(f"{name}: only the functions {sorted(FUNCTIONS)} "
                                     f"may be called in {text!r}")
            if isinstance(node, ast.Constant) and not isinstance(node.value, (int, float)):
                raise StudyError(f"{name}: only numbers may appear as constants in "
                                 f"{text!r}")
        names: list[str] = []

        def collect(node: ast.AST) -> None:
            # a maximal a.b.c chain is one name; a called function is not
            if isinstance(node, (ast.Attribute, ast.Name)):
                dotted = _dotted(node)
                if dotted is None:
                    raise StudyError(f"{name}: {text!r} reads an attribute of a value")
                names.append(dotted)
                return
            children = node.args if isinstance(node, ast.Call) else ast.iter_child_nodes(node)
            for child in children:
                collect(child)

        collect(tree)
        return cls(name, text, compile(tree, name, "eval"), tuple(dict.fromkeys(names)))

    def __call__(self, values: dict[str, Any]) -> float:
        """Value for one row of ``values`` (missing or None quantities read as NaN)."""
        scope: dict[str, Any] = {"__builtins__": {}, **FUNCTIONS}
        for n in self.names:
            v = values.get(n)
            v = math.nan if v is None else float(v)
            parts = n.split(".")
            ns = scope
            for p in parts[:-1]:
                ns = (ns.setdefault(p, SimpleNamespace()) if isinstance(ns, dict)
                      else ns.__dict__.setdefault(p, SimpleNamespace()))
            if isinstance(ns, dict):
                ns[parts[-1]] = v
            else:
                setattr(ns, parts[-1], v)
        try:
            return float(eval(self.code, scope))  # noqa: S307 - checked AST, no builtins
        except (ZeroDivisionError, ValueError, OverflowError, TypeError):
            return math.nan
