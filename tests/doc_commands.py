"""The fenced command blocks of README.md and docs/*.md, and what the docs-commands test
does with each command (tests/test_docs_commands.py; the convention is in
docs/architecture.md, "Commands in the docs are tested").

A block is a fenced code block; ``bash``/``sh``/``shell``/``console`` blocks hold
commands, one per line (``\\`` or an indented next line continues a line, ``#`` starts a
comment, ``&&`` chains), and a ``text`` block may be the printed output of a command.
HTML comments on the lines right above the opening fence annotate a block, one directive
each::

    <!-- test: set grid.dx=0.1 case.t_end=0.3 -->   appended as --set to every pdeflow command
    <!-- test: before pdeflow run cases/x.toml --store run.h5 -q -->   run first, not shown
    <!-- test: output pdeflow sweep cases/collapse_sweep.toml -->  (text block) its output
    <!-- test: vary wall -->      (output block) numbers in lines / columns naming it differ
    <!-- test: slow -->           run only by the slow test (minutes or more)
    <!-- test: parse -->          pdeflow commands parsed, not run
    <!-- test: skip REASON -->    nothing run or checked (say why)
"""

from __future__ import annotations

import ast
import re
import shlex
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHELL = {"bash", "sh", "shell", "console"}
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```[ \t]*$", re.S | re.M)
DIRECTIVE = re.compile(r"<!--\s*test:\s*(.*?)\s*-->", re.S)
PLACEHOLDER = re.compile(r"^[A-Z][A-Z0-9_]*(\.[a-z0-9]+)?$")  # CASE.toml, OUT.json, DIR, N
NUMBER = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?(?![\w.])")
OPTION = re.compile(r"(?<![\w.=/-])(--?[A-Za-z][\w-]*)")


def pages() -> list[Path]:
    """README.md and every docs/*.md, the pages whose commands are tested."""
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


@dataclass
class Block:
    """A fenced block of a page, with the directives above it."""

    page: Path
    line: int
    lang: str
    text: str
    directives: list[tuple[str, str]] = field(default_factory=list)

    def where(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"

    def get(self, name: str) -> list[str]:
        """The arguments of every directive ``name`` of the block."""
        return [arg for key, arg in self.directives if key == name]

    def has(self, name: str) -> bool:
        return any(key == name for key, _ in self.directives)

    def sets(self) -> list[str]:
        return [s for arg in self.get("set") for s in shlex.split(arg)]


def blocks(page: Path) -> list[Block]:
    """The fenced blocks of a page in order, each with the directives in the HTML comments
    on the lines right above its fence."""
    text = page.read_text()
    out = []
    for m in FENCE.finditer(text):
        before = text[:m.start()].rstrip("\n").split("\n")
        comments: list[str] = []
        while before and before[-1].strip().startswith("<!--") and "test:" in before[-1]:
            comments.insert(0, before.pop().strip())
        directives = []
        for comment in comments:
            for body in DIRECTIVE.findall(comment):
                name, _, arg = body.partition(" ")
                directives.append((name, arg.strip()))
        out.append(Block(page, text[:m.start()].count("\n") + 1, m.group(1).lower(),
                         m.group(2), directives))
    return out


def commands(text: str) -> list[list[str]]:
    """The commands of a shell block as argument lists: continuation lines joined,
    comments dropped, ``&&`` chains split."""
    joined = re.sub(r"\\\n|\n(?=[ \t])", " ", text)  # "\" or an indented next line
    out = []
    for line in joined.splitlines():
        tokens = shlex.split(line, comments=True)
        while tokens:
            if "&&" in tokens:
                i = tokens.index("&&")
                out.append(tokens[:i])
                tokens = tokens[i + 1:]
            else:
                out.append(tokens)
                tokens = []
    return [c for c in out if c]


def strip_env(cmd: list[str]) -> list[str]:
    """The command without leading ``NAME=value`` environment settings."""
    i = 0
    while i < len(cmd) and re.match(r"^[A-Z_][A-Z0-9_]*=", cmd[i]):
        i += 1
    return cmd[i:]


def is_synopsis(cmd: list[str]) -> bool:
    """A usage line (``pdeflow run CASE.toml [--set ...]``), not a runnable command:
    brackets, alternatives or upper-case placeholders."""
    return any(tok.startswith("[") or tok.endswith("]") and "=" not in tok
               or "|" in tok and "=" not in tok for tok in cmd) or any(
        PLACEHOLDER.match(tok) for tok in cmd[1:])


def options(cmd: list[str]) -> list[str]:
    """The options a command (or synopsis) names: ``--set``, ``-q``."""
    return OPTION.findall(" ".join(cmd[1:]))


def script_options(path: Path) -> set[str]:
    """The option strings a script's argparse parser defines (read from its source,
    not run: ``add_argument("--quick", ...)``)."""
    found = {"-h", "--help"}
    for node in ast.walk(ast.parse(path.read_text())):
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                and node.func.attr == "add_argument"):
            found.update(a.value for a in node.args
                         if isinstance(a, ast.Constant) and isinstance(a.value, str))
    return found


def kind(cmd: list[str]) -> str:
    """What the test does with a command: 'install' (checked against the extras, not
    run), 'pytest' (paths checked), 'script' (a python file: options checked, run by
    the slow test), 'python' (other python, run), 'synopsis' (options checked against
    the command's --help), 'app' (a server: parsed), 'pdeflow' (run), or 'unknown'."""
    cmd = strip_env(cmd)
    if cmd[:2] == ["pip", "install"]:
        return "install"
    if cmd[:1] == ["python"]:
        if cmd[1:3] == ["-m", "pytest"]:
            return "pytest"
        return "script" if len(cmd) > 1 and cmd[1].endswith(".py") else "python"
    if cmd[:1] == ["pdeflow"]:
        if is_synopsis(cmd):
            return "synopsis"
        return "app" if cmd[1:2] == ["app"] else "pdeflow"
    return "unknown"


# --- numbers of printed output ----------------------------------------------------------

def _unit(number: str) -> float:
    """Half a unit in the last printed digit of a number (``7.3`` -> 0.05,
    ``2.4e-03`` -> 5e-05, ``402`` -> 0.5)."""
    mantissa, _, exponent = number.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    return 0.5 * 10.0 ** (-decimals + (int(exponent) if exponent else 0))


def _skeleton(line: str) -> str:
    return " ".join(NUMBER.sub("#", line).split())


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def numbers_agree(doc: str, printed: str) -> bool:
    """Two printed numbers agree to the digits both show: the difference is within half a
    unit of the finer one's last digit (``7.3`` against ``7.4`` does not, ``10`` against
    ``9.9`` does not, ``1.20`` against ``1.2`` does)."""
    tol = min(_unit(doc), _unit(printed))
    return abs(float(doc) - float(printed)) <= tol * (1 + 1e-9)


def _line_agrees(doc: str, out: str, skip_columns: set[int], vary: list[str]) -> bool:
    if _skeleton(doc) != _skeleton(out):
        return False
    if doc.strip().startswith("|"):
        pairs = [(i, d, o) for i, (d, o) in enumerate(zip(_cells(doc), _cells(out), strict=False))]
    else:
        pairs = [(0, doc, out)]
    for i, d, o in pairs:
        if i in skip_columns or any(w.lower() in d.lower() for w in vary):
            continue
        if not all(numbers_agree(a, b) for a, b in zip(NUMBER.findall(d), NUMBER.findall(o),
                                                     strict=False)):
            return False
    return True


def compare_output(doc_text: str, output: str, vary: list[str]) -> list[str]:
    """The lines of a documented output that the printed output does not have, in order
    (an excerpt may leave lines out); numbers compared within their printed digits, not
    at all in lines naming a ``vary`` word or in table columns whose header names one."""
    out_lines = [ln for ln in output.splitlines() if ln.strip()]
    problems, pos, skip_columns = [], 0, set()
    for doc in (ln for ln in doc_text.splitlines() if ln.strip()):
        if doc.strip().startswith("|") and not skip_columns and "---" not in doc:
            skip_columns = {i for i, c in enumerate(_cells(doc))
                            if any(w.lower() in c.lower() for w in vary)}
        candidates = [j for j in range(pos, len(out_lines))
                      if _skeleton(out_lines[j]) == _skeleton(doc)]
        match = next((j for j in candidates
                      if _line_agrees(doc, out_lines[j], skip_columns, vary)), None)
        if match is None:
            near = out_lines[candidates[0]] if candidates else "(no line of that form)"
            problems.append(f"documented: {doc.strip()}\n    printed:    {near.strip()}")
        else:
            pos = match + 1
    return problems
