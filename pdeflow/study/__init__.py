"""Parameter studies from one study file, run on Dask (``pdeflow study``).

Modules, one job each: :mod:`.spec` (the study file: parameters, design,
quantities), :mod:`.expressions` (its [derived] and [objectives] expressions),
:mod:`.designs` (the points of a grid, Latin-hypercube or Sobol design; the optimiser's
trials), :mod:`.evaluate` (one evaluation: the runs a point needs and its quantities),
:mod:`.results` (the results table, appended row by row, resumable), :mod:`.execute`
(batches on a Dask cluster), :mod:`.report` (report.md and figures).
Needs the ``studies`` extra: ``pip install "pdeflow[studies]"``.
"""

from .spec import StudyError, StudySpec, load_study

__all__ = ["StudyError", "StudySpec", "load_study"]
