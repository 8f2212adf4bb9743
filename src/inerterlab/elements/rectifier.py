"""Hydraulic device with rectifier (5.3) as a composite: k_r - (c_r | f_r | flywheel).

Identified values from :class:`inerterlab.devices.models.RectifierDevice` (nylon-large
flywheel, r = 1318.6 rad/m). By default the flywheel stays coupled (the model the thesis
identified), k_r - (c_r | f_r | afw); with ``freewheel`` the motor drives it through a
one-way clutch, k_r - (c_r | f_r | owc) (:mod:`.one_way_clutch`). A bearing drag
``flywheel_drag`` c_d [N m s/rad] is a damper c_d r^2 beside the coupled flywheel
(:mod:`.bearing_drag`) or slows the free-wheeling one.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..devices.models import RectifierDevice
from ..errors import ParameterError
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
    freewheel: bool = False
    flywheel_drag: float = 0.0

    prefix = "rect"
    DEFAULT_RATIO = _D.transmission.ratio
    EXAMPLE = {}
    description = "rectifier device"
    PARAMETERS = (
        *(
            Param("flywheel", choices=FLYWHEEL_PRESETS) if p.name == "flywheel" else p
            for p in HydraulicElement.PARAMETERS
        ),
        Param("freewheel", choices=(False, True)),
        Param("flywheel_drag", "N m s/rad", low_open=False),
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.freewheel and self.law == "slider-dynamics":
            raise ParameterError(
                "freewheel", True, "False with law='slider-dynamics' (free-wheeling is "
                "modelled for the thesis and momentum laws)",
            )  # fmt: skip
        if self.freewheel and self.damping <= 0:
            raise ParameterError("damping", self.damping, "> 0 N s/m with freewheel=True")
