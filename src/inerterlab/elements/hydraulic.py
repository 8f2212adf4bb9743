"""Hydraulic device (3.15) as a composite: k_h - (b_ah | F_fh friction | flywheel inerter).

Identified values (docs/model.md §3) come from
:class:`inerterlab.devices.models.HydraulicDevice`; ``flywheel="none"`` drops the
inertance (the quarter car's system A, (6.1)).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..devices.models import HydraulicDevice
from ..flywheels import FLYWHEEL_PRESETS
from ..transmissions import FORCE_LAWS
from ._base import ElementBase, Param
from .adaptive_flywheel import AdaptiveFlywheelInerter
from .damper import Damper
from .friction import Friction
from .spring import Spring

__all__ = ["HydraulicElement", "series_device_expansion"]

_D = HydraulicDevice()


def series_device_expansion(el) -> tuple[str, dict]:
    """k - (c | fric | afw) of a series device, without the parts that are zero."""
    parts = {"k": Spring(stiffness=el.stiffness)}
    branch = []
    if el.damping > 0:
        parts["c"] = Damper(damping=el.damping)
        branch.append("c")
    if el.friction > 0:
        parts["fric"] = Friction(force=el.friction, velocity=el.friction_velocity)
        branch.append("fric")
    if el.flywheel != "none":
        parts["afw"] = AdaptiveFlywheelInerter(
            flywheel=el.flywheel, changing_ratio=el.changing_ratio, ratio=el.ratio, law=el.law
        )
        branch.append("afw")
    return f"k - ({' | '.join(branch)})", parts


@dataclass(frozen=True, kw_only=True)
class HydraulicElement(ElementBase):
    """Hydraulic device: ``stiffness`` k_h, ``damping`` b_ah, ``friction`` F_fh,
    ``friction_velocity`` v_eps, ``flywheel`` (preset or ``none``), ``changing_ratio``,
    ``ratio`` r, ``law``."""

    stiffness: float = _D.stiffness
    damping: float = _D.damping
    friction: float = _D.friction
    friction_velocity: float = _D.friction_velocity
    flywheel: str = _D.flywheel.name
    changing_ratio: float | None = None
    ratio: float = _D.transmission.ratio
    law: str = _D.law

    prefix = "hyd"
    EXAMPLE = {}
    description = "hydraulic device"
    PARAMETERS = (
        Param("stiffness", "N/m"),
        Param("damping", "N s/m", low_open=False),
        Param("friction", "N", low_open=False),
        Param("friction_velocity", "m/s"),
        Param("flywheel", choices=(*FLYWHEEL_PRESETS, "none")),
        Param("changing_ratio", "", 0.0, 1.0, optional=True),
        Param("ratio", "rad/m"),
        Param("law", choices=FORCE_LAWS),
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.damping == 0.0 and self.flywheel == "none":
            from ..errors import ParameterError

            raise ParameterError(
                "damping", 0.0, "a value > 0 N s/m when the device has no flywheel"
            )

    def expansion(self):
        return series_device_expansion(self)
