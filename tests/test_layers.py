"""The import layers of the whole package are those of docs/architecture.md's picture.

The picture (the first ``text`` block of the page) is the one table of layers: each of
its lines that starts at the left margin is a floor, top first, and names its modules
(``cli.py``) and packages (``analysis/``) before its description; a parenthesis
(``(but core.py)``) is a remark, and the most specific name wins (``study/core.py`` sits
below ``study/``). Every import of every module of pdeflow/, those inside functions and
under ``TYPE_CHECKING`` included, must point to its own floor or one below, and no
modules may import each other in a circle (directly or through others).
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
PACKAGE = ROOT / "pdeflow"
DOC = ROOT / "docs" / "architecture.md"


def picture_floors() -> list[list[str]]:
    """The floors of the picture, top first: the paths (relative to pdeflow/, packages
    ending in ``/``) each names."""
    text = DOC.read_text(encoding="utf-8")
    block = re.search(r"```text\n(.*?)```", text, re.S)
    assert block, "docs/architecture.md has no ```text picture of the layers"
    floors = []
    for line in block.group(1).splitlines():
        if line.strip().startswith("---"):
            break  # what follows is outside the package
        if not line.strip() or line[2:3].isspace():
            continue  # a description's continuation
        names = []
        for token in re.sub(r"\([^)]*\)", " ", line).split():
            if not (token.endswith(".py") or token.endswith("/")):
                break  # the description begins
            names.append(token)
        assert names, f"a floor of the picture names no module: {line!r}"
        floors.append(names)
    return floors


def module_names() -> dict[str, Path]:
    """Every module of the package by its dotted name (a package by its own name)."""
    mods = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        mods[".".join(parts)] = path
    return mods


def floor_of(module: str, floors: list[list[str]]) -> int | None:
    """The index of the floor (0 = top) whose most specific name holds ``module``."""
    rel = module.replace(".", "/")[len("pdeflow/"):] if module != "pdeflow" else ""
    best: tuple[int, int] | None = None
    for i, names in enumerate(floors):
        for name in names:
            if name == "__init__.py":
                hit = rel == ""
            elif name.endswith("/"):
                hit = rel != "" and (rel + "/").startswith(name)
            else:
                hit = rel + ".py" == name
            if hit and (best is None or len(name) > best[1]):
                best = (i, len(name))
    return None if best is None else best[0]


def imports(module: str, path: Path, mods: dict[str, Path]) -> Iterator[tuple[str, int]]:
    """The modules of pdeflow that ``module`` imports anywhere in its file, with the line."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]

    def known(name: str) -> str:
        while name and name not in mods:
            name = name.rpartition(".")[0]
        return name

    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join([*parts, base] if base else parts)
            # ``from pkg import mod`` imports the module mod, ``from mod import f`` mod
            names = [f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base
                     for a in node.names]
        else:
            continue
        for name in names:
            target = known(name) if name.split(".")[0] == "pdeflow" else ""
            if target and target != module:
                yield target, node.lineno


def import_graph() -> dict[str, dict[str, int]]:
    """module -> {imported module: line of its first import}."""
    mods = module_names()
    graph: dict[str, dict[str, int]] = {}
    for module, path in mods.items():
        graph[module] = {}
        for target, line in imports(module, path, mods):
            graph[module].setdefault(target, line)
    return graph


def circles(graph: dict[str, dict[str, int]]) -> list[list[str]]:
    """The sets of two or more modules that import each other (Tarjan's strongly
    connected components, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(graph[start]))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(graph.get(child, {}))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def test_the_picture_names_only_what_exists():
    for names in picture_floors():
        for name in names:
            assert (PACKAGE / name).exists(), f"docs/architecture.md names {name}: absent"


def test_every_module_is_on_a_floor_of_the_picture():
    floors = picture_floors()
    missing = [m for m in module_names() if floor_of(m, floors) is None]
    assert not missing, f"modules on no floor of docs/architecture.md: {missing}"


def test_every_import_points_down_or_across():
    floors = picture_floors()
    up = [f"{module} (line {line}) -> {target}"
          for module, targets in import_graph().items()
          for target, line in targets.items()
          if floor_of(target, floors) < floor_of(module, floors)]
    assert not up, "imports up the layers of docs/architecture.md:\n" + "\n".join(up)


def test_no_modules_import_each_other_in_a_circle():
    found = circles(import_graph())
    assert not found, f"circles of imports: {found}"


@pytest.mark.parametrize("graph, expected", [
    ({"a": {"b": 1}, "b": {"c": 1}, "c": {"a": 1}, "d": {"a": 1}}, [["a", "b", "c"]]),
    ({"a": {"b": 1}, "b": {}, "c": {"a": 1}}, []),
])
def test_circles_are_found(graph, expected):
    """The detector itself: a circle through three modules, and none in a chain."""
    assert circles(graph) == expected
