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
from ..transmissions import FORCE_LAWS
from ._base import ElementBase, Param
from .hydraulic import series_device_expansion

__all__ = ["RectifierElement"]

_D = RectifierDevice()


@dataclass(frozen=True, kw_only=True)
class RectifierElement(ElementBase):
    """Rectifier device: the parameters of :class:`HydraulicElement` with (5.14) values."""

    stiffness: float = _D.stiffness
    damping: float = _D.damping
    friction: float = _D.friction
    friction_velocity: float = _D.friction_velocity
    flywheel: str = _D.flywheel.name
    changing_ratio: float | None = None
    ratio: float = _D.transmission.ratio
    law: str = _D.law

    prefix = "rect"
    description = "rectifier device"
    PARAMETERS = (
        Param("stiffness", "N/m"),
        Param("damping", "N s/m", low_open=False),
        Param("friction", "N", low_open=False),
        Param("friction_velocity", "m/s"),
        Param("flywheel", choices=FLYWHEEL_PRESETS),
        Param("changing_ratio", "", 0.0, 1.0, optional=True),
        Param("ratio", "rad/m"),
        Param("law", choices=FORCE_LAWS),
    )

    def expansion(self):
        return series_device_expansion(self)
