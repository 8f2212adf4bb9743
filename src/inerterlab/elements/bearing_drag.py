"""Flywheel bearing drag: a viscous torque c_d omega on a flywheel turning at omega.

Seen at the terminals through a transmission of ratio r [rad/m] (omega = r v) the
torque is a force F = r c_d omega = c_d r^2 v: a linear damper of c_d r^2 [N s/m]. That
is the element (prefix ``drag``), for a flywheel coupled to its terminals. A flywheel
behind a one-way clutch (:mod:`.one_way_clutch`) feels the same torque while it runs
free and slows down under it; that element calls :func:`drag_torque`, the law written
once here.

The thesis identifies no bearing drag (the rectifier device of ch. 5.3 has none); the
element lets a user add one, and without it a free-wheeling flywheel never slows down.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numba as nb

from ..transmissions import hydraulic as hydraulic_transmission
from ._base import DAMPER, ElementBase, Param

__all__ = ["BearingDrag", "drag_torque"]


@nb.njit(cache=True, inline="always")
def drag_torque(drag, omega):
    """Bearing torque [N m] opposing a flywheel at ``omega`` [rad/s], viscous drag
    ``drag`` c_d [N m s/rad]."""
    return drag * omega


@dataclass(frozen=True, kw_only=True)
class BearingDrag(ElementBase):
    """Viscous bearing ``drag`` c_d [N m s/rad] of a flywheel driven at ``ratio`` r
    [rad/m]: the damper F = c_d r^2 v at the terminals."""

    drag: float
    ratio: float = field(default_factory=lambda: hydraulic_transmission().ratio)

    prefix = "drag"
    description = "flywheel bearing drag"
    ROLE = "dissipative"
    EXAMPLE = {"drag": 2e-3}
    PARAMETERS = (
        Param("drag", "N m s/rad", design=(1e-5, 1.0)),
        Param("ratio", "rad/m"),
    )
    code = DAMPER
    is_linear = True

    @property
    def damping(self) -> float:
        """c_d r^2 [N s/m], the damper at the terminals."""
        return self.ratio * drag_torque(self.drag, self.ratio)

    def row(self):
        return self._row(self.damping, 0.0)

    def scaled(self, factor):
        return dataclasses.replace(self, drag=self.drag * factor)

    def rest_network(self):
        return "c", {"c": self.damping}
