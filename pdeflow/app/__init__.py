"""Teaching app in the browser: ``pdeflow app`` (Panel on Bokeh's server), or in Jupyter.

Three pages over pdeflow's public API (they run cases with
:func:`pdeflow.simulate.run_model` and :func:`pdeflow.analysis.sweep.run_sweep`, and analyse states
with :mod:`pdeflow.models.two_layer.hyperbolicity`):

1. dam break (:mod:`.dam_break`): sliders for a case's parameters, both models animated,
   the summary table of ``pdeflow run``;
2. run-out law (:mod:`.runout`): r(a) of both models, the fit of the set, the paper's
   fits and the published laws;
3. hyperbolicity (:mod:`.hyperbolicity`): the eigenvalues of a local state, the band
   where they are complex, and where F_extra acts in the current run.

Each page fits screens from a 1024x768 projector to wide ones, and has a presentation
mode (larger fonts and lines, fewer controls: :mod:`.look`); the dam-break page shows
the command line's warnings about its numbers (:func:`pdeflow.checks.run_warnings`).

In Jupyter (after ``pip install ".[app]"``)::

    from pdeflow.app import create_app
    create_app()                     # the same app as `pdeflow app`, in the notebook
    create_app(present=True)         # in presentation mode

Needs panel (``pip install ".[app]"``); nothing here imports it until it is used.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any


def create_app(case_dir: str | Path | None = None, page: str | None = None,
               present: bool = False) -> Any:
    """The app as a Panel object (see :func:`pdeflow.app.layout.create_app`)."""
    from .layout import create_app as _create_app

    return _create_app(case_dir, page, present)


__all__ = ["create_app"]
