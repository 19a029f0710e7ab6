"""The outputs of ``pdeflow run``: its folder, checked before the run, staged while the
run goes and after it, then written all together, or not at all.

* **The folder.** Without output options a run writes its summary and figures to
  ``results/<case>/`` for the case as written and to ``results/<case>--<overrides>/``
  for a run with ``--set`` overrides (:func:`run_folder`): every variant of a case has
  its own folder, whose name says which it is (its ``summary.json`` lists the
  overrides). ``--outdir DIR`` names the folder instead. A run *replaces* its folder as
  a whole (:class:`pdeflow.io.PendingDir`), so no file of an earlier run (a longer
  run's snapshots) stays beside the new ones; a folder that holds anything else than
  a run's files is refused before the run (:func:`check_run_folder`), as are other
  outputs inside it.
* **Staged, then committed.** The movie, frames and stored runs are written under
  temporary names while the models run; after the last one the summary, final states
  and figures are written under temporary names too, and :meth:`RunOutputs.write`
  then renames everything into place, with SIGINT and SIGTERM held back. An interrupt
  before that keeps nothing (older files at the same names stay as they were); one
  that comes while the outputs are written lets them all be completed first.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import re
from pathlib import Path
from typing import Any

from .io import (
    OutputError,
    PendingDir,
    PendingFile,
    discard_pending,
    signals_blocked,
    write_json,
    write_npz,
)
from .outpaths import FIGURE_SUFFIXES, check_dir, check_file

RESULTS = Path("results")
"""the parent folder of the default run folders"""
MAX_NAME = 120
"""longest folder name [characters]; longer override lists end in a hash"""


def model_path(path: str | Path, model: str, first: bool) -> Path:
    """Per-model output name: PATH for the first model, NAME.<model>.SUFFIX after it."""
    path = Path(path)
    return path if first else path.with_name(f"{path.stem}.{model}{path.suffix}")


def _value_text(value: Any) -> str:
    """A parsed override value as it appears in a folder name."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, list):
        return ",".join(_value_text(v) for v in value)
    if isinstance(value, dict):
        return ",".join(f"{k}:{_value_text(v)}" for k, v in sorted(value.items()))
    return repr(value) if isinstance(value, float) else str(value)


def run_folder(case_name: str, overrides: list[str]) -> Path:
    """The default folder of a run: ``results/<case>`` for the case as written,
    ``results/<case>--<section.key=value>--...`` with overrides.

    The overrides are parsed as the case parses them, the last of a key wins and they
    are sorted by key, so that the same variant always gets the same folder
    (``grid.dx=5e-4`` and ``grid.dx=0.0005`` too); ``case.name`` names the case, not a
    variant. Characters other than letters, digits and ``._,=+-`` become ``_``; a name
    longer than :data:`MAX_NAME` is cut and ends in a hash of the whole."""
    from .cases import Case

    parsed = Case({})
    for item in overrides:
        parsed.set(item)
    parts = sorted(f"{section}.{key}={_value_text(value)}"
                   for section, table in parsed.data.items() for key, value in table.items()
                   if (section, key) != ("case", "name"))
    if not parts:
        return RESULTS / case_name
    name = re.sub(r"[^A-Za-z0-9._,=+-]", "_", "--".join([case_name, *parts]))
    if len(name) > MAX_NAME:
        digest = hashlib.sha1(name.encode()).hexdigest()[:10]
        name = f"{name[:MAX_NAME - 12]}--{digest}"
    return RESULTS / name


def _is_run_file(path: Path) -> bool:
    """A file a run writes into its folder (or a temporary one left by a killed run)."""
    if path.name.startswith(".") and ".part" in path.name:
        return True
    return path.is_file() and (path.name == "summary.json" or path.suffix == ".png"
                               or (path.name.startswith("peak_")  # a run over a bed's
                                   and path.suffix in (".asc", ".prj")))


def _is_run_summary(path: Path) -> bool:
    """Whether ``path`` is the summary.json of a pdeflow run."""
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and {"case", "pdeflow_version", "models"} <= set(data)


def check_run_folder(path: Path, option: str) -> None:
    """Raise :class:`OutputError` unless the run may replace ``path`` as a whole: it does
    not exist, is empty, or is an earlier run's folder (its ``summary.json``, figures
    and peak rasters, nothing else); it is not the working directory or above it."""
    if not path.exists():
        return
    if Path.cwd().resolve().is_relative_to(path.resolve()):
        raise OutputError(f"{option} {path}: is the working directory or holds it; a run "
                          "replaces its folder as a whole: give a folder of its own")
    entries = sorted(path.iterdir())
    if not entries:
        return
    foreign = [p.name for p in entries if not _is_run_file(p)]
    if not foreign and not _is_run_summary(path / "summary.json"):
        foreign = ["no summary.json of a pdeflow run"]
    if foreign:
        shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
        raise OutputError(f"{option} {path}: is not a run's folder ({shown}); a run "
                          "replaces its folder as a whole: give a new or empty folder")


def check_run_outputs(args: argparse.Namespace, outdir: Path | None) -> None:
    """Every output of ``pdeflow run`` can be written, checked before the run."""
    check_file(args.summary, "--summary", (".json",))
    check_file(args.final, "--final", (".npz",))
    check_file(args.plot, "--plot", FIGURE_SUFFIXES)
    check_file(args.store, "--store", (".h5", ".hdf5"))
    check_file(args.movie, "--movie")
    check_dir(args.frames, "--frames")
    check_dir(outdir, "--outdir", create=not args.outdir)
    if outdir is not None:
        option = "--outdir" if args.outdir else "the run's folder"
        check_run_folder(outdir, option)
        for name in ("summary", "final", "plot", "store", "movie", "frames"):
            value = getattr(args, name)
            if value and Path(value).resolve().is_relative_to(outdir.resolve()):
                raise OutputError(f"--{name} {value}: is inside {option} {outdir}, which "
                                  "a run replaces as a whole; write it elsewhere")
    if args.movie:
        from .trackers.live import check_movie_path

        check_movie_path(args.movie)
    if args.store:
        from .storage import require_h5py

        require_h5py()


class RunOutputs:
    """The outputs of one ``pdeflow run``: the trackers that write while the models run
    (:meth:`add`), then :meth:`write`; :meth:`discard` removes everything not yet
    written (a failed or interrupted run)."""

    def __init__(self, args: argparse.Namespace, outdir: Path | None):
        self.args = args
        self.outdir = outdir
        self.trackers: list[Any] = []  # those that hold files: commit() and discard()
        self.staged: list[tuple[PendingFile | PendingDir, Any]] = []
        # the folders the run would create (results/, the frames' DIR): removed again,
        # if still empty, when nothing is written
        self.created = [d for top in (outdir, args.frames and Path(args.frames)) if top
                        for d in (top, *top.parents) if not d.exists()]

    def add(self, trackers: list[Any]) -> None:
        """Keep the trackers among ``trackers`` that write files."""
        self.trackers.extend(t for t in trackers if hasattr(t, "discard"))

    def _stage(self, case: Any, summary: dict, results: dict, figures: Any) -> None:
        """Write the summary, final states and figures under temporary names."""
        args = self.args
        folder = PendingDir(self.outdir) if self.outdir else None
        if folder is not None:
            self.staged.append((folder, folder.path / "summary.json"))
            write_json(folder.tmp / "summary.json", summary)
        if args.summary:
            self._file(args.summary, lambda tmp: write_json(tmp, summary))
        for m in case.models if folder is not None else []:
            self._peak_outputs(case, m, results[m], folder)
        for i, m in enumerate(case.models if args.final else []):
            self._file(model_path(args.final, m, i == 0),
                       lambda tmp, m=m: write_npz(tmp, results[m].final_arrays()))
        if figures is None:
            return
        from .case_figures import run_figure_jobs

        plot = PendingFile(args.plot) if args.plot else None
        if plot is not None:
            self.staged.append((plot, plot.path))
        jobs = run_figure_jobs(results, folder and folder.tmp, plot and plot.tmp)
        for path in figures.draw(jobs):
            if folder is not None and Path(path).parent == folder.tmp:
                self.staged.append((_Done(), folder.path / Path(path).name))

    def _peak_outputs(self, case: Any, model: str, result: Any, folder: PendingDir) -> None:
        """A run over a bed: its peak rasters and figure in the results folder."""
        if result.peak_fields is None:
            return
        from .numerics.geometry import centre_values
        from .terrain_run import write_peak_outputs

        bed = centre_values(result.metric.bed)
        suffix = "" if len(case.models) == 1 else f"_{model}"
        for path in write_peak_outputs(case, model, result.peak_fields, bed, folder.tmp,
                                       suffix):
            self.staged.append((_Done(), folder.path / path.name))

    def _file(self, path: str | Path, write: Any) -> None:
        """Stage one file: ``write(tmp)`` writes it under its temporary name."""
        pending = PendingFile(path)
        self.staged.append((pending, pending.path))
        write(pending.tmp)

    def write(self, case: Any, summary: dict, results: dict, figures: Any = None
              ) -> list[Any]:
        """Write every output (the figures by ``figures``, a
        :class:`~pdeflow.figure_worker.RunFigures`), SIGINT and SIGTERM held back; a
        signal that came before is honoured first (nothing is written). Returns what
        was written."""
        from .interrupts import deferred_signals, note_written, received

        written: list[Any] = []

        def wrote(*paths: Any) -> None:  # told at once: the last line must be true
            written.extend(paths)
            note_written(paths)

        with deferred_signals():
            if received():  # its KeyboardInterrupt was swallowed on the way
                raise KeyboardInterrupt("a signal came before the results were written")
            self._stage(case, summary, results, figures)
            for pending, shown in self.staged:
                pending.commit()
                wrote(shown)
            for t in self.trackers_of("commit", "metadata"):  # the stored runs
                model = t.metadata["model"]
                extra = {"summary": summary["models"][model]}
                if results[model].series is not None:  # the erosion series (with a bed)
                    extra["erosion_series"] = results[model].series.to_dict()
                wrote(t.commit(extra))
            for t in self.trackers_of("commit", "frames_dir"):
                wrote(*_shown_live(t, t.commit()))
        return written

    def trackers_of(self, *attributes: str) -> list[Any]:
        """The trackers that have all ``attributes`` (stored runs: metadata, live
        plots: frames)."""
        return [t for t in self.trackers if all(hasattr(t, a) for a in attributes)]

    def discard(self) -> None:
        """Remove every temporary of the run (movies, frames, stored runs, the staged
        folder and files); targets stay as they were. A second Ctrl-C meanwhile waits
        until the clean-up is done."""
        with signals_blocked():
            for t in self.trackers:
                t.discard()
            discard_pending()
            for folder in sorted(self.created, key=lambda d: len(d.parts), reverse=True):
                try:
                    folder.rmdir()
                except OSError:
                    pass  # not empty (written meanwhile by someone else), or never made


class _Done:
    """A staged entry already in place with its folder (a figure)."""

    def commit(self) -> None:
        """Nothing left to do."""


def _shown_live(tracker: Any, paths: list[Path]) -> list[Any]:
    """What a live plot tracker wrote, as printed: the movie, the frames' pattern."""
    return [f"{p}/frame_*.png ({len(tracker.frame_paths)} frames)"
            if tracker.frames_dir is not None and p == tracker.frames_dir else p
            for p in paths]
