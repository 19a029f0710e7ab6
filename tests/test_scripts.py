"""The scripts outside the package (benchmarks/, docs/generate/) still fit the package.

They import pdeflow inside functions and inside the code they hand to fresh
interpreters (strings run with ``python -c``), so importing them proves little: a
renovation that removes a module breaks them only when someone runs the benchmark.
Here every such import is read with ``ast``, in the script and in every string of it
that is Python code naming pdeflow, and resolved against the current package: each
``from pdeflow.x import y`` names a module and a name that exist, and each attribute
read or patched through an imported pdeflow module (``_fv_split.ready_all = ...``)
exists. Then every script with a ``__main__`` block parses ``--help`` (in this process:
no script runs its work before parsing its arguments).
"""

from __future__ import annotations

import ast
import importlib
import runpy
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).parents[1]
SCRIPTS = sorted((ROOT / "benchmarks").glob("*.py")) + sorted(
    (ROOT / "docs" / "generate").glob("*.py"))
MAINS = [p for p in SCRIPTS if '__name__ == "__main__"' in p.read_text(encoding="utf-8")]


def _ids(paths: list[Path]) -> list[str]:
    return [str(p.relative_to(ROOT)) for p in paths]


def code_of(path: Path) -> Iterator[tuple[str, ast.Module]]:
    """The script's syntax tree, then that of every string in it that parses as Python
    and names pdeflow (code run in a child interpreter); each with a label."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    yield "module", tree
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) \
                and "pdeflow" in node.value and "import" in node.value:
            try:
                inner = ast.parse(node.value)
            except SyntaxError:
                continue  # prose, not code
            yield f"string at line {node.lineno}", inner


def _module(name: str, here: Path) -> ModuleType | None:
    """``name`` imported, if it is pdeflow's or a sibling script of ``here``; else None
    (a third-party module is not this test's business)."""
    top = name.split(".")[0]
    if top == "pdeflow":
        return importlib.import_module(name)
    if (here / f"{top}.py").exists():
        sys.path.insert(0, str(here))  # a sibling, as the script imports it
        try:
            return importlib.import_module(name)
        finally:
            sys.path.remove(str(here))
    return None


def missing_names(path: Path, tree: ast.Module) -> list[str]:
    """What ``tree`` imports from or reads off pdeflow (or a sibling script) that does
    not exist."""
    here, missing = path.parent, []
    aliases: dict[str, ModuleType] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                try:
                    mod = _module(alias.name, here)
                except ImportError as err:
                    missing.append(f"import {alias.name}: {err}")
                    continue
                if mod is not None:
                    aliases[alias.asname or alias.name.split(".")[0]] = (
                        mod if alias.asname else _module(alias.name.split(".")[0], here))
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            try:
                mod = _module(node.module, here)
            except ImportError as err:
                missing.append(f"from {node.module}: {err}")
                continue
            if mod is None:
                continue
            for alias in node.names:
                value = getattr(mod, alias.name, None)
                if value is None:
                    try:
                        value = importlib.import_module(f"{node.module}.{alias.name}")
                    except ImportError:
                        missing.append(f"from {node.module} import {alias.name}")
                        continue
                if isinstance(value, ModuleType):
                    aliases[alias.asname or alias.name] = value
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                and node.value.id in aliases:
            mod = aliases[node.value.id]
            if not hasattr(mod, node.attr):
                try:
                    importlib.import_module(f"{mod.__name__}.{node.attr}")
                except ImportError:
                    missing.append(f"{node.value.id}.{node.attr} ({mod.__name__}) "
                                   f"at line {node.lineno}")
    return missing


@pytest.mark.parametrize("path", SCRIPTS, ids=_ids(SCRIPTS))
def test_script_names_only_what_the_package_has(path):
    problems = [f"{where}: {name}" for where, tree in code_of(path)
                for name in missing_names(path, tree)]
    assert not problems, f"{path.relative_to(ROOT)} names what is gone:\n" + "\n".join(
        problems)


def test_the_check_finds_a_removed_name(tmp_path):
    """The check above fails on what the renovation broke: a module that is gone, in
    code handed to a child interpreter, and a patched attribute that is gone."""
    script = tmp_path / "old.py"
    script.write_text('CODE = """\nfrom pdeflow.numerics.bundles import SINGLE_LAYER\n"""\n'
                      "import pdeflow.solvers.fv_split as _fv\n"
                      "_fv.ready_all = None\n", encoding="utf-8")
    found = sorted(name for _, tree in code_of(script)
                   for name in missing_names(script, tree))
    assert len(found) == 2, found
    assert "ready_all" in found[0] and "bundles" in found[1], found


@pytest.mark.parametrize("path", MAINS, ids=_ids(MAINS))
def test_script_parses_help(path, monkeypatch, capsys):
    monkeypatch.syspath_prepend(str(path.parent))
    monkeypatch.setattr(sys, "argv", [str(path), "--help"])
    with pytest.raises(SystemExit) as stop:
        runpy.run_path(str(path), run_name="__main__")
    assert stop.value.code in (0, None)
    assert "usage:" in capsys.readouterr().out
