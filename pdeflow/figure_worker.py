"""Drawing the figures of ``pdeflow run`` in a process forked before they are needed.

Importing matplotlib takes longer than loading a case's kernels from the disk cache and
running it: a :class:`FigureWorker` forked before the kernels are loaded imports it
meanwhile, then draws the figure jobs (:mod:`pdeflow.case_figures`) it is sent, on two
cores where there are (:func:`pdeflow.case_figures.draw_all`), while this process
waits; this process never imports matplotlib. When kernels must be compiled, the
worker is forked while this process waits for the compile helper (the import then
fills that wait, :func:`pdeflow.numerics.warmup.prepare`). :class:`RunFigures` is what
``pdeflow run`` uses. The figures are drawn from the results the run sends, after
it: they cannot change a run's numbers.

Signals: until its jobs come, the worker ends on SIGINT or SIGTERM (as this process
does, :func:`pdeflow.interrupts.signals_interrupt`); while it draws it holds them back
(:func:`pdeflow.interrupts.deferred_signals`), like this process while it writes the
results: the figures are written completely, or not at all.
"""

from __future__ import annotations

import gc
import sys
import traceback
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .numerics.compile_parallel import can_fork, fork_context


class FigureError(RuntimeError):
    """Drawing the figures failed in the worker (the message has its traceback)."""


class RunFigures:
    """How one ``pdeflow run`` draws its figures: :meth:`start` forks the
    :class:`FigureWorker` (where it cannot fork, or with ``here``, it imports matplotlib
    in this process instead), :meth:`draw` draws the jobs there (or here), :meth:`close`
    ends the worker.

    Args:
        here: draw in this process (a live plot, a movie or frames draw here, with
            pyplot: a fork would share their window).
    """

    def __init__(self, here: bool = False):
        self.here = here
        self.worker: FigureWorker | None = None
        self.started = False

    def start(self) -> None:
        """Fork the worker (or import matplotlib here); once."""
        if self.started:
            return
        self.started = True
        if not self.here:
            self.worker = FigureWorker.start()
        if self.worker is None:
            import_matplotlib()

    def draw(self, jobs: Sequence[Any]) -> list[Path]:
        """Draw and save the figures of ``jobs`` (:mod:`pdeflow.case_figures`); their
        paths."""
        self.start()
        if self.worker is not None:
            return self.worker.draw(jobs)
        from .case_figures import draw_all

        return draw_all(jobs)

    def close(self) -> None:
        """End the worker, if there is one."""
        if self.worker is not None:
            self.worker.close()


class FigureWorker:
    """A forked process that imports matplotlib at once and draws the jobs that
    :meth:`draw` sends it. Start it with :meth:`start`; :meth:`close` ends it (also
    when no jobs were sent)."""

    def __init__(self, process: Any, conn: Any):
        self.process = process
        self.conn = conn

    @classmethod
    def start(cls) -> FigureWorker | None:
        """The started worker, or None where this process cannot fork safely
        (:func:`~pdeflow.numerics.compile_parallel.can_fork`)."""
        if not can_fork():
            return None
        ctx = fork_context()
        mine, theirs = ctx.Pipe()
        # not a daemon: it forks a helper of its own to draw on two cores
        process = ctx.Process(target=_serve, args=(theirs,), name="pdeflow-figures")
        process.start()
        theirs.close()
        return cls(process, mine)

    def draw(self, jobs: Sequence[Any]) -> list[Path]:
        """Draw and save the figures of ``jobs`` in the worker; their paths (as
        :func:`~pdeflow.case_figures.draw_all` returns them). Raises
        :class:`FigureError` if the worker failed or ended."""
        try:
            self.conn.send(list(jobs))
            status, value = self.conn.recv()
        except (EOFError, OSError):
            status, value = "gone", None
        finally:
            self.close()
        if status == "gone":
            raise FigureError(f"the figure worker ended before the figures were drawn "
                              f"(exit code {self.process.exitcode})")
        if status != "ok":
            raise FigureError(f"drawing the figures failed:\n{value}")
        return value

    def close(self) -> None:
        """End the worker: tell it there is nothing to draw (if it still waits), wait
        for it to leave, stop it if it does not."""
        if self.process.is_alive():
            try:
                self.conn.send(None)
            except OSError:
                pass  # it has left already
        self.conn.close()
        self.process.join(timeout=5)
        if self.process.is_alive():
            self.process.terminate()
            self.process.join()


def _serve(conn: Any) -> None:
    """The worker: import matplotlib, draw the jobs that come (None: nothing) and send
    back ("ok", paths) or ("error", traceback)."""
    from .interrupts import deferred_signals

    # what this process inherited (numba, py-pde, the runs) lives on: collections that
    # walk it would cost more than matplotlib's import
    gc.freeze()
    failed = None
    try:
        try:
            import_matplotlib(lean=True)
        except Exception:
            failed = traceback.format_exc()  # told when the jobs come
        jobs = conn.recv()
    except (KeyboardInterrupt, EOFError):
        return  # the run was stopped, or this process is gone
    if jobs is None:
        return
    with deferred_signals():
        reply: tuple[str, Any] = ("error", failed)
        if failed is None:
            try:
                from .case_figures import draw_all

                reply = ("ok", draw_all(jobs))
            except Exception:
                reply = ("error", traceback.format_exc())
        conn.send(reply)


def import_matplotlib(lean: bool = False) -> None:
    """Import what the figures need: matplotlib's figure and Agg modules, its font list
    and mathtext (the labels' subscripts), and the figure modules.

    ``lean`` (the worker, a process that only draws files) leaves out what only
    interactive use needs, the larger part of the import: the 3D axes
    (mpl_toolkits.mplot3d, which matplotlib registers on import; no figure of pdeflow's
    is 3D, the projection "3d" is then missing) and the property lists that
    matplotlib writes into the docstrings of every artist's ``set`` (``kwdoc``)."""
    blocked = lean and "mpl_toolkits.mplot3d" not in sys.modules
    if blocked:
        sys.modules["mpl_toolkits.mplot3d"] = None  # type: ignore[assignment]
    try:
        with warnings.catch_warnings():
            # matplotlib warns that it could not register the 3D axes
            warnings.simplefilter("ignore")
            import matplotlib.artist

            if lean and "matplotlib.figure" not in sys.modules:
                matplotlib.artist.kwdoc = lambda artist: ""
            import matplotlib.backends.backend_agg  # noqa: F401
            import matplotlib.figure  # noqa: F401
            import matplotlib.font_manager  # noqa: F401
            import matplotlib.mathtext  # noqa: F401
    finally:
        if blocked:
            del sys.modules["mpl_toolkits.mplot3d"]

    from . import bed_figures, case_figures, figures_2d  # noqa: F401
