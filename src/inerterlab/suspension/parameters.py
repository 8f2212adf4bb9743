"""Parameter sets of the quarter car and of the real hydraulic device.

Base values are the thesis's (4.16); the device values are the identified hydraulic
parameters of ch. 5 used in ch. 6 (docs/model.md §3).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import check_nonnegative, check_positive

__all__ = ["QuarterCarParameters", "HydraulicDeviceParameters", "GRAVITY"]

GRAVITY = 9.81  # [m/s^2]


@dataclass(frozen=True, kw_only=True)
class QuarterCarParameters:
    """Masses, suspension and tyre of a quarter car (thesis (4.1), (4.16)).

    Parameters
    ----------
    sprung_mass : float
        M (the thesis's M_v in the tables) [kg]. The thesis sweeps 340-400 kg and uses
        370 kg for the changing-ratio studies; 370 kg is the default here ((4.16)
        prints 300 kg, which no table uses).
    unsprung_mass : float
        M_t [kg], default 25.
    stiffness : float
        K [N/m], suspension spring, default 90 kN/m.
    damping : float
        C [N s/m], suspension damper, default 5000.
    tyre_stiffness : float
        K_t [N/m], default 120 kN/m.
    tyre_damping : float
        C_t [N s/m], default 1300. May be 0.
    gravity : float
        g [m/s^2], used by the tyre grip index (4.20) and the lift-off test.

    Examples
    --------
    >>> p = QuarterCarParameters(sprung_mass=340)
    >>> round(p.static_tyre_load, 2)  # (340 + 25) kg x 9.81 m/s^2
    3580.65
    """

    sprung_mass: float = 370.0
    unsprung_mass: float = 25.0
    stiffness: float = 90_000.0
    damping: float = 5000.0
    tyre_stiffness: float = 120_000.0
    tyre_damping: float = 1300.0
    gravity: float = GRAVITY

    def __post_init__(self) -> None:
        check_positive("sprung_mass", self.sprung_mass, "kg")
        check_positive("unsprung_mass", self.unsprung_mass, "kg")
        check_nonnegative("stiffness", self.stiffness, "N/m")
        check_nonnegative("damping", self.damping, "N s/m")
        check_positive("tyre_stiffness", self.tyre_stiffness, "N/m")
        check_nonnegative("tyre_damping", self.tyre_damping, "N s/m")
        check_positive("gravity", self.gravity, "m/s^2")

    @property
    def static_tyre_load(self) -> float:
        """(M + M_t) g [N], the static tyre force ((4.20) denominator)."""
        return (self.sprung_mass + self.unsprung_mass) * self.gravity


@dataclass(frozen=True, kw_only=True)
class HydraulicDeviceParameters:
    """The real hydraulic two-terminal device of ch. 3.2.4 and 6 ((3.15), (6.1), (6.2)).

    A spring ``stiffness`` (k_h) in series with a branch holding the inertance (system B
    only), a damper ``damping`` (b_ah) and Coulomb friction ``friction`` (F_fh). The
    friction is smoothed as F_fh tanh(u / friction_velocity), u the velocity through
    the branch.

    Parameters
    ----------
    damping : float
        b_ah [N s/m], identified 8100 +/- 100. Must be > 0: in system A the branch
        has no mass, so its velocity follows from the force balance through it.
    friction : float
        F_fh [N], identified 190 +/- 8.
    stiffness : float
        k_h [N/m], identified 7.76e5.
    friction_velocity : float
        v_eps [m/s] of the tanh smoothing, default 1e-3. Results converge as it
        shrinks; smaller values make the equations stiffer.
    """

    damping: float = 8100.0
    friction: float = 190.0
    stiffness: float = 7.76e5
    friction_velocity: float = 1e-3

    def __post_init__(self) -> None:
        check_positive("device_damping", self.damping, "N s/m")
        check_nonnegative("device_friction", self.friction, "N")
        check_positive("device_stiffness", self.stiffness, "N/m")
        check_positive("friction_velocity", self.friction_velocity, "m/s")
