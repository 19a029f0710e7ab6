r"""The paper's operator-split scheme: the CFL stepping loop of the ``fv-split`` solver.

One step of length dt (Lie splitting, as in the paper):

1. advection (29): q <- q + dt L_HLL(q), dt = CFL dx / max|S| over the faces
   (:mod:`pdeflow.numerics.advection`);
2. exchange (31), 3. implicit momentum sources (32), 4. hyperbolicity (33)-(34): the
   source stage of the model (e.g. :mod:`pdeflow.models.two_layer.sources`).

With MUSCL the advection is integrated with SSP-RK2 (Heun); with Strang splitting half
a source step is applied before and after it.

The loop is compiled once per reconstruction order, splitting, IFCP fallback, rows per
layer of the model's state and number of the grid's axes (:func:`stepping_kernel`) and
takes the model's kernels as arguments: its advection stage
(:func:`pdeflow.numerics.advection.advection_kernel`, one per model, flux, reconstruction
and limiter), source stage and MUSCL predictor, called once or twice per step through a
function pointer. :func:`scheme_stepper` puts the two together for one
scheme. Everything is cached on disk; all parameters are arrays and the grid an
argument, so that sweeps never recompile.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from numba import njit, types

from . import layout as L
from .advect_step import _copy_range, advect_step_function, speed_scale
from .advection import ADVECT_SIGNATURE, advection_kernel
from .boxes import box_grow, gather_rows, row_calls
from .compiled import (
    FIELDS,
    METRIC,
    PARAMS,
    STATE,
    VECTOR,
    WORK,
    entry,
    f8,
    first_class,
    flag,
    i8,
    ready,
    specialise,
)
from .model_kernels import ModelKernels
from .resting import reach as reach_of
from .resting import rest_changed, rest_maxima, rest_outside
from .threads import BOX_PREDICTOR, BOX_SOURCES, box_kernels, box_passes

STATUS_END = 0  #: reached t_end
STATUS_REST = 1  #: everything at rest: nothing will change any more
STATUS_FAIL = 2  #: non-finite or negative state: the step was undone
MAX_RETRIES = 30  #: halvings of dt tried on a step that left a depth negative


def stepping_function(ifcp: bool, strang: bool, advect_step: Any, reach: int,
                      width: int = 2, two_d: bool = False, compiled: bool = True) -> Any:
    """The stepping loop as a Python closure (compiled by :func:`stepping_kernel`, which
    documents it); ``advect_step`` is :func:`advect_step_function`, ``reach`` that of
    its reconstruction order (:func:`pdeflow.numerics.resting.reach`), ``width`` the
    model's rows per layer, ``two_d`` a 2D grid, ``compiled`` whether the loop is
    compiled (else it runs in Python, :func:`python_stepping`).

    The loop's windows of cells are boxes (:mod:`pdeflow.numerics.boxes`): the bounding
    box of the live cells widened by ``reach`` cells along every axis, so that on a 2D
    grid the dry (or resting) cells beside a flow in y are skipped as well as those
    ahead of it in x; on a 1D grid a box is a range of cells.
    """
    sources_box = row_calls(compiled, two_d)[0]
    # a compiled 2D loop's passes over its box run row by row on numba's threads
    copy_box, copy_box1, _, clear_outside1, live_box = box_passes(compiled and two_d)

    def advance(q, t, t_pause, t_end, dx, metric, bc_left, bc_right, P, g, r, dry, cfl, diag,
                rate, backup, diag_backup, work, max_steps, stop_at_rest, advect, sources,
                predictor, fallback):
        n = q.shape[1]
        line = int(metric[L.M_AXES, 4]) if two_d else n  # a line of the last axis
        scale = speed_scale(metric, dx) if two_d else 1.0
        steps = 0
        rec = work[:2]
        q0 = work[2]
        fex = diag[L.N_DIAG:]
        # to undo a Strang half source step that broke the CFL, or an IFCP step
        diag_keep = diag_backup[:L.N_DIAG]
        fex_keep = diag_backup[L.N_DIAG:]
        # Only the live cells (moving, or changed by the last step) widened by the reach
        # of a step are visited; no stage changes the others (pdeflow.numerics.resting).
        # A call going on from the state the last one left (diag[D_RESUME]) starts from
        # its live cells; else the first step visits all (the source stage cleans the
        # initial state).
        resume = diag[L.D_RESUME]
        first = resume != 1.0 and resume != 2.0
        v_lo = 0 if first else int(diag[L.D_LIVE_LO])
        v_hi = n - 1 if first else int(diag[L.D_LIVE_HI])
        s_lo = 0
        s_hi = n - 1
        # running maxima of the wave speed of the cells at rest outside the box visited
        speeds, valid = rest_maxima(n, line)
        gather = gather_rows(n, line, two_d)  # what rows share, for every step
        # backup holds the state a step starts from wherever the step can change it:
        # copied here for a call that starts afresh or after a call whose last step
        # left in it the state before that step (D_RESUME 2), else kept by the last
        # step's live pass (live_box), which sets it to the state it leaves on its box
        if first or resume == 2.0:
            copy_box(backup, q, 0, n - 1, line)
        while t < t_pause and steps < max_steps:
            b_lo, b_hi = (0, n - 1) if first else box_grow(v_lo, v_hi, reach, line, n)
            e_lo, e_hi = box_grow(b_lo, b_hi, 1, line, n)
            s_rest = rest_outside(speeds, valid, q, e_lo, e_hi, g, dry, width, line)
            if two_d:
                s_rest *= scale
            if strang or ifcp:
                _copy_range(diag_keep, diag, 0, L.N_DIAG - 1)
                copy_box1(fex_keep, fex, b_lo, b_hi, line)
            # One call site of the (inlined) advection stage for every attempt: numba
            # types and lowers an inlined function again at each site.
            fell_back = False
            retries = 0
            step_end = t_end
            while True:
                dt, mass_rate, ok, a_lo, a_hi, changed = advect_step(
                    fallback if fell_back else advect, sources, predictor, q, t, step_end,
                    dx, metric, bc_left, bc_right, P, g, r, dry, cfl, diag, rate, backup,
                    rec, gather, q0, diag_keep, fex_keep, first, e_lo, e_hi, b_lo, b_hi,
                    s_rest, line)
                if ok:
                    break
                if ifcp and not fell_back:
                    # IFCP is Roe's linearisation for one layer: not positive where
                    # cells move apart fast. Redo the step with HLL, which is; counted.
                    fell_back = True
                elif retries < MAX_RETRIES:
                    # safety net: a step that would leave a depth negative is rejected
                    # and redone with half the time step (the limited schemes are
                    # positive for a small enough dt); counted in diag[D_RETRIES]. (The
                    # step ends at t + dt/2 at the latest: its own end time caps dt.)
                    retries += 1
                    step_end = t + 0.5 * dt
                else:
                    break
                copy_box(q, backup, b_lo, b_hi, line)
                if strang or ifcp:
                    _copy_range(diag, diag_keep, 0, L.N_DIAG - 1)
                    copy_box1(fex, fex_keep, b_lo, b_hi, line)
            if fell_back:
                diag[L.D_FLUX_FALLBACKS] += 1.0
            diag[L.D_RETRIES] += retries
            t_new = t + dt if dt < t_end - t else t_end
            if not ok:
                copy_box(q, backup, b_lo, b_hi, line)
                return t, steps, STATUS_FAIL
            diag[L.D_DT] = 0.5 * dt if strang else dt
            if first:
                a_lo = 0
                a_hi = n - 1
            # F_extra of cells that left the active region (if nothing is wet, the stage
            # only needs to clear the last F_extra)
            clear_outside1(fex, s_lo, s_hi, a_lo, a_hi, line)
            sources_box(sources, q, 0.5 * dt if strang else dt, t_new, P, diag, gather, a_lo,
                        a_hi, line)
            changed = max(changed, diag[L.D_CHANGED])
            s_lo = a_lo
            s_hi = a_hi
            # the call's last step keeps in backup the state before it (the step
            # changed the cells of box b only), for output at t_pause (interpolated by
            # the caller); any other step's backup becomes the state it leaves
            last = t_new >= t_pause
            if b_lo <= b_hi:
                v_lo, v_hi = live_box(q, backup, gather, b_lo, b_hi, width, line, not last)
                rest_changed(valid, b_lo, b_hi, line)
            diag[L.D_LIVE_LO] = v_lo
            diag[L.D_LIVE_HI] = v_hi
            diag[L.D_RESUME] = 2.0 if last else 1.0
            first = False
            t = t_new
            steps += 1
            if stop_at_rest and mass_rate == 0.0 and changed == 0.0:
                return t, steps, STATUS_REST
        return t, steps, STATUS_END

    return advance


ADVECT = types.FunctionType(types.Tuple((f8, i8, i8))(*ADVECT_SIGNATURE))
"""type of an advection stage passed to the loop (a function pointer)"""
SOURCES = types.FunctionType(types.none(STATE, f8, f8, PARAMS, VECTOR, i8, i8))
"""type of a source stage on a range of cells (e.g. :mod:`pdeflow.models.two_layer.sources`);
on a 2D grid the loop calls it on each row of a box (:func:`.boxes._sources_in_box` says
what its bookkeeping must allow)"""
PREDICTOR = types.FunctionType(types.none(STATE, f8, PARAMS, i8, i8))
"""type of a MUSCL predictor (e.g. :mod:`pdeflow.models.two_layer.friction`)"""


@functools.cache
def stepping_kernel(order: int, strang: bool, ifcp: bool, width: int = 2,
                    two_d: bool = False) -> Any:
    """The ``fv-split`` stepping loop for one reconstruction order, splitting, flux
    fallback, ``width`` rows per layer and a 1D or (``two_d``) 2D grid, for any model
    (compiled on first use, see :func:`pdeflow.numerics.compiled.ready`): advance ``q``
    from ``t`` to ``t_end`` with the CFL-limited splitting scheme,

    ``advance(q, t, t_pause, t_end, dx, metric, bc_left, bc_right, P, g, r, dry, cfl,
    diag, rate, backup, diag_backup, work, max_steps, stop_at_rest, advect, sources,
    predictor, fallback) -> (t, steps, status)``; ``metric``: the grid's
    (:class:`~pdeflow.numerics.geometry.Metric`).

    Only ``t_end`` (the end of the run) shortens a step: the loop returns after the
    first step that reaches ``t_pause`` (<= ``t_end``; an output time), so that the
    steps do not depend on when the caller looks at the state; ``backup`` then holds
    the state before that step (dt earlier), for output at ``t_pause`` in between.

    ``rate`` and ``backup`` have the shape of ``q``, ``diag_backup`` that of ``diag``;
    ``work`` has shape (3, *q.shape); ``g`` = g_z [m/s^2], ``r`` = rho1/rho2 (0 for one
    layer) and ``dry`` [m] are the model's. The model's kernels: ``advect`` (its
    advection stage), ``sources`` (its source stage), ``predictor`` (MUSCL, ``order``
    2: the friction predictor of the SSP-RK2/Heun integrator, see
    :func:`~pdeflow.models.two_layer.friction.predictor_two_layer`; else None; on a 2D
    grid both take the box, :func:`pdeflow.numerics.threads.box_kernels`) and
    ``fallback`` (``ifcp``: the HLL advection stage that redoes a step IFCP left
    negative; else None). ``strang`` applies half a source step before and after the
    advection (else Lie, as in the paper). With Strang, dt is chosen before the first
    half source step; if that half step makes the waves faster than dt allows (erosion
    deepens the upper layer), it is undone and the step retried with a shorter dt.

    ``diag[D_RESUME]`` = 1 or 2 lets a call go on from the live cells the last call
    recorded in ``diag`` (:mod:`pdeflow.numerics.resting`); the caller must clear it
    (0) unless ``q`` is the state that call left and ``backup`` the array it left (a
    step keeps in it the state it starts from, and sets it to the state it leaves on
    its box, but the step that reached ``t_pause``: then D_RESUME is 2 and the next
    call copies the state into ``backup`` first).

    Returns ``(t, steps, status)``: status :data:`STATUS_END`; :data:`STATUS_REST`
    (everything at rest and unchanged: stationary from ``t`` on); or
    :data:`STATUS_FAIL` (the last step produced a non-finite or negative state and was
    undone; ``q`` holds the last good state).
    """
    step = njit(inline="always")(advect_step_function(order, strang, None, width, two_d))
    loop = stepping_function(ifcp, strang, step, reach_of(order), width, two_d)
    return specialise(loop, STATE, f8, f8, f8, f8,
                      METRIC, i8, i8, PARAMS, f8, f8, f8, f8, VECTOR, FIELDS, FIELDS, VECTOR,
                      WORK, i8, flag,
                      ADVECT, BOX_SOURCES if two_d else SOURCES,
                      (BOX_PREDICTOR if two_d else PREDICTOR) if order == 2 else types.none,
                      ADVECT if ifcp else types.none, pointer=False)


class Stepper:
    """The stepping loop of one scheme with its model's kernels:
    ``stepper(q, t, t_end, dx, metric, bc_left, bc_right, P, cfl, diag, rate, backup,
    work, max_steps, stop_at_rest) -> (t, steps, status)`` (see :func:`stepping_kernel`).
    Nothing is compiled before the first call (or :meth:`ready`)."""

    def __init__(self, model: ModelKernels, flux: int, order: int, limiter: int,
                 strang: bool, geometry: int):
        self.model = model
        self.ifcp = flux == L.FLUX_IFCP
        self.two_d = geometry in (L.GEOMETRY_PLANAR_2D, L.GEOMETRY_TERRAIN_2D)
        self.loop = stepping_kernel(order, strang, self.ifcp, model.layer_rows, self.two_d)
        self.advect = advection_kernel(model, flux, order, limiter, geometry)
        # on a 2D grid the stage and the predictor take a box, its rows on threads
        sources, predictor = box_kernels(model) if self.two_d else \
            (model.sources, model.predictor)
        self.sources = sources
        self.predictor = predictor if order == 2 else None
        self.fallback = advection_kernel(model, L.FLUX_HLL, order, limiter, geometry) \
            if self.ifcp else None
        self.kernels = [k for k in (self.loop, self.advect, self.sources, self.predictor,
                                    self.fallback) if k is not None]
        entry(*self.kernels)
        self.arguments: tuple[Any, ...] | None = None

    def ready(self) -> Stepper:
        """Compile (or load) every kernel of this scheme now."""
        if self.arguments is None:
            for kernel in self.kernels:
                ready(kernel)
            self.arguments = tuple(first_class(k) for k in (
                self.advect, self.sources, self.predictor, self.fallback))
        return self

    def __call__(self, q: np.ndarray, t: float, t_end: float, dx: float,
                 metric: np.ndarray, bc_left: int, bc_right: int, P: np.ndarray,
                 cfl: float, diag: np.ndarray, rate: np.ndarray, backup: np.ndarray,
                 work: np.ndarray, max_steps: int, stop_at_rest: bool,
                 t_pause: float | None = None) -> tuple[float, int, int]:
        return self.run(self.ready().loop, q, t, t_end, dx, metric, bc_left, bc_right, P,
                        cfl, diag, rate, backup, work, max_steps, stop_at_rest, t_pause)

    def run(self, loop: Any, q: np.ndarray, t: float, t_end: float, dx: float,
            metric: np.ndarray, bc_left: int, bc_right: int, P: np.ndarray, cfl: float,
            diag: np.ndarray, rate: np.ndarray, backup: np.ndarray, work: np.ndarray,
            max_steps: int, stop_at_rest: bool,
            t_pause: float | None = None) -> tuple[float, int, int]:
        """``loop`` (the compiled loop, or its Python code) with this scheme's kernels
        on the stepper's arguments; ``t_pause`` (default ``t_end``): return after the
        first step that reaches it, with the state before that step in ``backup`` (see
        :func:`stepping_kernel`)."""
        return loop(q, t, t_end if t_pause is None else min(t_pause, t_end), t_end, dx,
                    metric, bc_left, bc_right, P, *self.model.constants(P), cfl, diag,
                    rate, backup, np.empty_like(diag), work, max_steps, stop_at_rest,
                    *self.ready().arguments)


@functools.cache
def scheme_stepper(model: ModelKernels, flux: int, order: int, limiter: int,
                   strang: bool, geometry: int) -> Stepper:
    """The :class:`Stepper` of one model's scheme on one geometry (one per process)."""
    return Stepper(model, flux, order, limiter, strang, geometry)


def python_stepping(model: ModelKernels, flux: int, order: int, limiter: int,
                    strang: bool, geometry: int, update: Any) -> Any:
    """:func:`scheme_stepper` as plain Python around the compiled advection and source
    kernels, with ``update`` for :func:`update` (the blow-up diagnosis replays a step
    with an update that records what it wrote); called as the stepper."""
    compiled = scheme_stepper(model, flux, order, limiter, strang, geometry).ready()
    width = model.layer_rows
    loop = stepping_function(compiled.ifcp, strang,
                             advect_step_function(order, strang, update, width, compiled.two_d),
                             reach_of(order), width, compiled.two_d, compiled=False)
    return functools.partial(compiled.run, loop)
