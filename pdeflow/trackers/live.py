"""Live plots of a running simulation: a py-pde tracker, in a window, Jupyter or headless.

:class:`LayersPlotTracker` redraws, at its interrupts in *simulation* time, the two layers
stacked on the bed (lower layer, upper layer, interface and free surface, filled), both
velocities and F_extra/rho1, with the simulation time in the title (the figure is a
:class:`pdeflow.plotting.RunFigure`); on a 2D grid the plan view of the total depth
with the deposit outline (a :class:`pdeflow.plan_view.PlanFigure`). Where it shows the
figure:

* ``display="window"``: a desktop window (an interactive matplotlib backend such as
  TkAgg or QtAgg), updated while the run goes (``pdeflow run CASE --live``);
* ``display="jupyter"``: in a notebook, one output updated in place;
* ``display="none"``: nowhere; with ``movie=`` and/or ``frames=`` it writes a movie
  (``.mp4`` through ffmpeg, ``.gif`` through Pillow) or numbered PNG frames, which is
  what a headless machine (``MPLBACKEND=Agg``) does (``--movie out.mp4``,
  ``--frames DIR``);
* ``display="auto"`` (default): "jupyter" under the inline backend, "window" under an
  interactive backend, else "none".

Example::

    from pdeflow.trackers.live import LayersPlotTracker
    live = LayersPlotTracker(0.02, title="5.1", movie="dam_break.mp4")
    eq.solve(state, t_range=5, solver="fv-split", tracker=live)

The last frame is the final state (the rest time if the run stopped at rest). Movies
and frames are complete or absent: a movie is written under a temporary name, the
frames into a temporary directory, both renamed into place when the run ends (with
``autocommit=False`` only on :meth:`LayersPlotTracker.commit`, as ``pdeflow run`` does
once every model has run); :meth:`LayersPlotTracker.discard` removes them if the run
fails or is interrupted.
The tracker does not change the run: fv-split shows it the state interpolated at its
interrupt times without shortening a step (:mod:`pdeflow.solvers.outputs`).
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np
from pde.trackers.base import InfoDict, TrackerBase

from ..io import PendingDir, PendingFile
from ..numerics.geometry import COORDINATES, geometry_of
from ..plan_view import DEPOSIT_THRESHOLD, PlanFigure, frames_box
from ..plotting import RedrawnFigure, RunFigure, Series
from ..systems import of_fields
from .frames import fextra_over_rho1, show_final_state, state_labels

#: movie containers written with H.264 through ffmpeg (WebM cannot hold H.264)
FFMPEG_SUFFIXES = (".mp4", ".m4v", ".mov", ".mkv", ".avi")
#: matplotlib backends that cannot show a window
HEADLESS_BACKENDS = ("agg", "pdf", "ps", "svg", "pgf", "cairo", "template")


def figure_of(series: list[Series], *, title: str = "", depth_max: float | None = None,
              pyplot: bool = False, threshold: float = DEPOSIT_THRESHOLD,
              box: Any = None) -> RedrawnFigure:
    """The figure redrawn in place for ``series``: a :class:`~pdeflow.plotting.RunFigure`
    of 1D runs, a :class:`~pdeflow.plan_view.PlanFigure` (with the deposit outline at
    ``threshold`` [m] and the ranges ``box``) of runs on 2D grids."""
    if series[0].y is None:
        return RunFigure(series, title=title, depth_max=depth_max, pyplot=pyplot)
    return PlanFigure(series, title=title, depth_max=depth_max, pyplot=pyplot,
                      threshold=threshold, box=box)


class MovieError(ValueError):
    """A movie that cannot be written (unknown format, no ffmpeg); names the file."""


def display_mode(requested: str = "auto") -> str:
    """Resolve ``'auto'`` to 'jupyter', 'window' or 'none' from the matplotlib backend."""
    if requested not in ("auto", "window", "jupyter", "none"):
        raise ValueError(f"display must be 'auto', 'window', 'jupyter' or 'none', got "
                         f"{requested!r}")
    if requested != "auto":
        return requested
    backend = matplotlib.get_backend().lower()
    if "inline" in backend:
        return "jupyter"
    if backend in HEADLESS_BACKENDS or backend.endswith("backend_agg"):
        return "none"
    return "window"


def ffmpeg_path() -> str | None:
    """An ffmpeg executable: from imageio-ffmpeg if installed, else on PATH, else None."""
    try:
        import imageio_ffmpeg

        return imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError):
        return shutil.which("ffmpeg")


def check_movie_path(path: str | Path) -> str:
    """Return the writer kind ('ffmpeg' or 'pillow') for a movie file, or raise
    :class:`MovieError` (before any computation) if it cannot be written here."""
    suffix = Path(path).suffix.lower()
    if suffix == ".gif":
        return "pillow"
    if suffix in FFMPEG_SUFFIXES:
        if ffmpeg_path() is None:
            raise MovieError(f"{path}: writing {suffix} movies needs ffmpeg: "
                             "pip install 'pdeflow[movie]' (imageio-ffmpeg), or write "
                             "a .gif instead")
        return "ffmpeg"
    raise MovieError(f"{path}: unknown movie format {suffix!r}; use "
                     f"{', '.join(FFMPEG_SUFFIXES)} (H.264 through ffmpeg) or .gif")


class MovieFile:
    """Frames of a figure written to a movie through a matplotlib animation writer,
    under a temporary name until :meth:`commit` (complete or absent)."""

    def __init__(self, path: str | Path, fig: Any, *, fps: float = 10, dpi: int = 100):
        from matplotlib import animation

        self.path = Path(path)
        kind = check_movie_path(self.path)
        self._pending = PendingFile(self.path)
        if kind == "ffmpeg":
            matplotlib.rcParams["animation.ffmpeg_path"] = ffmpeg_path()
            self._writer = animation.FFMpegWriter(fps=fps, codec="h264",
                                                  extra_args=["-pix_fmt", "yuv420p"])
        else:
            self._writer = animation.PillowWriter(fps=fps)
        self._fig = fig
        self.closed = False
        self._writer.setup(fig, str(self._pending.tmp), dpi=dpi)
        self.frames = 0

    def grab(self) -> None:
        """Append the figure as it is now."""
        self._writer.grab_frame()
        self.frames += 1

    def close(self) -> None:
        """Write the end of the movie (still under its temporary name)."""
        if not self.closed:
            self._writer.finish()
            self.closed = True

    def commit(self) -> Path:
        """Rename the closed movie into place; return its path."""
        return self._pending.commit()

    def finish(self) -> Path:
        """Close the movie and rename it into place."""
        self.close()
        return self.commit()

    def discard(self) -> None:
        """Stop the writer and remove the temporary file."""
        if self._pending.done:
            return
        proc = getattr(self._writer, "_proc", None)
        if proc is not None:
            try:
                proc.kill()
                proc.wait()
            except OSError:  # pragma: no cover
                pass
        self._pending.discard()


class LayersPlotTracker(TrackerBase):
    """py-pde tracker drawing the run while it goes (see the module docstring).

    Not py-pde's ``PlotTracker``: that one draws ``state.plot()``, while this figure
    stacks the layers and needs F_extra/rho1 (not part of the state) and the final
    state of a run that stops at rest between two interrupts; it also draws every
    frame (py-pde's drops frames by wall-clock rate while showing them) and writes
    movies that are complete or absent.

    Args:
        interrupts: when to draw, in simulation time: an interval [s] (from t = 0),
            a list of times, or anything py-pde accepts.
        title: text before "t = ... s" in the figure title.
        display: 'auto', 'window', 'jupyter' or 'none'.
        movie: write the frames to this movie (.mp4 needs ffmpeg, .gif does not).
        frames: write the frames as ``frame_00000.png``, ... into this directory.
        fps: frames per second of the movie.
        dpi: resolution of movie frames and PNG frames.
        depth_max: upper depth limit of the plot [m] (default: from the initial state).
        threshold: on a 2D grid the deposit outline's total depth [m] (``pdeflow run``
            passes the case's ``output.front_threshold``, whose default this is).
        pause: seconds the window's event loop runs per frame (window display only).
        model: the registered name of the run's model (default: the first model whose
            state has the run's field labels, see :func:`pdeflow.systems.of_fields`).
        autocommit: rename the movie and the frames' directory into place when the run
            ends; with False, call :meth:`commit` or :meth:`discard`.
    """

    def __init__(self, interrupts: Any = 0.05, *, title: str = "",
                 display: str = "auto", movie: str | Path | None = None,
                 frames: str | Path | None = None, fps: float = 10, dpi: int = 100,
                 depth_max: float | None = None, pause: float = 1e-3,
                 model: str | None = None, autocommit: bool = True,
                 threshold: float = DEPOSIT_THRESHOLD):
        super().__init__(interrupts=interrupts)
        self.autocommit = autocommit
        self.model = model
        self.title = title
        self.display = display_mode(display)
        self.movie_path = None if movie is None else Path(movie)
        if self.movie_path is not None:
            check_movie_path(self.movie_path)
        self.frames_dir = None if frames is None else Path(frames)
        self.fps = float(fps)
        self.dpi = int(dpi)
        self.depth_max = depth_max
        self.threshold = float(threshold)
        self.pause = float(pause)
        self.figure: RedrawnFigure | None = None
        self.times: list[float] = []
        self.frame_paths: list[Path] = []
        self.movie: MovieFile | None = None
        self._frames: PendingDir | None = None  # the frames until committed
        self._info: InfoDict | None = None
        self._field: Any = None
        self._handle: Any = None
        self.last_time = -math.inf

    # --- py-pde tracker interface ---------------------------------------------------------
    def initialize(self, field: Any, info: InfoDict | None = None) -> float:
        self._info = info
        self._field = field
        model = self.model or of_fields(state_labels(field)).name
        grid = field.grid
        y = np.asarray(grid.axes_coords[1]) if grid.num_axes == 2 else None
        series = [Series(np.asarray(grid.axes_coords[0]), model,
                         coordinate=COORDINATES[geometry_of(grid, two_d=True)], y=y)]
        self.figure = figure_of(series, title=self.title, depth_max=self.depth_max,
                                pyplot=self.display == "window",
                                threshold=self.threshold)
        if self.frames_dir is not None:
            self._frames = PendingDir(self.frames_dir)
        if self.movie_path is not None:
            self.movie = MovieFile(self.movie_path, self.figure.fig, fps=self.fps,
                                   dpi=self.dpi)
        if self.display == "window":
            import matplotlib.pyplot as plt

            plt.show(block=False)
        return super().initialize(field, info)

    def handle(self, field: Any, t: float) -> None:
        self._field = field
        self.draw(field.data, float(t), fextra_over_rho1(self._info, field.grid.shape))

    def finalize(self, info: InfoDict | None = None) -> None:
        super().finalize(info)
        if self.figure is None:
            return
        show_final_state(self, info)
        if self.movie is not None:
            self.movie.close()
        if self.display != "window":
            self.figure.close()
        if self.autocommit:
            self.commit()

    def commit(self) -> list[Path]:
        """Rename the movie and the frames' directory (each if asked for) into place; a
        previous run's frames there are replaced as a whole. Returns what was
        written: the movie and the frames' directory."""
        written = []
        if self.movie is not None:
            self.movie.close()
            written.append(self.movie.commit())
        if self._frames is not None:
            written.append(self._frames.commit())
        return written

    # --- drawing --------------------------------------------------------------------------
    def draw(self, data: np.ndarray, t: float, fextra: np.ndarray | None = None) -> None:
        """Redraw the figure with ``data`` at time t [s] and emit the frame."""
        assert self.figure is not None, "initialize() first"
        self.figure.update(t, [data], [fextra])
        self.times.append(t)
        self.last_time = t
        fig = self.figure.fig
        if self.display == "window":
            import matplotlib.pyplot as plt

            if plt.fignum_exists(fig.number):
                fig.canvas.draw_idle()
                fig.canvas.start_event_loop(self.pause)
            # else: the user closed the window; the run goes on (movie/frames still)
        elif self.display == "jupyter":
            from IPython.display import Image, display

            image = Image(data=self.figure.png(self.dpi), format="png")
            if self._handle is None:
                self._handle = display(image, display_id=True)
            else:
                self._handle.update(image)
        if self.movie is not None:
            self.movie.grab()
        if self._frames is not None:
            name = f"frame_{len(self.frame_paths):05d}.png"
            self.figure.save(self._frames.tmp / name, dpi=self.dpi)
            self.frame_paths.append(self._frames.path / name)  # where it will be

    def discard(self) -> None:
        """Abandon the movie and frames of a failed or interrupted run (nothing of them
        is left behind; an older movie or frames' directory stays as it was)."""
        if self.movie is not None:
            self.movie.discard()
        if self._frames is not None and not self._frames.done:
            self._frames.discard()
        if self.figure is not None and self.display != "window":
            self.figure.close()


def replay(frames: list[tuple[float, list[np.ndarray | None], list[np.ndarray | None]]],
           series: list[Series], path: str | Path, *, title: str = "", fps: float = 10,
           dpi: int = 100, progress: bool = False,
           threshold: float = DEPOSIT_THRESHOLD) -> Path:
    """Write a movie of given frames (t, states, fextras) of one or more runs; with
    ``progress`` a bar on stderr counts the frames (tqdm, as py-pde's progress bar:
    drawing takes tens of milliseconds per frame). Runs on 2D grids are drawn in plan
    view (:func:`figure_of`), zoomed to the material of all frames, with the deposit
    outline at ``threshold`` [m]."""
    from tqdm.auto import tqdm

    box = None if series[0].y is None else frames_box(series, [f[1] for f in frames])
    fig = figure_of(series, title=title, threshold=threshold, box=box)
    movie = MovieFile(path, fig.fig, fps=fps, dpi=dpi)
    bar = tqdm(total=len(frames), desc=f"drawing {Path(path).name}", unit="frame",
               disable=not progress, leave=True)
    try:
        for t, states, fextras in frames:
            fig.update(t, states, fextras)
            movie.grab()
            bar.update(1)
        out = movie.finish()
    except BaseException:
        movie.discard()
        raise
    finally:
        bar.close()
        fig.close()
    return out


__all__ = ["LayersPlotTracker", "MovieError", "MovieFile", "check_movie_path",
           "display_mode", "ffmpeg_path", "figure_of", "replay"]
