"""Kernels that are another kernel's Python code with some of its callees replaced.

A model's source stage with a rate-dependent basal law is its Coulomb stage with the
friction helpers swapped (e.g. :mod:`pdeflow.models.two_layer.laws`): the same code,
compiled as a kernel of its own, so that the Coulomb runs' kernels do not change.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from typing import Any


def with_callees(module: str, dispatcher: Any, name: str, **callees: Any) -> Callable:
    """The Python function of the kernel ``dispatcher`` with the global names
    ``callees`` bound to other kernels, named ``name`` in ``module`` (where the caller
    binds it to that name, so that it can be imported by name; with
    ``NUMBA_DISABLE_JIT=1`` the kernels are Python functions)."""
    f = getattr(dispatcher, "py_func", dispatcher)
    scope = {**f.__globals__, **callees}
    new = types.FunctionType(f.__code__, scope, name, f.__defaults__, f.__closure__)
    new.__qualname__ = name
    new.__module__ = module
    new.__doc__ = f"{f.__name__} with a rate-dependent basal law (see {module})."
    return new
