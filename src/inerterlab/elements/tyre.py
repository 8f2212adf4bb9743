"""Point-contact tyre: spring and damper in parallel that cannot pull (lift-off).

The element's force (tension, the convention of every element: it pulls its ends
together) is F = k_t x + c_t v, x = x_wheel - x_road the tyre's extension from static
equilibrium and v its rate. The road pushes the wheel up with the contact force
F_0 - F, F_0 the static load; a tyre cannot pull, so with lift-off F is capped at F_0
(contact force max(0, F_0 - k_t x - c_t v)). The kink is an event of the integration
(switching function F_0 - k_t x - c_t v, positive in contact); a step takes the law of
the side it starts on, continued past the kink, and the step is cut at the crossing. Without a static load (``static_load`` None)
the tyre always presses: a linear spring and damper.

The tyre sits between a body with mass (the wheel) and the road only: the vehicle
templates (:mod:`inerterlab.systems.vehicle`) place it; it is not a network name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb

from ._base import TYRE, ElementBase, KernelLaw, Param

__all__ = ["Tyre", "TyreLaw", "tyre_force", "tyre_switch"]


@nb.njit(cache=True, inline="always")
def tyre_force(tab, o, x, v, side):
    """F [N] at extension x [m] and rate v [m/s]: min(F_0, k_t x + c_t v) (F_0 = tab[o+2],
    inf without lift-off). A held ``side`` (the integrator's, see
    :func:`inerterlab.systems._kernel.evaluate`) takes one law continued past the kink:
    > 0 in contact (k_t x + c_t v), < 0 lifted off (F_0); 0 whichever holds."""
    f = tab[o] * x + tab[o + 1] * v
    if side > 0.0:
        return f
    if side < 0.0:
        return tab[o + 2]
    return f if f < tab[o + 2] else tab[o + 2]


@nb.njit(cache=True, inline="always")
def tyre_switch(tab, o, x, v):
    """The contact force F_0 - k_t x - c_t v [N]: its sign changes where the tyre lifts
    off or lands (1 without lift-off)."""
    if math.isinf(tab[o + 2]):
        return 1.0
    return tab[o + 2] - tab[o] * x - tab[o + 1] * v


class TyreLaw(KernelLaw):
    """The tyre's row: one that always presses keeps its (linear) law; one that lifts
    off has no Gaussian equivalent (its lift-off probability is the Gaussian tail of
    its load)."""

    code = TYRE
    argument = "displacement"
    contact = True

    @classmethod
    def gaussian_keeps(cls, row) -> bool:
        return not math.isfinite(row[2])

    @classmethod
    def gaussian_refusal(cls, row, description: str) -> tuple[str, str] | None:
        if math.isfinite(row[2]):
            return (
                "a tyre that lifts off",
                "a tyre that always presses for the statistical linearisation (its "
                "lift-off probability is the Gaussian tail of its load)",
            )
        return None


@dataclass(frozen=True, kw_only=True)
class Tyre(ElementBase):
    """Tyre of ``stiffness`` k_t [N/m] > 0 and ``damping`` c_t [N s/m] >= 0; with a
    ``static_load`` F_0 [N] > 0 it lifts off when the contact force F_0 - k_t x - c_t v
    would be negative (None: always in contact, linear)."""

    stiffness: float
    damping: float = 0.0
    static_load: float | None = None

    prefix = "tyre"
    description = "point-contact tyre"
    ROLE = "elastic"
    EXAMPLE = {"stiffness": 2e5, "damping": 100.0, "static_load": 4e3}
    PARAMETERS = (
        Param("stiffness", "N/m"),
        Param("damping", "N s/m", low_open=False),
        Param("static_load", "N", optional=True),
    )
    code = TYRE

    def row(self):
        f0 = math.inf if self.static_load is None else self.static_load
        return self._row(self.stiffness, self.damping, f0)

    @property
    def is_linear(self):
        return self.static_load is None

    def rest_network(self):
        """k_t | c_t: in contact at rest."""
        if self.damping > 0:
            return "k | c", {"k": self.stiffness, "c": self.damping}
        return "k", {"k": self.stiffness}
