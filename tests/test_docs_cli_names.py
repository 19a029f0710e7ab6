"""Every pdeflow command the docs name in passing exists: ``python -m pdeflow.X`` a module
that runs, ``pdeflow VERB --option`` a command of the CLI with that option.

tests/test_docs_commands.py runs the fenced blocks of README.md and docs/*.md; the
commands named in prose, in study reports and study files, in the generators'
docstrings and in the case files' comments are not run, and one of them named a module
that never existed (``python -m pdeflow.analysis.calibration``, issue 38). This test
reads them all and checks the names against the package and the CLI's parser.
"""

from __future__ import annotations

import argparse
import importlib.util
import re
import shlex
from functools import cache
from pathlib import Path

import pytest

from pdeflow.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
SOURCES = ("README.md", "docs/**/*.md", "docs/**/*.toml", "docs/**/*.py", "docs/*.ipynb",
           "cases/*.toml")
"""Files whose text may name a command (globs under the repository's root)."""
MODULE = re.compile(r"python -m (pdeflow[\w.]*)")
INLINE = re.compile(r"`(pdeflow [a-z][^`]*)`")
"""A command in backticks (Markdown prose, docstrings)."""
LINE = re.compile(r"^[\s#$>\"]*(pdeflow [a-z].*)$", re.M)
"""A command on a line of its own (code blocks, ``::`` blocks, comments)."""
OPTION = re.compile(r"^--?[A-Za-z][\w-]*")


def _files() -> list[Path]:
    found = {p for pattern in SOURCES for p in ROOT.glob(pattern) if p.is_file()}
    return sorted(found)


def _named(pattern: re.Pattern[str]) -> list[tuple[str, str]]:
    """(file, match) for every match of ``pattern`` in the files, one each."""
    out = set()
    for path in _files():
        for m in pattern.findall(path.read_text(errors="replace")):
            out.add((str(path.relative_to(ROOT)), m.strip()))
    return sorted(out)


@cache
def _commands() -> dict[str, argparse.ArgumentParser]:
    """The CLI's subcommands and their parsers."""
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def _words(command: str) -> list[str]:
    """The words of a command up to a redirection, comment or the end of its sentence."""
    try:
        words = shlex.split(command, comments=True)
    except ValueError:  # an unclosed quote: a sentence, not a command line
        words = command.split()
    cut = next((i for i, w in enumerate(words) if w in (">", "|", "&&", ";")), len(words))
    return words[:cut]


def test_the_sources_are_read():
    """The scan sees the docs (a wrong glob would pass every check vacuously)."""
    assert len(_named(MODULE)) >= 2
    assert len(_named(INLINE)) + len(_named(LINE)) >= 50


@pytest.mark.parametrize("where,module", _named(MODULE))
def test_a_module_the_docs_run_exists(where, module):
    """``python -m pdeflow.X``: X is a module with a ``__main__`` guard, or a package
    with a ``__main__`` module."""
    spec = importlib.util.find_spec(module)
    assert spec is not None and spec.origin, f"{where}: no module {module}"
    if spec.submodule_search_locations:  # a package: python -m runs its __main__
        assert importlib.util.find_spec(f"{module}.__main__"), \
            f"{where}: {module} is a package without __main__"
    else:
        assert "__name__ == \"__main__\"" in Path(spec.origin).read_text(), \
            f"{where}: {module} does nothing when run with python -m"


def _pdeflow_commands() -> list[tuple[str, str]]:
    return sorted({*_named(INLINE), *_named(LINE)})


@pytest.mark.parametrize("where,command", _pdeflow_commands())
def test_a_pdeflow_command_the_docs_name_exists(where, command):
    """``pdeflow VERB ...``: VERB is a command of the CLI and every option named after
    it is one of that command's options."""
    words = _words(command)
    verb = words[1] if len(words) > 1 else ""
    if not re.fullmatch(r"[a-z]+", verb) or verb in ("is", "itself"):
        pytest.skip(f"not a command line: {command}")
    commands = _commands()
    assert verb in commands, f"{where}: pdeflow has no command {verb!r} ({command})"
    known = set(commands[verb]._option_string_actions)
    for word in words[2:]:
        option = OPTION.match(word)
        if option and not word.startswith("---"):
            assert option.group(0) in known, \
                f"{where}: pdeflow {verb} has no option {option.group(0)} ({command})"
