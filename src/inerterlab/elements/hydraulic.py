"""Hydraulic device (3.15) as a composite: k_h - (b_ah | F_fh friction | flywheel inerter).

Identified values (docs/model.md §3) come from
:class:`inerterlab.devices.models.HydraulicDevice`; ``flywheel="none"`` drops the
inertance (the quarter car's system A, (6.1)). The flywheel's size is given either by
the transmission ``ratio`` r [rad/m] or by the ``inertance`` at rest r^2 I_min [kg]
(:func:`resolve_inertance`).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..devices.models import HydraulicDevice
from ..flywheels import FLYWHEEL_PRESETS
from ..transmissions import FORCE_LAWS
from ._base import ElementBase, Param
from .adaptive_flywheel import AdaptiveFlywheelInerter
from .bearing_drag import BearingDrag
from .damper import Damper
from .friction import Friction
from .one_way_clutch import OneWayClutch
from .spring import Spring

__all__ = ["HydraulicElement", "series_device_expansion", "resolve_inertance"]

_D = HydraulicDevice()

#: relative difference above which a given ``inertance`` and ``ratio`` disagree
CONSISTENT = 1e-9


def resolve_inertance(el, default_ratio: float) -> None:
    """Set ``el.ratio`` from ``el.inertance`` (b = r^2 I_min, so r = sqrt(b / I_min)) or
    the default, and ``el.inertance`` to r^2 I_min; a ParameterError naming
    ``inertance`` if both are given and differ, or if there is no flywheel.

    The ratio is the element's own parameter (:meth:`HydraulicElement.parameters`
    reports it, the inertance as None): either may be given, not two that disagree."""
    from ..errors import ParameterError
    from ..flywheels import AdaptiveFlywheel
    from ..flywheels import flywheel as make_flywheel

    b, r = el.inertance, el.ratio
    if el.flywheel == "none":
        if b is not None:
            raise ParameterError(
                "inertance", b, "no value: the device has no flywheel (flywheel=none)"
            )
        object.__setattr__(el, "ratio", default_ratio if r is None else r)
        return
    fw = el.flywheel if isinstance(el.flywheel, AdaptiveFlywheel) else make_flywheel(el.flywheel)
    if el.changing_ratio is not None:
        fw = fw.with_changing_ratio(el.changing_ratio)
    i_min = fw.inertia_min
    if b is not None:
        rb = (b / i_min) ** 0.5
        if r is not None and abs(r - rb) > CONSISTENT * rb:
            raise ParameterError(
                "inertance",
                b,
                f"one of inertance and ratio, or both consistent: ratio={r:g} rad/m gives "
                f"r^2 I_min = {r * r * i_min:.6g} kg ({fw.name} flywheel, I_min = "
                f"{i_min:.6g} kg m^2); inertance={b:g} kg needs ratio={rb:.6g} rad/m",
            )
        object.__setattr__(el, "ratio", float(rb))  # the inertance as given, to the bit
        return
    if r is None:
        r = default_ratio
    object.__setattr__(el, "ratio", float(r))
    object.__setattr__(el, "inertance", float(r * r * i_min))


def series_device_expansion(el) -> tuple[str, dict]:
    """k - (c | fric | afw | drag) of a series device, without the parts that are zero;
    with a free-wheeling flywheel (``freewheel``) k - (c | fric | owc), the one-way
    clutch carrying the bearing drag."""
    parts = {"k": Spring(stiffness=el.stiffness)}
    branch = []
    if el.damping > 0:
        parts["c"] = Damper(damping=el.damping)
        branch.append("c")
    if el.friction > 0:
        parts["fric"] = Friction(force=el.friction, velocity=el.friction_velocity)
        branch.append("fric")
    drag = getattr(el, "flywheel_drag", 0.0)
    wheel = dict(flywheel=el.flywheel, changing_ratio=el.changing_ratio, ratio=el.ratio, law=el.law)
    if el.flywheel != "none" and getattr(el, "freewheel", False):
        parts["owc"] = OneWayClutch(**wheel, drag=drag)
        branch.append("owc")
    elif el.flywheel != "none":
        parts["afw"] = AdaptiveFlywheelInerter(**wheel)
        branch.append("afw")
        if drag > 0:
            parts["drag"] = BearingDrag(drag=drag, ratio=el.ratio)
            branch.append("drag")
    return f"k - ({' | '.join(branch)})", parts


@dataclass(frozen=True, kw_only=True)
class HydraulicElement(ElementBase):
    """Hydraulic device: ``stiffness`` k_h, ``damping`` b_ah, ``friction`` F_fh,
    ``friction_velocity`` v_eps, ``flywheel`` (preset or ``none``), ``changing_ratio``,
    ``ratio`` r [rad/m] or ``inertance`` r^2 I_min [kg] (either; after construction both
    hold the resolved values), ``law``."""

    stiffness: float = _D.stiffness
    damping: float = _D.damping
    friction: float = _D.friction
    friction_velocity: float = _D.friction_velocity
    flywheel: str = _D.flywheel.name
    changing_ratio: float | None = None
    ratio: float | None = None
    law: str = _D.law
    inertance: float | None = None

    prefix = "hyd"
    ALTERNATIVES = {"inertance": "ratio"}
    DEFAULT_RATIO = _D.transmission.ratio
    EXAMPLE = {}
    description = "hydraulic device"
    PARAMETERS = (
        Param("stiffness", "N/m"),
        Param("damping", "N s/m", low_open=False),
        Param("friction", "N", low_open=False),
        Param("friction_velocity", "m/s"),
        Param("flywheel", choices=(*FLYWHEEL_PRESETS, "none")),
        Param("changing_ratio", "", 0.0, 1.0, optional=True),
        Param("ratio", "rad/m", optional=True),
        Param("law", choices=FORCE_LAWS),
        Param("inertance", "kg", optional=True),
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        resolve_inertance(self, self.DEFAULT_RATIO)
        if self.damping == 0.0 and self.flywheel == "none":
            from ..errors import ParameterError

            raise ParameterError(
                "damping", 0.0, "a value > 0 N s/m when the device has no flywheel"
            )

    def parameters(self) -> dict:
        """The parameter values by name; the size as the ``ratio`` (``inertance`` None)."""
        return {**super().parameters(), "inertance": None}

    def expansion(self):
        return series_device_expansion(self)
