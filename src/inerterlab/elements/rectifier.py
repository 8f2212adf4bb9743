"""Hydraulic device with rectifier (5.3) as a composite: k_r - (c_r | f_r | flywheel).

Identified values from :class:`inerterlab.devices.models.RectifierDevice` (nylon-large
flywheel, r = 1318.6 rad/m). The flywheel stays coupled (the model the thesis
identified); the one-way free-wheeling motor is available in the device models
(:mod:`inerterlab.devices`), not as a network element.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..devices.models import RectifierDevice
from ..flywheels import FLYWHEEL_PRESETS
from ._base import Param
from .hydraulic import HydraulicElement

__all__ = ["RectifierElement"]

_D = RectifierDevice()


@dataclass(frozen=True, kw_only=True)
class RectifierElement(HydraulicElement):
    """Rectifier device: the parameters of :class:`HydraulicElement` with (5.14) values
    (a flywheel is required; ``ratio`` or ``inertance`` sizes it)."""

    stiffness: float = _D.stiffness
    damping: float = _D.damping
    friction: float = _D.friction
    friction_velocity: float = _D.friction_velocity
    flywheel: str = _D.flywheel.name
    law: str = _D.law

    prefix = "rect"
    DEFAULT_RATIO = _D.transmission.ratio
    EXAMPLE = {}
    description = "rectifier device"
    PARAMETERS = tuple(
        Param("flywheel", choices=FLYWHEEL_PRESETS) if p.name == "flywheel" else p
        for p in HydraulicElement.PARAMETERS
    )
