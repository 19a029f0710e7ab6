"""Analysis: exact solutions, and the studies defined on :class:`~pdeflow.study.core.Study`
(convergence, work-precision, validation, stability)."""

from .exact import mangeney, ritter, stoker

__all__ = ["mangeney", "ritter", "stoker"]
