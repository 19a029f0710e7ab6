"""Whether the ``fv-split`` stepping kernel is compiled, or cached on disk.

A query on :func:`pdeflow.numerics.splitting.advance_split` that the solver (which loads
the kernels before a run) and the progress bar (which says that they compile) both ask,
kept here, below both.
"""

from __future__ import annotations

from .splitting import advance_split


def kernels_ready() -> bool:
    """True if the ``fv-split`` stepping kernel is compiled (or loaded) in this process
    (always with NUMBA_DISABLE_JIT=1: nothing to compile)."""
    signatures = getattr(advance_split, "signatures", None)
    return True if signatures is None else bool(signatures)


def kernels_cached() -> bool:
    """True if numba's disk cache holds the stepping kernel for this machine's CPU, so
    that loading it takes a fraction of a second instead of compiling it (about 26 s
    here: see docs/user_guide.md). Reads numba's cache index; False if it cannot."""
    try:
        index = advance_split._cache._cache_file._load_index()  # {} if source changed
        magic = advance_split.targetctx.codegen().magic_tuple()
    except Exception:  # pragma: no cover - numba internals moved: assume the worst
        return False
    return any(key[1] == magic for key in index)
