"""Studies: the one Study type, and parameter studies from one study file on Dask.

:mod:`.core` is the Study under every study of pdeflow (points, a measure, a pluggable
executor: this process, a process pool or Dask); the analysis studies
(:mod:`pdeflow.analysis`) and the study files of ``pdeflow study`` are definitions on it.
The study files' modules, one job each: :mod:`.spec` (the study file: parameters,
design, quantities), :mod:`.expressions` (its [derived] and [objectives] expressions),
:mod:`.designs` (the points of a grid, Latin-hypercube or Sobol design; the optimiser's
trials), :mod:`.evaluate` (one evaluation: the runs a point needs and its quantities),
:mod:`.results` (the results table, appended row by row, resumable), :mod:`.execute`
(the study file as a Study on a Dask cluster), :mod:`.report` (report.md and figures).
Study files need the ``studies`` extra: ``pip install "pdeflow[studies]"``.
"""

from .spec import StudyError, StudySpec, load_study

__all__ = ["StudyError", "StudySpec", "load_study"]
