"""Parameter vector and diagnostics slots of the shallow-water model."""

from pdeflow.numerics.layout import G_X, G_Z, MODEL_SLOTS, N_HEADER

__all__ = ["G_Z", "G_X"]

DRY = N_HEADER  #: dry tolerance [m]
SIZE = N_HEADER + 1

D_MOVE = MODEL_SLOTS[0]  #: last time any cell moved [s]
DIAGNOSTICS = {"last_move": D_MOVE}
"""name -> slot of the fv-split diagnostics (what the summary reads)"""
