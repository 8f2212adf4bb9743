"""Transmissions from terminal motion to flywheel rotation, and the force laws.

A two-terminal device turns the relative terminal velocity v [m/s] into flywheel speed
omega = r v [rad/s]; the equivalent mass is m_e = r^2 I ((3.12), (3.29)).

Three ways a speed-dependent inertia can produce a force are offered (docs/model.md §2):

``thesis``
    F = r^2 I(r|v|) dv/dt, what the thesis integrates. It does not conserve energy:
    the work done on the device differs from the stored energy change by
    -1/2 (dI/dt) omega^2 - (spring energy change).
``momentum``
    F = r d(I omega)/dt = r^2 (I + |omega| dI/d|omega|) dv/dt with the sliders in
    quasi-static equilibrium. Work in = kinetic + spring energy.
``slider-dynamics``
    The sliders are their own degree of freedom; see :mod:`inerterlab.slider_dynamics`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import check_choice, check_positive
from .flywheels import AdaptiveFlywheel

__all__ = [
    "Transmission",
    "hydraulic",
    "rectifier",
    "inverse_screw",
    "transmission",
    "TRANSMISSIONS",
    "FORCE_LAWS",
    "equivalent_mass",
    "inertance",
]

TRANSMISSIONS = ("hydraulic", "rectifier", "screw")
FORCE_LAWS = ("thesis", "momentum", "slider-dynamics")


@dataclass(frozen=True, kw_only=True)
class Transmission:
    """A linear-to-rotary transmission omega = ratio * v.

    Parameters
    ----------
    ratio : float
        r [rad/m].
    name : str
        Label.
    one_way : bool
        True for the hydraulic rectifier: the motor only turns one way and the
        flywheel free-wheels when it runs faster than r|v|.
    """

    ratio: float
    name: str = "custom"
    one_way: bool = False

    def __post_init__(self) -> None:
        check_positive("ratio", self.ratio, "rad/m")


def hydraulic(*, area: float = 0.001256, displacement: float = 1.30607e-6) -> Transmission:
    """Two-terminal hydraulic device of Table 3.2: r = A / h [rad/m].

    Parameters
    ----------
    area : float
        Cylinder cross-section A [m^2].
    displacement : float
        Motor displacement h [m^3/rad].

    Examples
    --------
    >>> round(hydraulic().ratio, 2)
    961.66
    """
    a = check_positive("area", area, "m^2")
    h = check_positive("displacement", displacement, "m^3/rad")
    return Transmission(ratio=a / h, name="hydraulic")


def rectifier(*, area: float = 0.00146, displacement: float = 1.1072e-6) -> Transmission:
    """Hydraulic device with rectifier of Table 5.3: r = A / H [rad/m].

    >>> round(rectifier().ratio, 1)
    1318.6
    """
    a = check_positive("area", area, "m^2")
    h = check_positive("displacement", displacement, "m^3/rad")
    return Transmission(ratio=a / h, name="rectifier", one_way=True)


def inverse_screw(*, diameter: float = 0.016, helix_angle_deg: float = 14.0) -> Transmission:
    """Inverse ball screw of Table 3.4, (3.26): r = 2 / (d tan(alpha)) [rad/m].

    >>> round(inverse_screw().ratio, 2)
    501.35
    """
    d = check_positive("diameter", diameter, "m")
    a = check_positive("helix_angle_deg", helix_angle_deg, "deg")
    if a >= 90:
        from .errors import ParameterError

        raise ParameterError("helix_angle_deg", helix_angle_deg, "an angle in (0, 90) deg")
    return Transmission(ratio=2.0 / (d * math.tan(math.radians(a))), name="screw")


def transmission(name: str) -> Transmission:
    """The thesis transmission called ``name`` (hydraulic, rectifier or screw)."""
    check_choice("device", name, TRANSMISSIONS)
    return {"hydraulic": hydraulic, "rectifier": rectifier, "screw": inverse_screw}[name]()


def equivalent_mass(fw: AdaptiveFlywheel, tr: Transmission, velocity):
    """m_e = r^2 I(r |v|) [kg] for terminal velocity ``velocity`` [m/s] ((3.12), (3.29))."""
    v = np.asarray(velocity, dtype=float)
    out = tr.ratio**2 * np.asarray(fw.inertia(tr.ratio * v))
    return out if out.ndim else float(out)


def inertance(fw: AdaptiveFlywheel, tr: Transmission, velocity, law: str = "thesis"):
    """The mass multiplying dv/dt in the force, F = inertance(v) dv/dt [kg].

    ``thesis``: r^2 I(r|v|). ``momentum``: r^2 (I + |omega| dI/d|omega|). The
    ``slider-dynamics`` law has no such algebraic form (see
    :mod:`inerterlab.slider_dynamics`).
    """
    check_choice("law", law, ("thesis", "momentum"))
    v = np.asarray(velocity, dtype=float)
    w = tr.ratio * v
    j = fw.inertia(w) if law == "thesis" else fw.momentum_inertia(w)
    out = tr.ratio**2 * np.asarray(j)
    return out if out.ndim else float(out)
