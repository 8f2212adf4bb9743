"""The real two-terminal devices of thesis ch. 3.2.4, 3.3.4 and 5.3, with their presets.

Three devices, each a frozen keyword-only dataclass (SI units):

:class:`HydraulicDevice` (3.15)
    A spring ``stiffness`` k_h in series with the branch [inertance m_e(v_a) + damper
    ``damping`` b_ah + Coulomb friction ``friction`` F_fh sgn(v_a)]:
    F = k_h x_k, v = x_k' + v_a, F = m_e v_a' + b_ah v_a + F_fh sgn(v_a).
:class:`ScrewDevice` (3.34)-(3.38)
    The inverse ball screw as the thesis models it, everything acting on the terminal
    displacement x = x_1 - x_2: F = k_i x + c_i x' + f_i sgn(x') [+ m_e x''  in contact].
    With a backlash rho_1 + rho_2 > 0 the inertance acts only in "contact", which
    (3.36)-(3.37) define by |k_i x + c_i x'| >= k_i (rho_1 + rho_2).
:class:`RectifierDevice` (5.3)
    The hydraulic device with a rectifier (ratio of Table 5.3, ``nylon-large`` flywheel
    of Table 5.4): the same series structure as (3.15). With ``freewheel=True`` the
    motor turns one way only and the flywheel is driven while r|v_a| >= omega and
    free-wheels otherwise.

Coulomb friction sgn(v) is smoothed to tanh(v / v_eps) (``friction_velocity`` v_eps,
default 1e-3 m/s). The friction force always has the sign of the velocity through
the friction element (for the screw this is x', where (3.35) prints the sign of the
displacement; see inerterlab/data/errata.md).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from ..errors import ParameterError, check_choice, check_nonnegative, check_positive
from ..flywheels import AdaptiveFlywheel, flywheel
from ..slider_dynamics import SliderDynamics
from ..transmissions import FORCE_LAWS, Transmission, transmission

__all__ = [
    "HydraulicDevice",
    "ScrewDevice",
    "RectifierDevice",
    "Device",
    "DEVICES",
    "device_preset",
    "PARAMETER_UNITS",
]

DEVICES = ("hydraulic", "screw", "rectifier")
PARAMETER_UNITS = {"stiffness": "N/m", "damping": "N s/m", "friction": "N"}


def _check_common(dev) -> None:
    check_positive("stiffness", dev.stiffness, "N/m")
    check_nonnegative("damping", dev.damping, "N s/m")
    check_nonnegative("friction", dev.friction, "N")
    check_positive("friction_velocity", dev.friction_velocity, "m/s")
    check_choice("law", dev.law, FORCE_LAWS)
    if not isinstance(dev.flywheel, AdaptiveFlywheel):
        raise ParameterError("flywheel", dev.flywheel, "an AdaptiveFlywheel")
    if not isinstance(dev.transmission, Transmission):
        raise ParameterError("transmission", dev.transmission, "a Transmission")
    if not isinstance(dev.slider_dynamics, SliderDynamics):
        raise ParameterError("slider_dynamics", dev.slider_dynamics, "a SliderDynamics")
    if dev.law == "slider-dynamics":
        dev.slider_dynamics.coefficients(dev.flywheel)  # raises for thesis-literal


@dataclass(frozen=True, kw_only=True)
class HydraulicDevice:
    """Two-terminal hydraulic device (3.15), Fig. 3.6.

    Parameters
    ----------
    stiffness : float
        k_h [N/m], series stiffness (5.8): 7.76e5.
    damping : float
        b_ah [N s/m], equivalent damping of the pressure loss (5.4): 8100.
    friction : float
        F_fh [N], Coulomb friction of piston and seals (5.4): 190.
    flywheel : AdaptiveFlywheel
        The flywheel on the motor shaft (default ``metal``, Table 3.1).
    transmission : Transmission
        r = A / h [rad/m] (default Table 3.2: 961.66).
    law : {"thesis", "momentum", "slider-dynamics"}
        How the speed-dependent inertia makes a force (docs/model.md §2).
    friction_velocity : float
        v_eps [m/s] of the smoothed friction tanh(v / v_eps).
    slider_dynamics : SliderDynamics
        Slider options for ``law="slider-dynamics"``.

    Examples
    --------
    >>> dev = HydraulicDevice()
    >>> dev.stiffness, dev.damping, dev.friction
    (776000.0, 8100.0, 190.0)
    """

    stiffness: float = 7.76e5
    damping: float = 8100.0
    friction: float = 190.0
    flywheel: AdaptiveFlywheel = field(default_factory=lambda: flywheel("metal"))
    transmission: Transmission = field(default_factory=lambda: transmission("hydraulic"))
    law: str = "thesis"
    friction_velocity: float = 1e-3
    slider_dynamics: SliderDynamics = field(default_factory=SliderDynamics)

    kind = "hydraulic"
    series = True

    def __post_init__(self) -> None:
        _check_common(self)

    @property
    def freewheel(self) -> bool:
        return False

    @property
    def backlash(self) -> float:
        return 0.0


@dataclass(frozen=True, kw_only=True)
class ScrewDevice:
    """Inverse ball screw with flywheel (3.34)-(3.38), Fig. 3.12.

    Parameters
    ----------
    stiffness : float
        k_i [N/m] (5.11): 1.97e6.
    damping : float
        c_i [N s/m] (5.11): 7600.
    friction : float
        f_i [N] (5.11): 80.
    backlash : float
        rho_1 + rho_2 [m], total backlash; the thesis gives no value (default 0: always
        in contact).
    flywheel : AdaptiveFlywheel
        Default ``nylon`` (Table 3.3).
    transmission : Transmission
        Default the inverse screw of Table 3.4, (3.26): 501.35 rad/m.
    law, friction_velocity, slider_dynamics
        As for :class:`HydraulicDevice`.
    """

    stiffness: float = 1.97e6
    damping: float = 7600.0
    friction: float = 80.0
    backlash: float = 0.0
    flywheel: AdaptiveFlywheel = field(default_factory=lambda: flywheel("nylon"))
    transmission: Transmission = field(default_factory=lambda: transmission("screw"))
    law: str = "thesis"
    friction_velocity: float = 1e-3
    slider_dynamics: SliderDynamics = field(default_factory=SliderDynamics)

    kind = "screw"
    series = False

    def __post_init__(self) -> None:
        _check_common(self)
        check_nonnegative("backlash", self.backlash, "m")

    @property
    def freewheel(self) -> bool:
        return False


@dataclass(frozen=True, kw_only=True)
class RectifierDevice:
    """Hydraulic device with rectifier (5.3), Tables 5.3 and 5.4.

    Parameters
    ----------
    stiffness : float
        k_r [N/m] (5.14): 9.89e5.
    damping : float
        c_r [N s/m] (5.14): 8100.
    friction : float
        f_r [N] (5.14): 240.
    freewheel : bool
        Model the one-way motor: the flywheel is driven while r|v_a| >= omega and
        free-wheels otherwise (laws ``thesis`` and ``momentum``). False (default) keeps
        the flywheel coupled, the model the thesis identified.
    flywheel_drag : float
        Viscous drag of the flywheel bearing c_d [N m s/rad] (torque c_d omega). The
        thesis gives none (default 0); without drag a free-wheeling flywheel keeps its
        top speed for ever, so it only re-engages when the terminals move faster.
    flywheel : AdaptiveFlywheel
        Default ``nylon-large`` (Table 5.4).
    transmission : Transmission
        Default Table 5.3: 1318.6 rad/m.
    law, friction_velocity, slider_dynamics
        As for :class:`HydraulicDevice`.
    """

    stiffness: float = 9.89e5
    damping: float = 8100.0
    friction: float = 240.0
    freewheel: bool = False
    flywheel_drag: float = 0.0
    flywheel: AdaptiveFlywheel = field(default_factory=lambda: flywheel("nylon-large"))
    transmission: Transmission = field(default_factory=lambda: transmission("rectifier"))
    law: str = "thesis"
    friction_velocity: float = 1e-3
    slider_dynamics: SliderDynamics = field(default_factory=SliderDynamics)

    kind = "rectifier"
    series = True

    def __post_init__(self) -> None:
        _check_common(self)
        check_nonnegative("flywheel_drag", self.flywheel_drag, "N m s/rad")
        if not isinstance(self.freewheel, bool):
            raise ParameterError("freewheel", self.freewheel, "True or False")
        if self.freewheel and self.law == "slider-dynamics":
            raise ParameterError(
                "freewheel",
                True,
                "False with law='slider-dynamics' (free-wheeling is "
                "modelled for the thesis and momentum laws)",
            )

    @property
    def backlash(self) -> float:
        return 0.0


Device = HydraulicDevice | ScrewDevice | RectifierDevice

_DEFAULT_FLYWHEEL = {"hydraulic": "metal", "screw": "nylon", "rectifier": "nylon-large"}


def device_preset(name: str, *, flywheel_preset: str | None = None, **changes) -> Device:
    """A device with the thesis's identified parameters.

    ``hydraulic``: (5.4), (5.8) with the metal flywheel (Table 3.1, ch. 5.1);
    ``screw``: (5.11) with the nylon flywheel (Table 3.3, ch. 5.2);
    ``rectifier``: (5.14) with the nylon-large flywheel (Table 5.4, ch. 5.3).

    Parameters
    ----------
    name : {"hydraulic", "screw", "rectifier"}
    flywheel_preset : str, optional
        Another flywheel preset (``metal``, ``nylon``, ``nylon-large``).
    **changes
        Any field to override (``law=``, ``stiffness=`` ...).

    Examples
    --------
    >>> device_preset("rectifier").transmission.ratio > 1318
    True
    """
    check_choice("device", name, DEVICES)
    cls = {"hydraulic": HydraulicDevice, "screw": ScrewDevice, "rectifier": RectifierDevice}[name]
    dev = cls()
    if flywheel_preset is not None:
        dev = dataclasses.replace(dev, flywheel=flywheel(flywheel_preset))
    return dataclasses.replace(dev, **changes) if changes else dev
