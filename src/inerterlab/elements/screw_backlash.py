"""The ball screw's backlash rule (thesis (3.36)-(3.37)): a flywheel inerter that acts
only while the screw is in contact.

The inverse ball screw carries k_i x + c_i x' through its elastic and damping parts; its
nut meets the screw, and the flywheel's inertial force acts, only once that force has
taken up the total backlash rho = rho_1 + rho_2:

    contact  <=>  |k_i x + c_i x'| >= k_i rho  <=>  |x + tau x'| >= rho,  tau = c_i / k_i,

x and x' the relative displacement and velocity of the element's terminals. In contact
the force is that of the adaptive-flywheel inerter (:mod:`.adaptive_flywheel`, any of
its laws); out of contact it is zero (the sliders of ``slider-dynamics`` keep moving
with the shaft). The switching function |x + tau x'| - rho is located by the
integrator; the flywheel's own saturation kink is then stepped across under error
control.

For small motions about rest (|x + tau x'| < rho) the element carries no force: an open
circuit for the linear analyses; with no backlash it is the flywheel inerter.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba as nb

from ._base import Param
from .adaptive_flywheel import AdaptiveFlywheelInerter

__all__ = ["ScrewContact", "contact_argument", "GATED"]

#: variant code of the contact-gated flywheel (row[14]); row[15] = rho, row[16] = tau
GATED = 1.0


@nb.njit(cache=True, inline="always")
def contact_argument(tab, o, x, v):
    """x + tau x' [m], the argument of the contact rule."""
    return x + tab[o + 16] * v


@nb.njit(cache=True, inline="always")
def in_contact(tab, o, x, v, side):
    """True in contact: ``side`` > 0 in contact, < 0 not (the side the integrator
    holds), 0 from |x + tau x'| >= rho."""
    if side != 0.0:
        return side > 0.0
    return abs(contact_argument(tab, o, x, v)) >= tab[o + 15]


@dataclass(frozen=True, kw_only=True)
class ScrewContact(AdaptiveFlywheelInerter):
    """Flywheel inerter of a ball screw with total ``backlash`` rho [m] >= 0, in contact
    while |``stiffness`` x + ``damping`` x'| >= ``stiffness`` rho (k_i [N/m] > 0, c_i
    [N s/m] >= 0 of the screw); the other parameters as
    :class:`AdaptiveFlywheelInerter`."""

    backlash: float = 0.0
    stiffness: float = 1.97e6
    damping: float = 7600.0

    prefix = "sgap"
    description = "ball-screw flywheel with backlash"
    PARAMETERS = (
        *AdaptiveFlywheelInerter.PARAMETERS,
        Param("backlash", "m", low_open=False),
        Param("stiffness", "N/m"),
        Param("damping", "N s/m", low_open=False),
    )
    EXAMPLE = {"backlash": 1e-4}

    def __post_init__(self) -> None:
        super().__post_init__()
        for p in self.PARAMETERS[5:]:
            object.__setattr__(self, p.name, float(p.check(getattr(self, p.name))))

    def row(self):
        r = super().row()
        r[14] = GATED
        r[15] = self.backlash
        r[16] = self.damping / self.stiffness
        return r

    def scaled(self, factor):
        from dataclasses import replace

        base = super().scaled(factor)  # the contact force scales with the copies too
        return replace(base, stiffness=self.stiffness * factor, damping=self.damping * factor)

    def linear_regime(self):
        return None if self.backlash > 0.0 else super().linear_regime()

    def rest_network(self):
        """The flywheel inerter with no backlash; else None (no contact about rest)."""
        return super().rest_network() if self.backlash == 0.0 else None
