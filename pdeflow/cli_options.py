"""Checks of command-line options that several commands share (:mod:`pdeflow.cli`,
:mod:`pdeflow.cli_stored`): below both, so that neither imports the other's."""

from __future__ import annotations

from .case_schema import CaseError


def positive(name: str, value: float | None) -> None:
    """CaseError (one line naming the option ``name``) unless ``value`` is None or > 0."""
    if value is not None and not value > 0:
        raise CaseError(f"{name} must be > 0, got {value!r}")


def threads_option(text: str) -> int:
    """argparse type of ``--threads``: the number of threads of a 2D run, refused in one
    line (argparse's error naming the option) unless an integer in 1..the cores."""
    import argparse

    from .numerics.threads import check_threads

    try:
        value: object = int(text)
    except ValueError:
        value = text
    try:
        return check_threads(value)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None
