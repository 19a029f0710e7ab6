"""Every command in README.md and docs/*.md runs, and the output the docs quote is what it
prints (docs/architecture.md, "Commands in the docs are tested", is the convention).

Each fenced ``bash`` block of a page is taken line by line (tests/doc_commands.py):

* ``pdeflow ...`` runs in this process (``pdeflow.cli.main``, the console script's own
  entry: the same output without 2-3 s of imports per command) in a scratch directory
  holding ``cases/``; it must exit 0. A ``<!-- test: set KEY=VALUE ... -->`` comment
  above the block appends ``--set KEY=VALUE`` to each (small grids, short runs), a
  ``<!-- test: before CMD -->`` runs CMD first (a file the block reads).
* Usage lines (``pdeflow run CASE.toml [--set ...]``: brackets, ``|``, upper-case
  placeholders) are checked against the command's ``--help``: every option they name
  exists. ``pdeflow app`` (a server) is parsed, not run.
* ``python docs/generate/*.py`` and other scripts: the file exists and defines every
  option the docs give it (read from its source); the slow test runs them.
* ``pip install ".[extra]"``: the extra exists in pyproject.toml (nothing installed);
  ``python -m pytest PATH``: the path exists.
* Anything else needs ``<!-- test: skip REASON -->``.

A ``text`` block under ``<!-- test: output CMD -->`` is CMD's printed output: each of its
lines must appear, in order, in what CMD prints now, every number equal within the digits
printed (``<!-- test: vary wall -->``: lines and table columns naming "wall" are not
compared). Identical commands run once per session.
"""

from __future__ import annotations

import io
import os
import subprocess
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import pytest

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

from tests.doc_commands import (
    OPTION,
    ROOT,
    SHELL,
    Block,
    blocks,
    commands,
    compare_output,
    kind,
    options,
    pages,
    script_options,
    strip_env,
)

PAGES = pages()
_OUTPUTS: dict[tuple[str, ...], tuple[int, str]] = {}


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One scratch directory for every page's commands, with the repository's cases."""
    path = tmp_path_factory.mktemp("doc_commands")
    (path / "cases").symlink_to(ROOT / "cases")
    return path


def _option_strings(name: str) -> set[str]:
    """The options ``pdeflow NAME --help`` lists."""
    _, text = pdeflow([name, "--help"], ROOT)
    return set(OPTION.findall(text))


def pdeflow(argv: list[str], cwd: Path) -> tuple[int, str]:
    """``pdeflow ARGV`` in this process, in ``cwd``: the exit code and what it printed
    (stdout and stderr together, in order); identical commands run once."""
    key = tuple(argv)
    if key not in _OUTPUTS:
        from pdeflow.cli import main

        buf = io.StringIO()
        old = Path.cwd()
        os.chdir(cwd)
        try:
            with redirect_stdout(buf), redirect_stderr(buf):
                try:
                    code = main(list(argv))
                except SystemExit as err:  # --help
                    code = err.code if isinstance(err.code, int) else 0
        finally:
            os.chdir(old)
        _OUTPUTS[key] = (code, buf.getvalue())
    return _OUTPUTS[key]


def with_sets(cmd: list[str], block: Block) -> list[str]:
    """The pdeflow arguments of a command with the block's ``set`` directives appended
    (to the subcommands that take --set)."""
    argv = cmd[1:]
    if block.sets() and "--set" in _option_strings(argv[0]):
        argv = argv + [x for s in block.sets() for x in ("--set", s)]
    return argv


def _extras() -> set[str]:
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())
    return set(data["project"]["optional-dependencies"])


def check_static(cmd: list[str], block: Block) -> None:
    """The checks of a command that is not run: installs, pytest lines, scripts, usage
    lines, the app."""
    what, cmd = kind(cmd), strip_env(cmd)
    where = f"{block.where()}: {' '.join(cmd)}"
    if what == "install":
        for tok in cmd[2:]:
            if tok.startswith(".["):
                for extra in tok[2:].rstrip("]").split(","):
                    assert extra in _extras(), f"{where}: no extra {extra!r} in pyproject"
    elif what == "pytest":
        for tok in cmd[3:]:
            if tok.startswith("tests"):
                assert (ROOT / tok.split("::")[0]).exists(), f"{where}: no {tok}"
    elif what == "script":
        path = ROOT / cmd[1]
        assert path.is_file(), f"{where}: no {cmd[1]}"
        unknown = set(options(cmd[1:])) - script_options(path)
        assert not unknown, f"{where}: {cmd[1]} has no option {sorted(unknown)}"
    elif what == "synopsis":
        unknown = set(options(cmd[1:])) - _option_strings(cmd[1])
        assert not unknown, f"{where}: pdeflow {cmd[1]} has no option {sorted(unknown)}"
    elif what in ("app", "pdeflow"):
        from pdeflow.cli import build_parser

        with redirect_stdout(io.StringIO()), redirect_stderr(io.StringIO()):
            try:
                build_parser().parse_args(with_sets(cmd, block))
            except SystemExit as err:  # --help, or an argument the parser rejects
                assert err.code == 0, f"{where}: the parser rejects it"

    else:
        raise AssertionError(f"{where}: not a command the test knows; run it from "
                             "pdeflow/python, or annotate <!-- test: skip REASON -->")


def run_command(cmd: list[str], block: Block, cwd: Path) -> str:
    """Run a command of a block (pdeflow in process, other python as a subprocess) and
    return what it printed; it must succeed."""
    what = kind(cmd)
    if what == "pdeflow":
        code, out = pdeflow(with_sets(cmd, block), cwd)
    else:
        proc = subprocess.run(strip_env(cmd), cwd=cwd, capture_output=True, text=True,
                              env={**os.environ, "PYTHONPATH": str(ROOT)})
        code, out = proc.returncode, proc.stdout + proc.stderr
    assert code == 0, f"{block.where()}: `{' '.join(cmd)}` exited {code}:\n{out[-3000:]}"
    return out


def _runs_here(cmd: list[str], block: Block, slow: bool) -> bool:
    """Whether the default suite (slow=False) or the slow test runs this command."""
    what = kind(cmd)
    if block.has("parse") or what not in ("pdeflow", "python", "script"):
        return False
    if what == "script":
        return slow
    return slow == block.has("slow")


def check_block(block: Block, cwd: Path, slow: bool = False) -> int:
    """Everything the test does with one block; the number of commands run."""
    if block.has("skip"):
        assert all(block.get("skip")), f"{block.where()}: skip needs a reason"
        return 0
    ran = 0
    if block.lang in SHELL:
        cmds = commands(block.text)
        for cmd in (c for c in cmds if kind(c) != "python"):
            check_static(cmd, block)
        if any(_runs_here(c, block, slow) for c in cmds):
            for before in block.get("before"):
                run_command(commands(before)[0], block, cwd)
        for cmd in cmds:
            if _runs_here(cmd, block, slow):
                run_command(cmd, block, cwd)
                ran += 1
    for command in block.get("output"):
        cmd = commands(command)[0]
        if slow != block.has("slow"):
            continue
        for before in block.get("before"):
            run_command(commands(before)[0], block, cwd)
        printed = run_command(cmd, block, cwd)
        problems = compare_output(block.text, printed, block.get("vary")[0].split()
                                  if block.get("vary") else [])
        assert not problems, (f"{block.where()}: the documented output of `{command}` is "
                              "not what it prints now:\n  " + "\n  ".join(problems))
        ran += 1
    return ran


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_page_commands(page: Path, workdir: Path) -> None:
    """The page's commands run (or are checked) and its quoted outputs are current."""
    for block in blocks(page):
        check_block(block, workdir)


@pytest.mark.slow
@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_page_slow_commands(page: Path, tmp_path: Path) -> None:
    """The long commands: generators (they rewrite their pages in docs/) and the blocks
    marked slow."""
    (tmp_path / "cases").symlink_to(ROOT / "cases")
    for block in blocks(page):
        check_block(block, tmp_path, slow=True)


def test_convention_is_documented_and_parsed() -> None:
    """The directives are the documented ones, and every page's shell blocks parse."""
    known = {"set", "before", "output", "vary", "slow", "parse", "skip"}
    text = (ROOT / "docs" / "architecture.md").read_text()
    assert "## Commands in the docs are tested" in text
    for page in PAGES:
        for block in blocks(page):
            for name, _ in block.directives:
                assert name in known, f"{block.where()}: unknown directive {name!r}"
            if block.lang in SHELL and not block.has("skip"):
                assert commands(block.text), f"{block.where()}: an empty command block"
            if block.get("output"):
                assert block.lang in ("text", ""), f"{block.where()}: output on {block.lang}"
