"""Analysis: exact solutions and scalar measures of states."""

from .exact import mangeney, ritter, stoker
from .metrics import front_position, mass, momentum, total_depth

__all__ = ["front_position", "mangeney", "mass", "momentum", "ritter", "stoker", "total_depth"]
