"""A bed z(x, y) [m] written as an expression in a case file (``terrain.expression``).

The expression is arithmetic in the bed's coordinates ``x`` and ``y`` [m]::

    expression = "200 - 0.4 * x + 30 * exp(-((x - 300)**2 + y**2) / 2e4)"

with numbers, ``+ - * / ** %``, the constants ``pi`` and ``e``, comparisons (for
``where``) and the numpy functions of :data:`FUNCTIONS`, evaluated on the grid's cell
corners as numpy arrays. It is parsed once (:func:`bed_expression`) and nothing else is
allowed: no attribute, subscript, keyword, lambda, comprehension or other name, so a
case file cannot run code. A bad expression is a one-line ValueError that says what is
not allowed and what is.
"""

from __future__ import annotations

import ast
from collections.abc import Callable

import numpy as np

FUNCTIONS = {name: getattr(np, name) for name in (
    "sin", "cos", "tan", "arcsin", "arccos", "arctan", "arctan2", "sinh", "cosh", "tanh",
    "exp", "log", "log10", "sqrt", "abs", "hypot", "minimum", "maximum", "clip", "where")}
"""the functions an expression may call (numpy's, elementwise)"""
NAMES = {"x", "y", "pi", "e"}
"""the names an expression may use besides :data:`FUNCTIONS`"""

_NODES = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Compare, ast.Call, ast.Name,
          ast.Load, ast.Constant, ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.Mod,
          ast.USub, ast.UAdd, ast.Lt, ast.LtE, ast.Gt, ast.GtE)
"""the syntax an expression may use: arithmetic, comparisons and calls by name"""


def _allowed() -> str:
    return f"x, y, pi, e, numbers, + - * / ** %, < <= > >= and {', '.join(FUNCTIONS)}"


def _check(tree: ast.AST) -> None:
    """ValueError (one line) at the first node of ``tree`` outside the allowed syntax."""
    for node in ast.walk(tree):
        if not isinstance(node, _NODES):
            raise ValueError(f"{type(node).__name__.lower()} is not allowed in a bed "
                             f"expression; use {_allowed()}")
        if isinstance(node, ast.Constant) and (
                isinstance(node.value, bool) or not isinstance(node.value, (int, float))):
            raise ValueError(f"{node.value!r} is not a number; use {_allowed()}")
        if isinstance(node, ast.Name) and node.id not in NAMES | set(FUNCTIONS):
            raise ValueError(f"name {node.id!r} is not allowed; use {_allowed()}")
        if isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name):
                raise ValueError(f"{type(node.func).__name__.lower()} is not allowed in a "
                                 f"bed expression; call {', '.join(FUNCTIONS)} by name")
            if node.func.id not in FUNCTIONS:
                raise ValueError(f"function {node.func.id!r} is not allowed; use "
                                 f"{_allowed()}")
            if node.keywords:
                raise ValueError(f"{node.func.id}(...) takes positional arguments only "
                                 f"in a bed expression")


def bed_expression(text: str) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """The bed ``z(x, y)`` [m] of the expression ``text`` (the module's syntax), at
    points ``x``, ``y`` [m] (arrays of one shape; the result has it even where the
    expression is a constant). Raises a one-line ValueError for an expression that does
    not parse or uses anything else, before any evaluation."""
    if not isinstance(text, str) or not text.strip():
        raise ValueError(f"must be an expression in x and y, got {text!r}")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as err:
        raise ValueError(f"{text!r} does not parse: {err.msg}") from None
    _check(tree)
    code = compile(tree, "<terrain.expression>", "eval")

    def z(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        x = np.asarray(x, float)
        y = np.asarray(y, float)
        names = {"x": x, "y": y, "pi": np.pi, "e": np.e, **FUNCTIONS}
        with np.errstate(all="ignore"):  # (a value that is not finite is refused after)
            out = eval(code, {"__builtins__": {}}, names)  # noqa: S307 - checked above
        return np.broadcast_to(np.asarray(out, float), np.broadcast(x, y).shape).copy()

    return z
