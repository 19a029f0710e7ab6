"""The 2D stepping loop's passes over a box on numba's threads, and how many threads.

On a 2D grid the ``fv-split`` loop's heavy passes run row by row of its box
(:mod:`pdeflow.numerics.boxes`), and the rows are independent: the advection stage's
sweeps (each line of an axis writes only its own cells,
:func:`pdeflow.numerics.advection.advection_kernel`), the source stage (per cell), the
MUSCL predictor (per cell) and the update (per cell). These kernels run the rows in
numba ``prange`` loops (compiled with ``parallel=True``). Every cell's result is the
same arithmetic in the same order whatever the thread count, so a run gives the same
numbers, bit for bit, with any number of threads; what the rows share is combined
after them in row order: the largest wave speed and mass rate (maxima, exact in any
order) and what the source stage books (each row books into a vector of its own,
folded into the diagnostics in row order by the model's ``fold``, so that its sums do
not depend on the threads; they are sums over rows of sums over cells, not one sum in
cell order as the serial loop had, a round-off apart).

How many threads: :func:`check_threads` and :func:`using_threads` (the ``fv-split``
solver's ``threads``, default :data:`DEFAULT_THREADS`). A 1D grid has no parallel
kernel and never starts numba's threads.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numba
import numpy as np
from numba import njit, prange, types

from . import layout as L
from .boxes import (
    box_join,
    clear_outside,
    clear_outside1,
    copy_box,
    copy_box1,
    rows_of,
)
from .compiled import FIELDS, PARAMS, STATE, VECTOR, f8, i8, specialise
from .model_kernels import ModelKernels
from .resting import live_box

# numba's default threading layer here is GNU OpenMP, whose threads spin between the
# loop's passes (a dozen a step): on cores shared with other processes the thread
# that spins takes the time slice the other thread needs, and two threads ran 3x
# slower than one (load 5 on 2 cores). Passive waiting sleeps instead; read when numba
# starts its threads (a 2D run's first step), and left alone if the user set it.
os.environ.setdefault("OMP_WAIT_POLICY", "passive")

DEFAULT_THREADS = 1
"""Threads of a 2D run unless it asks for more: one, so that commands that run several
runs at once in processes (sweeps, studies, a test suite on every core) do not put two
threads on each core (``numba``'s own default would be one per core)."""

BOX_SOURCES = types.FunctionType(types.none(STATE, f8, f8, PARAMS, VECTOR, FIELDS, i8, i8,
                                            i8))
"""type of a 2D source stage on a box ``(q, dt, t, P, diag, gather, lo, hi, line)``
(:func:`box_kernels`)"""
BOX_PREDICTOR = types.FunctionType(types.none(STATE, f8, PARAMS, i8, i8, i8))
"""type of a 2D MUSCL predictor on a box ``(q, dt, P, lo, hi, line)``"""


def available_threads() -> int:
    """The most threads a run may use: numba's (``NUMBA_NUM_THREADS``, by default the
    cores of the machine)."""
    return int(numba.config.NUMBA_NUM_THREADS)


def check_threads(threads: Any) -> int:
    """``threads`` as an int, or ValueError (one line) unless it is an integer in
    1..:func:`available_threads`."""
    allowed = available_threads()
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) \
            or not 1 <= threads <= allowed:
        raise ValueError(f"threads must be an integer in [1, {allowed}] (numba's threads "
                         f"on this machine), got {threads!r}")
    return int(threads)


@contextmanager
def using_threads(threads: int) -> Iterator[None]:
    """numba's parallel kernels called in this block (from this thread) use
    ``threads`` threads; the previous number is restored after. (Starts numba's
    threading layer: only 2D runs call it.)"""
    previous = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        yield
    finally:
        numba.set_num_threads(previous)


def on_threads(func: Callable[..., Any], threads: int) -> Callable[..., Any]:
    """``func`` called :func:`using_threads` ``threads``."""

    def threaded(*args: Any) -> Any:
        with using_threads(threads):
            return func(*args)

    return threaded


@functools.cache
def box_kernels(model: ModelKernels) -> tuple[Any, Any]:
    """The 2D source stage and MUSCL predictor of ``model`` on a box, its rows on
    numba's threads: ``sources(q, dt, t, P, diag, gather, lo, hi, line)``
    (:data:`BOX_SOURCES`)
    and ``predictor(q, dt, P, lo, hi, line)`` (:data:`BOX_PREDICTOR`).

    The model's 2D stage books a row into a vector of its own, ``sources(q, dt, t, P,
    book, fex, lo, hi)`` (``fex``: the per-cell diagnostic, ``diag[N_DIAG:]``; the
    books: rows of ``gather``, :func:`.boxes.gather_rows`), and ``model.fold(diag,
    book)`` adds a row's booking to ``diag`` (its own slots; called in row order on
    books that started at zero). Of the scheme's slots D_CHANGED is the 'or' over the
    rows, D_T the stage's time and D_STEPS counts one stage."""
    sources = model.sources
    fold = model.fold
    predictor = model.predictor

    def sources_on_rows(q, dt, t, P, diag, gather, lo, hi, line):
        fex = diag[L.N_DIAG:]
        x0, x1, y0, y1 = rows_of(lo, hi, line)
        if x0 > x1:  # nothing to visit: the stage books that it saw nothing
            sources(q, dt, t, P, diag, fex, 1, 0)
            return
        books = gather
        for k in prange(x1 - x0 + 1):
            x = x0 + k
            books[k, :] = 0.0
            sources(q, dt, t, P, books[k], fex, x * line + y0, x * line + y1)
        steps = diag[L.D_STEPS]
        changed = 0.0
        for k in range(x1 - x0 + 1):  # in row order: the same sums for any threads
            fold(diag, books[k])
            changed = max(changed, books[k, L.D_CHANGED])
        diag[L.D_CHANGED] = changed
        diag[L.D_T] = t
        diag[L.D_STEPS] = steps + 1.0

    def predictor_on_rows(q, dt, P, lo, hi, line):
        x0, x1, y0, y1 = rows_of(lo, hi, line)
        for x in prange(x0, x1 + 1):
            predictor(q, dt, P, x * line + y0, x * line + y1)

    return (specialise(sources_on_rows, STATE, f8, f8, PARAMS, VECTOR, FIELDS, i8, i8, i8,
                       parallel=True),
            specialise(predictor_on_rows, STATE, f8, PARAMS, i8, i8, i8, parallel=True))


@functools.cache
def update_on_rows(update: Any) -> Any:
    """The state update ``update`` (:func:`pdeflow.numerics.advect_step.update_function`,
    compiled) on the rows of a box on numba's threads: ``update_rows(q, base, rate, dt,
    weight, gather, lo, hi, line) -> (mass_rate, ok)``, the largest mass rate and
    whether every row was ok (each row's in ``gather``, :func:`.boxes.gather_rows`;
    combined after the rows: exact whatever the threads)."""

    def update_rows(q, base, rate, dt, weight, gather, lo, hi, line):
        x0, x1, y0, y1 = rows_of(lo, hi, line)
        rows = max(x1 - x0 + 1, 0)
        for k in prange(rows):
            x = x0 + k
            mass, good = update(q, base, rate, dt, weight, x * line + y0, x * line + y1)
            gather[k, 0] = mass
            gather[k, 1] = 1.0 if good else 0.0
        mass_rate = 0.0
        ok = True
        for k in range(rows):
            mass_rate = max(mass_rate, gather[k, 0])
            ok = ok and gather[k, 1] == 1.0
        return mass_rate, ok

    return specialise(update_rows, STATE, STATE, FIELDS, f8, f8, FIELDS, i8, i8, i8,
                      helper=True, parallel=True)


def _copy_rows(dst, src, lo, hi, line):
    """:func:`.boxes.copy_box` row by row on threads."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    for x in prange(x0, x1 + 1):
        copy_box(dst, src, x * line + y0, x * line + y1, line)


def _copy_rows1(dst, src, lo, hi, line):
    """:func:`.boxes.copy_box1` row by row on threads."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    for x in prange(x0, x1 + 1):
        copy_box1(dst, src, x * line + y0, x * line + y1, line)


def _clear_rows(a, lo, hi, lo2, hi2, line):
    """:func:`.boxes.clear_outside` row by row on threads."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    for x in prange(x0, x1 + 1):
        clear_outside(a, x * line + y0, x * line + y1, lo2, hi2, line)


def _clear_rows1(a, lo, hi, lo2, hi2, line):
    """:func:`.boxes.clear_outside1` row by row on threads."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    for x in prange(x0, x1 + 1):
        clear_outside1(a, x * line + y0, x * line + y1, lo2, hi2, line)


def _live_rows(q, before, gather, lo, hi, width, line, sync):
    """:func:`.resting.live_box` row by row on threads, each row's box in ``gather``
    (:func:`.boxes.gather_rows`; cell indices, exact as floats), the rows' boxes joined
    in row order after them (minima and maxima: the same box whatever the threads)."""
    x0, x1, y0, y1 = rows_of(lo, hi, line)
    rows = max(x1 - x0 + 1, 0)
    for k in prange(rows):
        x = x0 + k
        r_lo, r_hi = live_box(q, before, x * line + y0, x * line + y1, width, line, sync)
        gather[k, 0] = r_lo
        gather[k, 1] = r_hi
    a_lo, a_hi = 1, 0
    for k in range(rows):
        a_lo, a_hi = box_join(a_lo, a_hi, int(gather[k, 0]), int(gather[k, 1]), line)
    return a_lo, a_hi


def _live_range(q, before, gather, lo, hi, width, line, sync):
    """:func:`.resting.live_box` with the arguments of :func:`_live_rows` (a 1D grid's
    loop, or a loop run in Python: ``gather`` is not used)."""
    return live_box(q, before, lo, hi, width, line, sync)


VECTOR_A = types.Array(f8, 1, "A")


@functools.cache
def box_passes(threaded: bool) -> tuple[Any, Any, Any, Any, Any]:
    """The stepping loop's own passes over a box: ``(copy, copy1, clear, clear1,
    live)``, :func:`.boxes.copy_box`, :func:`.boxes.copy_box1`,
    :func:`.boxes.clear_outside`, :func:`.boxes.clear_outside1` and
    :func:`.resting.live_box` (``live(q, before, gather, lo, hi, width, line, sync)``, see
    :func:`.boxes.gather_rows`); ``threaded`` (a compiled 2D loop): their rows on numba's
    threads."""
    if not threaded:
        return copy_box, copy_box1, clear_outside, clear_outside1, \
            njit(inline="always")(_live_range)
    return (specialise(_copy_rows, STATE, STATE, i8, i8, i8, helper=True, parallel=True),
            specialise(_copy_rows1, VECTOR_A, VECTOR_A, i8, i8, i8, helper=True,
                       parallel=True),
            specialise(_clear_rows, FIELDS, i8, i8, i8, i8, i8, helper=True,
                       parallel=True),
            specialise(_clear_rows1, VECTOR_A, i8, i8, i8, i8, i8, helper=True,
                       parallel=True),
            specialise(_live_rows, STATE, FIELDS, FIELDS, i8, i8, i8, i8, types.boolean,
                       helper=True, parallel=True))
