"""The scheme: the one object that says how the fv-split solver discretises a model.

A :class:`Scheme` is the interface flux, the reconstruction and its limiter, and the
splitting of the sources: the choices the stepping loop is built for, checked with
one-line errors and turned into the kernels' codes (:mod:`pdeflow.numerics.layout`)
here only. The PDE assembles a model and a scheme (``GranularPDE(scheme=...)``), the
solver reads it from there, and :class:`pdeflow.variant.Variant` (a scheme with a
hyperbolicity treatment and an integrator) is built around it. The grid's geometry is
not part of it: it comes from the grid (:func:`pdeflow.numerics.geometry.metric_of`).
"""

from __future__ import annotations

import re
from collections.abc import Collection, KeysView
from dataclasses import dataclass

from . import layout as L

FLUXES: KeysView[str] = L.FLUXES.keys()
"""interface fluxes: 'hll' (the paper's), 'rusanov', 'ifcp', then any registered by
:func:`register_flux` (a live view of ``layout.FLUXES``, the one table of their names)"""
_SHIPPED_FLUXES = frozenset(L.FLUXES)
RECONSTRUCTIONS: tuple[str, ...] = tuple(L.RECONSTRUCTIONS)
"""'first-order' (the paper's) or 'muscl' (second order in space)"""
LIMITERS: tuple[str, ...] = tuple(L.LIMITERS)
"""slope limiters of 'muscl': 'minmod', 'mc' (monotonised central)"""
SPLITTINGS: tuple[str, ...] = ("lie", "strang")
"""'lie' (advection, then sources: the paper's) or 'strang' (half a source step on each
side of the advection step)"""
MAX_CFL = {"first-order": 1.0, "muscl": 0.5}
"""The largest Courant number of each reconstruction: the first-order update is positive
up to 1; MUSCL's SSP-RK2 update with limited slopes keeps depths non-negative only up to
1/2 (docs/stability.md)."""


MAX_CFL_BED = 0.5
"""The largest Courant number over a bed z_b(x, y): the face depths of the reconstruction
over it reach 2h (:mod:`pdeflow.models.single_layer.terrain`), as MUSCL's face values
make its limit 1/2."""


class SchemeError(ValueError):
    """A scheme choice that is not one of the allowed ones."""


def register_flux(name: str) -> int:
    """Add the interface flux ``name`` (lower-case letters, as variant names spell
    fluxes) and return its code, the next free one: what a model's
    ``fluctuations(code)`` answers (docs/architecture.md, "Adding a flux")."""
    if not re.fullmatch(r"[a-z]+", str(name)):
        raise SchemeError(f"flux name must be lower-case letters a-z, got {name!r}")
    if name in L.FLUXES:
        raise SchemeError(f"a flux named {name!r} is registered already")
    L.FLUXES[name] = max(L.FLUXES.values()) + 1
    return L.FLUXES[name]


def unregister_flux(name: str) -> None:
    """Remove the flux ``name`` added by :func:`register_flux` (a test's); the shipped
    fluxes stay."""
    if name not in _SHIPPED_FLUXES:
        L.FLUXES.pop(name, None)


def check_choice(what: str, value: object, allowed: Collection[str],
                 where: str = "") -> None:
    """Raise :class:`SchemeError` ``"{where}{what} must be one of [...], got ..."``
    unless ``value`` is one of ``allowed``."""
    if value not in allowed:
        raise SchemeError(f"{where}{what} must be one of {list(allowed)}, got {value!r}")


@dataclass(frozen=True)
class Scheme:
    """How fv-split discretises a model (defaults: the paper's scheme).

    ``Scheme.parse("hll/muscl/mc+strang")`` reads the names the docs use.
    """

    flux: str = "hll"
    """interface flux: one of :data:`FLUXES`"""
    reconstruction: str = "first-order"
    """one of :data:`RECONSTRUCTIONS`; 'muscl' is advanced with SSP-RK2 (Heun)"""
    limiter: str = "minmod"
    """slope limiter of 'muscl': one of :data:`LIMITERS` (unused at first order)"""
    splitting: str = "lie"
    """splitting of the sources: one of :data:`SPLITTINGS`"""

    def __post_init__(self) -> None:
        check_choice("flux", self.flux, FLUXES)
        check_choice("reconstruction", self.reconstruction, RECONSTRUCTIONS)
        check_choice("limiter", self.limiter, LIMITERS)
        check_choice("splitting", self.splitting, SPLITTINGS)

    @classmethod
    def parse(cls, name: str) -> Scheme:
        """The scheme of ``FLUX/RECONSTRUCTION[/LIMITER][+SPLITTING]``."""
        text, _, splitting = str(name).strip().partition("+")
        parts = text.split("/")
        if len(parts) not in (2, 3) or (len(parts) == 3 and parts[1] != "muscl"):
            raise SchemeError(f"scheme must be FLUX/RECONSTRUCTION[/LIMITER][+SPLITTING] "
                              f"(a limiter with muscl only), got {name!r}")
        return cls(*parts[:2], *(parts[2:] or ["minmod"]), splitting or "lie")

    @property
    def spatial(self) -> str:
        """The spatial discretisation's name, e.g. 'hll/first-order', 'ifcp/muscl/mc'."""
        name = f"{self.flux}/{self.reconstruction}"
        return name + (f"/{self.limiter}" if self.reconstruction == "muscl" else "")

    @property
    def name(self) -> str:
        """Canonical name (Lie splitting left out); ``Scheme.parse(s.name) == s`` up to
        the limiter of a first-order scheme, which is unused."""
        return self.spatial + ("" if self.splitting == "lie" else f"+{self.splitting}")

    def __str__(self) -> str:
        return self.name

    @property
    def codes(self) -> tuple[int, int, int]:
        """(flux, order, limiter): the kernels' codes (layout.FLUX_*, the order of the
        reconstruction, layout.LIMITER_*)."""
        return (L.FLUXES[self.flux], L.RECONSTRUCTIONS[self.reconstruction],
                L.LIMITERS[self.limiter])

    @property
    def strang(self) -> bool:
        """True with Strang splitting."""
        return self.splitting == "strang"

    @property
    def max_cfl(self) -> float:
        """The largest Courant number of the reconstruction (:data:`MAX_CFL`)."""
        return MAX_CFL[self.reconstruction]
