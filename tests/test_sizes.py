"""Issue 35's size rules over the package: no module over 450 lines, no function over 80
lines outside numba kernels.

A kernel is a function compiled by numba: decorated by a compile decorator
(``@njit``, ``@cached``, ``@kernel(...)``, ...), or handed to a compile call
(``specialise(f, ...)``, ``njit(inline="always")(f)``), or made by a factory whose
result is handed to one (``specialise(_two_layer(...), ...)``; ``loop =
stepping_function(...)`` then ``specialise(loop, ...)``): the factory's kernel is the
function it returns. A kernel is one loop the compiler inlines into one piece of machine
code, so its length is the algorithm's; the factory around it is counted without it.
Lines are physical lines, docstrings and comments included (what a reader scrolls).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
PACKAGE = ROOT / "pdeflow"
MAX_MODULE_LINES = 450
MAX_FUNCTION_LINES = 80
COMPILERS = {"njit", "jit", "cached", "kernel", "specialise", "_jit", "cfunc",
             "vectorize", "guvectorize", "generated_jit", "stencil"}
"""names of the calls and decorators that compile a function with numba (pdeflow's
:mod:`pdeflow.numerics.compiled` wrappers and numba's own)"""

Function = ast.FunctionDef | ast.AsyncFunctionDef


def _callee(node: ast.expr) -> str:
    """The name a call or decorator is called by (``njit(...)(f)``: ``njit``)."""
    while isinstance(node, ast.Call):
        node = node.func
    if isinstance(node, ast.Attribute):
        return node.attr
    return node.id if isinstance(node, ast.Name) else ""


def _compiled_arguments(tree: ast.AST) -> list[tuple[ast.expr, ast.AST]]:
    """The first argument of every compile call in ``tree``, with the function (or
    module) the call is in."""
    out = []

    def visit(node: ast.AST, scope: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, Function):
                visit(child, child)
                continue
            if isinstance(child, ast.Call) and child.args and _callee(child) in COMPILERS:
                out.append((child.args[0], scope))
            visit(child, scope)

    visit(tree, tree)
    return out


def _made_by(name: str, scope: ast.AST) -> str | None:
    """The factory whose call ``name`` is assigned from in ``scope``, if any."""
    for node in ast.walk(scope):
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call) and any(
                isinstance(t, ast.Name) and t.id == name for t in node.targets):
            return _callee(node.value)
    return None


def kernel_names(tree: ast.AST) -> tuple[set[str], set[str]]:
    """Names of the functions ``tree`` compiles directly (not a parameter handed on,
    as ``_jit(func)`` does) and of the factories whose result it compiles."""
    direct, factories = set(), set()
    for arg, scope in _compiled_arguments(tree):
        if isinstance(arg, ast.Call):
            factories.add(_callee(arg))
        elif isinstance(arg, ast.Name):
            made = _made_by(arg.id, scope)
            if made:
                factories.add(made)
            elif not (isinstance(scope, Function) and arg.id in {
                    a.arg for a in ast.walk(scope.args) if isinstance(a, ast.arg)}):
                direct.add(arg.id)
    return direct, factories


def is_kernel(func: Function, parent: ast.AST | None, direct: set[str],
              factories: set[str]) -> bool:
    """Whether ``func`` (defined in ``parent``) is compiled by numba."""
    if any(_callee(d) in COMPILERS for d in func.decorator_list) or func.name in direct:
        return True
    return isinstance(parent, Function) and parent.name in factories and any(
        isinstance(n, ast.Return) and isinstance(n.value, ast.Name)
        and n.value.id == func.name for n in parent.body)


def long_functions(trees: dict[str, ast.AST], limit: int = MAX_FUNCTION_LINES
                   ) -> list[str]:
    """``module: function (lines)`` for each function over ``limit`` lines that is
    not a kernel, nested kernels' lines left out (a function is compiled by its own
    module; a factory may be called by another)."""
    names = {where: kernel_names(tree) for where, tree in trees.items()}
    factories = set().union(*(f for _, f in names.values()))
    found = []

    def visit(node: ast.AST, where: str) -> None:
        direct = names[where][0]
        for child in ast.iter_child_nodes(node):
            if not isinstance(child, Function):
                visit(child, where)
                continue
            kernel = is_kernel(child, node, direct, factories)
            nested = sum(n.end_lineno - n.lineno + 1 for n in ast.walk(child)
                         if n is not child and isinstance(n, Function)
                         and is_kernel(n, _parent(child, n), direct, factories))
            lines = child.end_lineno - child.lineno + 1 - nested
            if not kernel and lines > limit:
                found.append(f"{where}: {child.name} ({lines} lines)")
            visit(child, where)

    for where, tree in trees.items():
        visit(tree, where)
    return found


def _parent(root: ast.AST, target: ast.AST) -> ast.AST | None:
    for node in ast.walk(root):
        if target in list(ast.iter_child_nodes(node)):
            return node
    return None


def package_trees() -> dict[str, ast.AST]:
    return {str(p.relative_to(ROOT)): ast.parse(p.read_text(encoding="utf-8"))
            for p in sorted(PACKAGE.rglob("*.py"))}


def test_no_module_over_450_lines():
    long = {str(p.relative_to(ROOT)): n for p in sorted(PACKAGE.rglob("*.py"))
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES}
    assert not long, f"modules over {MAX_MODULE_LINES} lines: {long}"


def test_no_function_over_80_lines_outside_kernels():
    found = long_functions(package_trees())
    assert not found, f"functions over {MAX_FUNCTION_LINES} lines:\n" + "\n".join(found)


@pytest.mark.parametrize("source, expected", [
    # a long plain function is found; the same decorated or handed to numba is not
    ("def f():\n" + "    x = 1\n" * 10, ["m: f (11 lines)"]),
    ("@cached\ndef f():\n" + "    x = 1\n" * 10, []),
    ("def f():\n" + "    x = 1\n" * 10 + "g = specialise(f, i8)\n", []),
    # a factory's returned kernel is left out of the factory's lines, not its own code
    ("def fac():\n    y = 0\n    def k():\n" + "        x = 1\n" * 10
     + "    return k\nloop = fac()\ng = specialise(loop)\n", []),
    ("def fac():\n" + "    y = 0\n" * 10 + "    def k():\n        x = 1\n    return k\n"
     "g = njit(inline='always')(fac())\n", ["m: fac (12 lines)"]),
])
def test_the_rule_tells_kernels_from_functions(source, expected):
    """Limit 10 lines on toy modules: what counts and what is left out."""
    assert long_functions({"m": ast.parse(source)}, limit=10) == expected
