"""What each generated page of the docs was generated from, and which pages are stale.

    python docs/generate/provenance.py                 # pages whose inputs changed since
    python docs/generate/provenance.py --check         # the same, exit 1 if any
    python docs/generate/provenance.py --stamp docs/rheology.md   # record a page as current
    python docs/generate/provenance.py --from-git      # record each page's inputs as they
                                                       # were at the page's last commit

A page's inputs are files named by glob patterns (:data:`PAGES`): its generator's
modules, the case files and caches it reads, and the code that computes its numbers
(:data:`KERNELS`: the models' and the scheme's kernels, the solver, the summaries). The
record, docs/generated.json, holds for each page the SHA-256 of its inputs' paths and
contents when it was last generated; the generators that write through
``run_cache.publish`` stamp their page themselves, the others are stamped with
``--stamp`` after they ran. A page is stale when its inputs' hash differs from the
record (a code change that keeps every number, e.g. a move of kernels checked
bit-identical, is then recorded with ``--stamp``).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RECORD = ROOT / "docs" / "generated.json"

KERNELS = ("pdeflow/numerics/**/*.py", "pdeflow/models/**/*.py", "pdeflow/solvers/**/*.py",
           "pdeflow/systems.py", "pdeflow/initial_shapes.py", "pdeflow/metrics.py",
           "pdeflow/simulate.py")
"""the code behind every run's numbers (the CLI, the app and the figures' styling are not)"""


@dataclass(frozen=True)
class Page:
    """A generated page: the command that writes it and its inputs (glob patterns
    relative to the repository's root; :data:`KERNELS` are added)."""

    command: str
    inputs: tuple[str, ...]


_AXI = ("docs/generate/axisymmetric*.py", "docs/generate/run_cache.py",
        "docs/generate/law_set.py", "cases/axisymmetric_collapse*.toml",
        "cases/paper_5_2_two_layer_law.toml", "pdeflow/analysis/sweep.py")

PAGES: dict[str, Page] = {
    "docs/axisymmetric.md": Page("python docs/generate/axisymmetric.py",
                                 (*_AXI, "docs/axisymmetric/sweep.csv")),
    "docs/rheology.md": Page("python docs/generate/rheology.py",
                             (*_AXI, "docs/generate/rheology*.py", "cases/collapse_sweep.toml",
                              "docs/rheology/sweep.csv")),
    "docs/erodible_bed.md": Page("python docs/generate/erodible_bed.py",
                                 ("docs/generate/erodible_bed*.py", "docs/generate/run_cache.py",
                                  "docs/generate/law_set.py", "cases/erodible_bed.toml",
                                  "cases/paper_5_2_two_layer_law.toml",
                                  "pdeflow/erosion.py", "docs/erodible_bed/sweep.csv")),
    "docs/calibration_5_1.md": Page(
        "python docs/generate/calibration.py > docs/calibration_5_1.md",
        ("docs/generate/calibration.py", "cases/study_calibration_5_1.toml",
         "cases/paper_5_1_dam_break.toml", "cases/collapse_sweep.toml",
         "docs/studies/calibration_5_1/*.csv")),
    "docs/calibration_relaxed.md": Page(
        "python docs/generate/calibration.py --study-relaxed > docs/calibration_relaxed.md",
        ("docs/generate/calibration.py", "cases/study_calibration_relaxed.toml",
         "cases/paper_5_1_dam_break.toml", "cases/collapse_sweep.toml",
         "docs/studies/calibration_relaxed/*.csv")),
    "docs/convergence.md": Page("python docs/generate/convergence.py",
                                ("docs/generate/convergence.py", "cases/paper_5_1_dam_break.toml",
                                 "cases/collapse_sweep.toml", "pdeflow/analysis/convergence.py")),
    "docs/rest_erosive_regime.md": Page("python docs/generate/rest_erosive_regime.py",
                                        ("docs/generate/rest_erosive_regime.py",
                                         "cases/paper_5_1_dam_break.toml")),
    "docs/stability.md": Page("python docs/generate/stability.py --extremes",
                              ("docs/generate/stability.py", "pdeflow/analysis/stability.py",
                               "cases/paper_5_1_dam_break.toml")),
    "docs/two_layer_law.md": Page("python docs/generate/two_layer_law.py --reuse",
                                  ("docs/generate/two_layer_law*.py", "cases/collapse_sweep.toml",
                                   "cases/paper_5_1_dam_break.toml",
                                   "cases/paper_5_2_two_layer_law.toml",
                                   "cases/study_two_layer_law*.toml", "docs/two_layer_law_*.csv",
                                   "docs/studies/two_layer_law*/*.csv")),
    "docs/validation.md": Page("python docs/generate/validation.py",
                               ("docs/generate/validation.py", "cases/ritter_dam_break.toml",
                                "cases/stoker_dam_break.toml",
                                "cases/mangeney_dam_break_slope.toml",
                                "cases/collapse_sweep.toml", "pdeflow/analysis/validation.py",
                                "pdeflow/analysis/exact.py")),
    "docs/positivity_stress.png": Page("python docs/generate/positivity.py",
                                       ("docs/generate/positivity.py",
                                        "pdeflow/analysis/positivity.py")),
    "docs/teaching.md": Page("python docs/generate/teaching_screenshots.py",
                             ("docs/generate/teaching_screenshots.py", "pdeflow/app/**/*.py",
                              "tests/browser.py", "cases/paper_5_1_dam_break.toml",
                              "cases/collapse_sweep.toml")),
    "docs/performance.md": Page("python benchmarks/run_benchmarks.py",
                                ("benchmarks/*.py", "benchmarks/measurements/*.json")),
}
"""every generated page (or figure) of the docs, by its path from the repository's root"""


def input_files(page: str, listing: Iterable[str]) -> list[str]:
    """The files of ``listing`` (paths relative to the root) that are inputs of ``page``,
    sorted."""
    patterns = (*PAGES[page].inputs, *KERNELS)
    return sorted(p for p in set(listing) if any(Path(p).match(pat) or _glob_match(p, pat)
                                                 for pat in patterns))


def _glob_match(path: str, pattern: str) -> bool:
    """``pattern`` with ``**`` (any number of folders) against ``path``, from the root
    (``Path.match`` matches from the right, and ``**`` as one folder before 3.13)."""
    if "**/" not in pattern:
        return False
    head, tail = pattern.split("**/", 1)
    return path.startswith(head) and Path(path).match(tail)


def inputs_hash(files: Iterable[str], read: Callable[[str], bytes]) -> str:
    """SHA-256 over the paths and contents of ``files`` (``read(path)`` gives a file's
    bytes)."""
    digest = hashlib.sha256()
    for path in sorted(files):
        digest.update(path.encode() + b"\0" + hashlib.sha256(read(path)).digest())
    return digest.hexdigest()


def _tracked(root: Path) -> list[str]:
    """The files of the checkout at ``root`` that git tracks or would (untracked, not
    ignored), or every file below it outside git."""
    try:
        out = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard"],
                             cwd=root, capture_output=True, text=True, check=True).stdout
        return [p for p in out.splitlines() if (root / p).is_file()]
    except (OSError, subprocess.CalledProcessError):
        return [str(p.relative_to(root)) for p in root.rglob("*") if p.is_file()]


def current_hash(page: str, root: Path = ROOT) -> str:
    """The hash of ``page``'s inputs in the working tree at ``root``."""
    return inputs_hash(input_files(page, _tracked(root)), lambda p: (root / p).read_bytes())


def read_record(path: Path = RECORD) -> dict[str, dict[str, str]]:
    """The stored record (page -> {"command", "inputs_sha256"}); empty if none."""
    return json.loads(path.read_text()) if path.is_file() else {}


def stamp(pages: Iterable[str], root: Path = ROOT, record: Path = RECORD,
          hashes: dict[str, str] | None = None) -> None:
    """Record ``pages`` as generated from their inputs as they are now (or from
    ``hashes``); the record is rewritten only if it changes."""
    from pdeflow.io import write_json

    data = read_record(record)
    new = dict(data)
    for page in pages:
        if page not in PAGES:
            raise SystemExit(f"provenance: {page!r} is not a generated page; one of: "
                             + ", ".join(sorted(PAGES)))
        new[page] = {"command": PAGES[page].command,
                     "inputs_sha256": (hashes or {}).get(page) or current_hash(page, root)}
    if new != data:
        write_json(record, dict(sorted(new.items())))


def stale(root: Path = ROOT, record: Path = RECORD) -> list[str]:
    """The pages whose inputs differ from the record (or that have none)."""
    data = read_record(record)
    return [page for page in PAGES
            if data.get(page, {}).get("inputs_sha256") != current_hash(page, root)]


def hashes_from_git(root: Path = ROOT) -> dict[str, str]:
    """Each page's inputs hash as its inputs were at the page's last commit."""
    out = {}
    for page in PAGES:
        commit = subprocess.run(["git", "log", "-1", "--format=%H", "--", page], cwd=root,
                                capture_output=True, text=True, check=True).stdout.strip()
        if not commit:
            continue
        listing = subprocess.run(["git", "ls-tree", "-r", "--name-only", commit], cwd=root,
                                 capture_output=True, text=True, check=True).stdout.split()

        def show(path: str, commit: str = commit) -> bytes:
            return subprocess.run(["git", "show", f"{commit}:{path}"], cwd=root,
                                  capture_output=True, check=True).stdout

        out[page] = inputs_hash(input_files(page, listing), show)
    return out


def main(argv: list[str] | None = None) -> int:
    """List the stale pages, or stamp pages as current."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="exit 1 if any page is stale")
    ap.add_argument("--stamp", nargs="+", metavar="PAGE", help="record PAGE as current")
    ap.add_argument("--from-git", action="store_true",
                    help="record every page's inputs as of the page's last commit")
    args = ap.parse_args(argv)
    if args.stamp:
        stamp(args.stamp)
    if args.from_git:
        hashes = hashes_from_git()
        stamp(hashes, hashes=hashes)
    old = stale()
    for page in old:
        print(f"{page}: inputs changed since it was generated; regenerate with "
              f"`{PAGES[page].command}`")
    if not old:
        print(f"all {len(PAGES)} generated pages are current", file=sys.stderr)
    return 1 if args.check and old else 0


if __name__ == "__main__":
    raise SystemExit(main())
