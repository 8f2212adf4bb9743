"""Inverse ball screw (3.34)-(3.38) as a composite: k_i | c_i | f_i | flywheel inerter,
all on the terminal displacement. Identified values from
:class:`inerterlab.devices.models.ScrewDevice` (nylon flywheel, r = 501.35 rad/m). With
a total ``backlash`` rho > 0 the flywheel acts only in contact, (3.36)-(3.37)
(:mod:`.screw_backlash`); the thesis publishes no value (default 0: always in contact).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..devices.models import ScrewDevice
from ..flywheels import FLYWHEEL_PRESETS
from ..transmissions import FORCE_LAWS
from ._base import ElementBase, Param
from .adaptive_flywheel import AdaptiveFlywheelInerter
from .damper import Damper
from .friction import Friction
from .hydraulic import resolve_inertance
from .screw_backlash import ScrewContact
from .spring import Spring

__all__ = ["ScrewElement"]

_D = ScrewDevice()


@dataclass(frozen=True, kw_only=True)
class ScrewElement(ElementBase):
    """Ball-screw device: ``stiffness`` k_i, ``damping`` c_i, ``friction`` f_i,
    ``friction_velocity``, ``flywheel``, ``changing_ratio``, ``ratio`` r [rad/m] or
    ``inertance`` r^2 I_min [kg] (either; after construction both hold the resolved
    values), ``law``."""

    stiffness: float = _D.stiffness
    damping: float = _D.damping
    friction: float = _D.friction
    friction_velocity: float = _D.friction_velocity
    flywheel: str = _D.flywheel.name
    changing_ratio: float | None = None
    ratio: float | None = None
    law: str = _D.law
    inertance: float | None = None
    backlash: float = 0.0

    prefix = "screw"
    ALTERNATIVES = {"inertance": "ratio"}
    DEFAULT_RATIO = _D.transmission.ratio
    EXAMPLE = {}
    description = "ball-screw device"
    PARAMETERS = (
        Param("stiffness", "N/m"),
        Param("damping", "N s/m", low_open=False),
        Param("friction", "N", low_open=False),
        Param("friction_velocity", "m/s"),
        Param("flywheel", choices=FLYWHEEL_PRESETS),
        Param("changing_ratio", "", 0.0, 1.0, optional=True),
        Param("ratio", "rad/m", optional=True),
        Param("law", choices=FORCE_LAWS),
        Param("inertance", "kg", optional=True),
        Param("backlash", "m", low_open=False),
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        resolve_inertance(self, self.DEFAULT_RATIO)

    def parameters(self) -> dict:
        """The parameter values by name; the size as the ``ratio`` (``inertance`` None)."""
        return {**super().parameters(), "inertance": None}

    def expansion(self):
        parts = {
            "k": Spring(stiffness=self.stiffness),
            "afw": AdaptiveFlywheelInerter(
                flywheel=self.flywheel,
                changing_ratio=self.changing_ratio,
                ratio=self.ratio,
                law=self.law,
            ),
        }
        if self.backlash > 0:
            parts["afw"] = ScrewContact(
                flywheel=self.flywheel, changing_ratio=self.changing_ratio, ratio=self.ratio,
                law=self.law, backlash=self.backlash, stiffness=self.stiffness,
                damping=self.damping,
            )  # fmt: skip
        names = ["k"]
        if self.damping > 0:
            parts["c"] = Damper(damping=self.damping)
            names.append("c")
        if self.friction > 0:
            parts["fric"] = Friction(force=self.friction, velocity=self.friction_velocity)
            names.append("fric")
        return " | ".join([*names, "afw"]), parts
