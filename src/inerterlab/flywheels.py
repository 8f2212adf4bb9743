"""Adaptive flywheels: geometry, the slider position law and the inertia law.

A disk carries ``n_sliders`` radial slots; in each one a slider of mass ``m_s`` sits on
a spring of stiffness ``k_s``. Rotation pushes the sliders outwards until they reach
the stop, so the moment of inertia grows with speed (thesis ch. 3).

Every flywheel in this module has an inertia law of the form

    I(omega) = I_rest + n_sliders * m_s * l(omega)**power          [kg m^2]

with ``power = 2`` (physical, (3.2), (3.6), (3.25)) or ``power = 1`` (the form printed
in thesis ch. 7, offered only as the explicit ``"thesis-literal"`` option). The slider
radius follows the quasi-static balance (3.7)-(3.9)

    k_s (l - l_min) = m_s l omega^2  =>  l(omega) = k_s l_min / (k_s - m_s omega^2)

clamped at ``l_max`` from the saturation speed
``omega_sat = sqrt(k_s (l_max - l_min) / (m_s l_max))`` upwards. The unclamped formula is
never evaluated at or beyond its pole ``omega = sqrt(k_s / m_s)``, which is always above
``omega_sat``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .errors import ParameterError, check_choice, check_finite, check_in_range, check_positive

__all__ = [
    "AdaptiveFlywheel",
    "MetalFlywheelGeometry",
    "NylonFlywheelGeometry",
    "flywheel",
    "constant_flywheel",
    "size_spring",
    "FLYWHEEL_PRESETS",
    "INERTIA_LAWS",
]

FLYWHEEL_PRESETS = ("metal", "nylon", "nylon-large")
INERTIA_LAWS = ("published", "geometry", "thesis-literal")


@dataclass(frozen=True, kw_only=True)
class AdaptiveFlywheel:
    """An adaptive flywheel with a quasi-static slider law.

    Parameters
    ----------
    rest_inertia : float
        I_rest [kg m^2], the inertia of everything except the point masses of the
        sliders (disk, removed material, the sliders' own rotational inertia).
    slider_mass : float
        m_s [kg], mass of one slider.
    spring_stiffness : float
        k_s [N/m], stiffness of one slider spring.
    slider_min : float
        l_min [m], slider centroid radius at rest.
    slider_max : float
        l_max [m], slider centroid radius at the stop.
    n_sliders : int
        Number of sliders (4 in every thesis design).
    power : int
        2 for the physical law; 1 reproduces the misprinted ch. 7 law
        ("thesis-literal"), never the default.
    name : str
        Label used in reports.

    Examples
    --------
    >>> fw = flywheel("nylon")
    >>> round(fw.inertia_min, 8), round(fw.inertia_max, 8)
    (0.00022299, 0.00031189)
    >>> round(fw.saturation_speed, 2)
    45.45
    """

    rest_inertia: float
    slider_mass: float
    spring_stiffness: float
    slider_min: float
    slider_max: float
    n_sliders: int = 4
    power: int = 2
    name: str = "custom"

    def __post_init__(self) -> None:
        check_positive("slider_mass", self.slider_mass, "kg")
        check_positive("spring_stiffness", self.spring_stiffness, "N/m")
        check_positive("slider_min", self.slider_min, "m")
        check_positive("slider_max", self.slider_max, "m")
        if not float(self.slider_min) < float(self.slider_max):
            raise ParameterError(
                "slider_min", self.slider_min, f"a radius < slider_max={self.slider_max} m"
            )
        if (
            not isinstance(self.n_sliders, int)
            or isinstance(self.n_sliders, bool)
            or (self.n_sliders < 1)
        ):
            raise ParameterError("n_sliders", self.n_sliders, "an integer >= 1")
        if self.power not in (1, 2):
            raise ParameterError("power", self.power, "1 (thesis-literal) or 2 (physical)")
        check_finite("rest_inertia", self.rest_inertia)
        if self.inertia_min <= 0:
            raise ParameterError(
                "rest_inertia", self.rest_inertia, "a value giving a positive minimum inertia"
            )

    # -- derived constants -------------------------------------------------------
    @property
    def inertia_coefficient(self) -> float:
        """n_sliders * m_s [kg]: the coefficient of l**power in the inertia law."""
        return self.n_sliders * self.slider_mass

    @property
    def inertia_min(self) -> float:
        """I_min [kg m^2], inertia at rest (sliders at l_min)."""
        return self.rest_inertia + self.inertia_coefficient * self.slider_min**self.power

    @property
    def inertia_max(self) -> float:
        """I_max [kg m^2], inertia with the sliders on the stop (l_max)."""
        return self.rest_inertia + self.inertia_coefficient * self.slider_max**self.power

    @property
    def changing_ratio(self) -> float:
        """x = (I_max - I_min) / I_max [-] (thesis 3.2.1)."""
        return (self.inertia_max - self.inertia_min) / self.inertia_max

    @property
    def saturation_speed(self) -> float:
        """omega_sat [rad/s], the speed at which the sliders reach l_max ((3.9) at l_max)."""
        k, m, a, b = self.spring_stiffness, self.slider_mass, self.slider_min, self.slider_max
        return math.sqrt(k * (b - a) / (m * b))

    @property
    def pole_speed(self) -> float:
        """sqrt(k_s / m_s) [rad/s], where the unclamped law (3.9) diverges."""
        return math.sqrt(self.spring_stiffness / self.slider_mass)

    # -- laws --------------------------------------------------------------------
    def slider_position(self, omega):
        """Slider radius l [m] against flywheel speed ``omega`` [rad/s], (3.9) clamped.

        Depends on |omega| only. The unclamped expression is evaluated only where
        |omega| < omega_sat, far from its pole.
        """
        w = np.abs(np.asarray(omega, dtype=float))
        ws = self.saturation_speed
        below = w < ws
        wb = np.where(below, w, 0.0)
        k, m = self.spring_stiffness, self.slider_mass
        l_free = k * self.slider_min / (k - m * wb * wb)
        out = np.where(below, l_free, self.slider_max)
        return out if out.ndim else float(out)

    def slider_position_derivative(self, omega):
        """d l / d|omega| [m s/rad]: zero at rest and above saturation."""
        w = np.abs(np.asarray(omega, dtype=float))
        below = w < self.saturation_speed
        wb = np.where(below, w, 0.0)
        k, m = self.spring_stiffness, self.slider_mass
        d = k - m * wb * wb
        out = np.where(below, 2.0 * k * self.slider_min * m * wb / (d * d), 0.0)
        return out if out.ndim else float(out)

    def inertia(self, omega):
        """Moment of inertia I [kg m^2] against speed ``omega`` [rad/s].

        Continuous, non-decreasing in |omega|, between ``inertia_min`` and
        ``inertia_max``.
        """
        l = np.asarray(self.slider_position(omega))
        out = self.rest_inertia + self.inertia_coefficient * l**self.power
        return out if np.ndim(out) else float(out)

    def inertia_derivative(self, omega):
        """dI / d|omega| [kg m^2 s/rad]."""
        l = np.asarray(self.slider_position(omega))
        dl = np.asarray(self.slider_position_derivative(omega))
        out = self.inertia_coefficient * self.power * l ** (self.power - 1) * dl
        return out if np.ndim(out) else float(out)

    def momentum_inertia(self, omega):
        """d(I omega)/d omega = I + |omega| dI/d|omega| [kg m^2] (the `momentum` law)."""
        w = np.abs(np.asarray(omega, dtype=float))
        out = np.asarray(self.inertia(w)) + w * np.asarray(self.inertia_derivative(w))
        return out if np.ndim(out) else float(out)

    def spring_energy(self, omega):
        """Energy stored in all slider springs [J] at quasi-static speed ``omega``."""
        l = np.asarray(self.slider_position(omega))
        out = 0.5 * self.n_sliders * self.spring_stiffness * (l - self.slider_min) ** 2
        return out if np.ndim(out) else float(out)

    # -- variants ----------------------------------------------------------------
    def with_changing_ratio(self, ratio: float) -> AdaptiveFlywheel:
        """The variant with changing ratio ``ratio`` (docs/model.md §1, thesis 4.3 and 6.3).

        Keeps I_min and the slider law l(omega) and scales the variable part:
        I(omega) = I_min + (I_min/(1-x) - I_min) (l^2 - l_min^2)/(l_max^2 - l_min^2).
        The slider mass and the spring stiffness are scaled by the same factor, so
        k_s/m_s (hence l(omega)) is unchanged and the slider-dynamics law stays
        energy-consistent.

        Parameters
        ----------
        ratio : float
            Changing ratio x in (0, 1).
        """
        x = check_in_range("changing_ratio", ratio, 0.0, 1.0, low_open=True, high_open=True)
        i_min = self.inertia_min
        span = self.slider_max**self.power - self.slider_min**self.power
        coeff = (i_min / (1.0 - x) - i_min) / span
        scale = coeff / self.inertia_coefficient
        return dataclasses.replace(
            self,
            slider_mass=self.slider_mass * scale,
            spring_stiffness=self.spring_stiffness * scale,
            rest_inertia=i_min - coeff * self.slider_min**self.power,
            name=f"{self.name} (x={x:.4g})",
        )

    def summary(self) -> dict:
        """The main numbers as a plain dict (SI units)."""
        return {
            "name": self.name,
            "inertia_min": self.inertia_min,
            "inertia_max": self.inertia_max,
            "changing_ratio": self.changing_ratio,
            "saturation_speed": self.saturation_speed,
            "slider_min": self.slider_min,
            "slider_max": self.slider_max,
            "slider_mass": self.slider_mass,
            "spring_stiffness": self.spring_stiffness,
            "rest_inertia": self.rest_inertia,
        }


def constant_flywheel(inertia: float, *, name: str = "constant") -> AdaptiveFlywheel:
    """A flywheel whose inertia never changes [kg m^2] (thesis's constant flywheel, CFW).

    Implemented as an adaptive flywheel with sliders so stiff that they never move
    within any speed the models reach (omega_sat ~ 1e12 rad/s).
    """
    i = check_positive("inertia", inertia, "kg m^2")
    # negligible slider mass, huge spring: l stays at l_min for any practical speed
    return AdaptiveFlywheel(
        rest_inertia=i - 4 * 1e-12 * 0.01**2,
        slider_mass=1e-12,
        spring_stiffness=1e12,
        slider_min=0.01,
        slider_max=0.02,
        name=name,
    )


@dataclass(frozen=True, kw_only=True)
class MetalFlywheelGeometry:
    """Metal disk of Table 3.1; inertia by (3.1)-(3.5).

    All lengths [m], masses [kg], stiffness [N/m].
    """

    hole_radius: float = 0.01  # r_m
    outer_radius: float = 0.047  # R_m
    slot_length: float = 0.03  # a_m
    slot_width: float = 0.02  # d_m (also the slider diameter)
    slider_length: float = 0.015  # l_sm
    spring_stiffness: float = 90.0  # k_sm
    slider_mass: float = 0.035  # m_sm
    disk_mass: float = 1.0  # m_fm (including the slot material)
    slot_mass: float = 0.079  # m_om, removed material of one slot
    slider_min: float = 0.0225
    slider_max: float = 0.0375

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            check_positive(f.name, getattr(self, f.name))
        if self.hole_radius >= self.outer_radius:
            raise ParameterError(
                "hole_radius", self.hole_radius, f"< outer_radius={self.outer_radius}"
            )
        if self.slider_max >= self.outer_radius:
            raise ParameterError(
                "slider_max", self.slider_max, f"< outer_radius={self.outer_radius}"
            )

    def rest_inertia(self) -> float:
        """Constant part of (3.3) [kg m^2]: disk (3.4) - 4 slots (3.5) + 4 slider self-inertias (3.1)."""
        disk = 0.5 * self.disk_mass * (self.hole_radius**2 + self.outer_radius**2)
        slot = (
            self.slot_mass / 12.0 * (self.slot_width**2 + self.slot_length**2)
            + self.slot_mass * (self.outer_radius - 0.5 * self.slot_length) ** 2
        )
        slider = self.slider_mass / 12.0 * (0.75 * self.slot_width**2 + self.slider_length**2)
        return disk - 4.0 * slot + 4.0 * slider


@dataclass(frozen=True, kw_only=True)
class NylonFlywheelGeometry:
    """Nylon (PA66) disk of Table 3.3 / 5.4; inertia by (3.19)-(3.24).

    (3.21) and (3.22) already hold all four slots and holes, (3.23) all four sliders.
    All lengths [m], masses [kg], density [kg/m^3], stiffness [N/m].
    """

    outer_radius: float = 0.05  # R_n
    thickness: float = 0.022  # T_n
    hole_distance: float = 0.0375  # L_n
    inner_radius: float = 0.01  # r_1n
    hole_radius: float = 0.0085  # r_2n
    slot_diameter: float = 0.017  # d_1n
    slot_length: float = 0.035  # l_1n
    slider_radius: float = 0.008  # r_3n
    slider_length: float = 0.015  # l_2n
    slider_mass: float = 0.0237  # m_sn
    density: float = 1150.0  # rho (PA66)
    spring_stiffness: float = 120.0  # k_sn
    solid_spring_length: float = 0.0045

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            check_positive(f.name, getattr(self, f.name))
        if self.inner_radius >= self.outer_radius:
            raise ParameterError(
                "inner_radius", self.inner_radius, f"< outer_radius={self.outer_radius}"
            )
        if self.slot_length >= self.outer_radius:
            raise ParameterError(
                "slot_length", self.slot_length, f"< outer_radius={self.outer_radius}"
            )
        if self.slider_max() <= self.slider_min():
            raise ParameterError(
                "solid_spring_length",
                self.solid_spring_length,
                "a length leaving the slider room to travel (l_max > l_min)",
            )

    def slider_min(self) -> float:
        """l_min [m] = slot inner end + half slider length."""
        return self.outer_radius - self.slot_length + 0.5 * self.slider_length

    def slider_max(self) -> float:
        """l_max [m] = outer radius - half slider length - solid spring length."""
        return self.outer_radius - 0.5 * self.slider_length - self.solid_spring_length

    def rest_inertia(self) -> float:
        """Constant part of (3.24): disk - slots - holes + slider self-inertia [kg m^2]."""
        rho, R, r1 = self.density, self.outer_radius, self.inner_radius
        disk_mass = rho * math.pi * (R**2 - r1**2) * self.thickness  # (3.20)
        disk = 0.5 * disk_mass * (R**2 + r1**2)  # (3.19)
        m_slot = math.pi * self.slot_diameter**2 / 4.0 * self.slot_length * rho  # (3.21)
        slots = (
            m_slot / 3.0 * (0.75 * self.slot_diameter**2 + self.slot_length**2)
            + 4.0 * m_slot * (R - 0.5 * self.slot_length) ** 2
        )
        m_hole = math.pi * self.hole_radius**2 * rho * self.thickness  # (3.22)
        holes = 2.0 * m_hole * self.hole_radius**2 + 4.0 * m_hole * self.hole_distance**2
        sliders = (
            self.slider_mass / 3.0 * (3.0 * self.slider_radius**2 + self.slider_length**2)
        )  # (3.23)
        return disk - slots - holes + sliders


NYLON_LARGE_GEOMETRY = NylonFlywheelGeometry(
    outer_radius=0.075,
    thickness=0.033,
    hole_distance=0.056,
    inner_radius=0.01,
    hole_radius=0.013,
    slot_diameter=0.025,
    slot_length=0.053,
    slider_radius=0.012,
    slider_length=0.022,
    slider_mass=0.078,
    density=1150.0,
    spring_stiffness=120.0,
)  # Table 5.4


def flywheel(preset: str = "nylon", *, law: str = "published", changing_ratio: float | None = None):
    """Build a thesis flywheel.

    Parameters
    ----------
    preset : {"metal", "nylon", "nylon-large"}
        ``metal`` is Table 3.1, ``nylon`` Table 3.3, ``nylon-large`` the rectifier
        device's flywheel of Table 5.4. For ``nylon-large`` the slider travel comes from
        the geometry: l_min = slot inner end + half slider length, l_max = outer radius -
        half slider length - a solid spring length of 4.5 mm (the value that gives the
        nylon preset's published l_max = 0.038 m).
    law : {"published", "geometry", "thesis-literal"}
        ``published`` uses the printed laws (3.6) and (3.25); ``geometry`` computes the
        constant from (3.1)-(3.5) or (3.19)-(3.24) (for metal this gives 8.03e-4, not the
        printed 8.83e-4; see inerterlab/data/errata.md); ``thesis-literal`` is the published law with
        l in place of l^2, as printed in ch. 7 (7.2)-(7.7). ``nylon-large`` has no
        published law, so ``published`` means ``geometry`` there.
    changing_ratio : float, optional
        If given, the variant with this changing ratio (see
        :meth:`AdaptiveFlywheel.with_changing_ratio`).

    Examples
    --------
    >>> round(flywheel("metal").changing_ratio, 4)
    0.1167
    >>> round(flywheel("nylon", law="geometry").rest_inertia, 7)
    0.0001752
    """
    check_choice("preset", preset, FLYWHEEL_PRESETS)
    check_choice("law", law, INERTIA_LAWS)
    power = 1 if law == "thesis-literal" else 2
    if preset == "metal":
        g = MetalFlywheelGeometry()
        rest = g.rest_inertia() if law == "geometry" else 8.83e-4  # (3.6)
        fw = AdaptiveFlywheel(
            rest_inertia=rest,
            slider_mass=g.slider_mass,
            spring_stiffness=g.spring_stiffness,
            slider_min=g.slider_min,
            slider_max=g.slider_max,
            power=power,
            name="metal",
        )
    elif preset == "nylon":
        g = NylonFlywheelGeometry()
        rest = g.rest_inertia() if law == "geometry" else 1.75e-4  # (3.25)
        fw = AdaptiveFlywheel(
            rest_inertia=rest,
            slider_mass=g.slider_mass,
            spring_stiffness=g.spring_stiffness,
            slider_min=0.0225,
            slider_max=0.038,
            power=power,
            name="nylon",
        )
    else:
        g = NYLON_LARGE_GEOMETRY
        fw = AdaptiveFlywheel(
            rest_inertia=g.rest_inertia(),
            slider_mass=g.slider_mass,
            spring_stiffness=g.spring_stiffness,
            slider_min=g.slider_min(),
            slider_max=g.slider_max(),
            power=power,
            name="nylon-large",
        )
    if changing_ratio is not None:
        fw = fw.with_changing_ratio(changing_ratio)
    return fw


def size_spring(
    *, slider_mass: float, slider_min: float, slider_max: float, design_speed: float
) -> float:
    """Spring stiffness k_s [N/m] that puts the sliders on the stop at ``design_speed``.

    (3.39): k_s = l_max m_s omega^2 / (l_max - l_min). ``design_speed`` is the flywheel
    speed [rad/s]; for a terminal velocity v [m/s] through a transmission of ratio r
    [rad/m] pass ``r * v`` ((3.40)).

    Examples
    --------
    >>> k = size_spring(slider_mass=0.035, slider_min=0.0225, slider_max=0.0375,
    ...                 design_speed=32.0713)
    >>> round(k, 1)
    90.0
    """
    m = check_positive("slider_mass", slider_mass, "kg")
    a = check_positive("slider_min", slider_min, "m")
    b = check_positive("slider_max", slider_max, "m")
    w = check_positive("design_speed", design_speed, "rad/s")
    if a >= b:
        raise ParameterError("slider_min", slider_min, f"a radius < slider_max={slider_max} m")
    return b * m * w * w / (b - a)
