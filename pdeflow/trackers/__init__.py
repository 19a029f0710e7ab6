"""py-pde trackers for granular runs: frames with F_extra, stopping at rest, progress.

Like py-pde's own trackers, they act only at their interrupts and cost nothing in
between (the compiled stepping loop runs uninterrupted from one to the next).

* :mod:`.frames` - :class:`FextraStorageTracker` (py-pde's ``StorageTracker`` with
  F_extra/rho1 in every frame) and the helpers the other trackers share;
* :mod:`.rest` - :class:`RestTracker`, practical rest for py-pde's generic solvers;
* :mod:`.progress` - :class:`ProgressBar`;
* :mod:`.live` - :class:`~pdeflow.trackers.live.LayersPlotTracker`, the live plot and
  movies (imported on its own: it needs matplotlib).

Trackers sit below the models and solvers, as in py-pde (a PDE's ``solve`` creates
them): they import nothing of pdeflow above :mod:`pdeflow.numerics`, :mod:`pdeflow.io`
and :mod:`pdeflow.plotting`.
"""

from .frames import FextraStorageTracker, fextra_over_rho1
from .progress import ProgressBar
from .rest import RestTracker

__all__ = ["FextraStorageTracker", "ProgressBar", "RestTracker", "fextra_over_rho1"]
