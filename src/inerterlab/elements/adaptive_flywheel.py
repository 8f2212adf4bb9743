"""Adaptive-flywheel inerter: a transmission of ratio r [rad/m] driving a flywheel whose
inertia I(omega) grows with speed (docs/model.md §1-§2).

The inertia law and its derivatives are written here once, as compiled functions:

    l(w) = k_s l_min / (k_s - m_s w^2) for w < w_sat, l_max above     (3.9)
    I(w) = I_rest + coef l(w)^power                                     (3.2), (3.6), (3.25)

with coef = n m_s (``power`` 2; 1 only for the misprinted ``thesis-literal`` law).

Force laws (docs/model.md §2), v the relative velocity, w = r|v|:

* ``thesis``: F = m_e dv/dt with m_e = r^2 I(w);
* ``momentum``: m_e = r^2 (I + w dI/dw);
* ``slider-dynamics``: the slider radius l and its rate are states,
  m_e = r^2 (I_rest + coef l^2) and F = m_e dv/dt + 2 coef r^2 l l' v.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numba as nb
import numpy as np

from ..errors import ParameterError
from ..flywheels import FLYWHEEL_PRESETS, INERTIA_LAWS, AdaptiveFlywheel
from ..flywheels import flywheel as make_flywheel
from ..slider_dynamics import SliderDynamics, slider_state_derivative
from ..transmissions import FORCE_LAWS
from ..transmissions import hydraulic as hydraulic_transmission
from ._base import FLYWHEEL, NO_GAUSSIAN_EQUIVALENT, NPAR, ElementBase, KernelLaw, Param

__all__ = [
    "AdaptiveFlywheelInerter",
    "FlywheelLaw",
    "inertia_law",
    "flywheel_inertance",
    "flywheel_switch",
    "flywheel_inertance_side",
    "factor_inertance",
    "slider_derivative",
]

LAW_CODES = {"thesis": 0.0, "momentum": 1.0, "slider-dynamics": 2.0}


@nb.njit(cache=True, error_model="numpy", inline="always")
def inertia_law(w, i_rest, coef, k_s, m_s, l_min, l_max, w_sat, power):
    """I, dI/dw, d2I/dw2 at speed w >= 0 [rad/s] for I = I_rest + coef l(w)^power."""
    if w < w_sat:
        d = k_s - m_s * w * w
        l = k_s * l_min / d
        l1 = 2.0 * k_s * l_min * m_s * w / (d * d)
        l2 = 2.0 * k_s * l_min * m_s / (d * d) + 8.0 * k_s * l_min * m_s * m_s * w * w / (d * d * d)
    else:
        l = l_max
        l1 = 0.0
        l2 = 0.0
    if power == 1:
        return i_rest + coef * l, coef * l1, coef * l2
    return i_rest + coef * l * l, 2.0 * coef * l * l1, 2.0 * coef * (l1 * l1 + l * l2)


# row layout: law, r, I_rest, coef, k_s, m_s, l_min, l_max, w_sat, power, n, c_s, k_c, c_c
@nb.njit(cache=True, error_model="numpy", inline="always")
def flywheel_inertance(tab, o, v, l, ld):
    """(m_e [kg], extra force g [N]) at relative velocity v of the row starting at
    ``tab[o]``; l, l' the slider states (used by ``slider-dynamics`` only). The row is
    read in place (a table and an offset, not a slice: a slice per call costs a view)."""
    r = tab[o + 1]
    if tab[o] == 2.0:
        me = r * r * (tab[o + 2] + tab[o + 3] * l * l)
        return me, 2.0 * tab[o + 3] * r * r * l * ld * v
    w = abs(r * v)
    i0, i1, _ = inertia_law(
        w, tab[o + 2], tab[o + 3], tab[o + 4], tab[o + 5], tab[o + 6], tab[o + 7], tab[o + 8],
        int(tab[o + 9]),
    )  # fmt: skip
    if tab[o] == 0.0:
        return r * r * i0, 0.0
    return r * r * (i0 + w * i1), 0.0


@nb.njit(cache=True, error_model="numpy", inline="always")
def flywheel_inertance_side(tab, o, v, side):
    """m_e [kg] of the thesis or momentum law on one side of the saturation kink,
    continued smoothly past it: ``side`` > 0 the sliders on their stops (r^2 I_max),
    < 0 the law below saturation, at any speed. An integration step that crosses the
    kink, taken on the law of the side it starts on, has an honest error estimate and a
    continuous extension on which the crossing is found."""
    r = tab[o + 1]
    w = abs(r * v)
    i0, i1, _ = inertia_law(
        w, tab[o + 2], tab[o + 3], tab[o + 4], tab[o + 5], tab[o + 6], tab[o + 7],
        -math.inf if side > 0.0 else math.inf, int(tab[o + 9]),
    )  # fmt: skip
    if tab[o] == 0.0:
        return r * r * i0
    return r * r * (i0 + w * i1)


def factor_inertance(tab, o) -> float:
    """The inertance [kg] a mass matrix factored beforehand takes for the row starting
    at ``tab[o]`` (:func:`inerterlab.systems._kernel.dense_tables`): with the thesis and
    momentum laws the sliders on their stops, r^2 I_max, where the flywheel sits once it
    turns fast enough (the excess over the factor is then exactly 0, and the solve for
    it is skipped); with ``slider-dynamics``, whose sliders never rest on a stop, its
    least, at rest. The same operations as the laws above, so the two agree to the
    last bit on the stops."""
    if tab[o] == 2.0:
        return float(tab[o + 1] ** 2 * (tab[o + 2] + tab[o + 3] * tab[o + 6] ** int(tab[o + 9])))
    return float(flywheel_inertance_side(tab, o, 0.0, 1.0))


@nb.njit(cache=True, inline="always")
def flywheel_switch(tab, o, v):
    """Switching function at relative velocity v [m/s]: r |v| - w_sat [rad/s], changing
    sign where the sliders reach their stops and the inertia law has a kink (thesis
    and momentum laws); 1 (never) for ``slider-dynamics``, whose law is smooth in the
    states."""
    if tab[o] == 2.0:
        return 1.0
    return abs(tab[o + 1] * v) - tab[o + 8]


@nb.njit(cache=True, error_model="numpy")
def slider_derivative(tab, o, l, ld, v):
    """l'' [m/s^2] of the sliders at relative velocity v (``slider-dynamics``)."""
    ldd, _ = slider_state_derivative(
        l, ld, tab[o + 1] * v, tab[o + 10], tab[o + 5], tab[o + 4], tab[o + 6], tab[o + 7], tab[o + 11],
        tab[o + 12], tab[o + 13],
    )
    return ldd


class FlywheelLaw(KernelLaw):
    """The adaptive-flywheel row (force m_e(v) a, laws ``thesis`` and ``momentum``):
    b_eq = E[m_e(v)] (v and a independent in a stationary response, so E[m_e(v) a^2] /
    E[a^2] = E[m_e(v)]), the quadrature split at the saturation speed; the equivalent a
    row of constant inertance b_eq. Sliders with dynamics, a one-way clutch and a ball
    screw's contact rule (states or contact rules of their own) have none."""

    code = FLYWHEEL
    argument = "acceleration"
    inertial = True

    @classmethod
    def nominal_inertance(cls, element) -> float:
        """Its least inertance (the sliders at rest)."""
        return element.inertance_min

    @classmethod
    def gaussian_refusal(cls, row, description: str) -> tuple[str, str] | None:
        from ._inertial import CLUTCH, GATED

        if row[14] in (CLUTCH, GATED) or row[0] == 2.0:
            return description, NO_GAUSSIAN_EQUIVALENT
        return None

    @classmethod
    def gaussian_gain(cls, row, sigma: float, expect) -> float:
        if sigma <= 0.0:
            return float(flywheel_inertance(row, 0, 0.0, 0.0, 0.0)[0])
        sat = row[8] / row[1] if row[1] else 0.0  # the saturation's relative speed
        return expect(lambda v: flywheel_inertance(row, 0, v, 0.0, 0.0)[0], sigma, (sat, -sat))

    @classmethod
    def gaussian_row(cls, row, gain: float) -> np.ndarray:
        """No slider term, I_rest = b_eq / r^2."""
        out = np.zeros(NPAR)
        out[:] = row
        out[0] = 0.0
        out[2] = gain / (row[1] * row[1])
        out[3] = 0.0
        return out


@dataclass(frozen=True, kw_only=True)
class AdaptiveFlywheelInerter(ElementBase):
    """Ideal device (no losses) with an adaptive flywheel.

    Parameters
    ----------
    flywheel : str or AdaptiveFlywheel
        Preset ``metal``, ``nylon`` (default) or ``nylon-large``, or a flywheel object.
    inertia_law : {"published", "geometry", "thesis-literal"}
        Law of a preset (docs/model.md §1).
    changing_ratio : float, optional
        The variant with this changing ratio x in (0, 1).
    ratio : float
        Transmission ratio r [rad/m] (default the hydraulic device's, 961.66).
    law : {"thesis", "momentum", "slider-dynamics"}
        How the speed-dependent inertia makes a force.
    slider : SliderDynamics
        Options of ``slider-dynamics``.
    """

    flywheel: str | AdaptiveFlywheel = "nylon"
    inertia_law: str = "published"
    changing_ratio: float | None = None
    ratio: float = field(default_factory=lambda: hydraulic_transmission().ratio)
    law: str = "thesis"
    slider: SliderDynamics = field(default_factory=SliderDynamics)

    prefix = "afw"
    description = "adaptive-flywheel inerter"
    PARAMETERS = (
        Param("flywheel", choices=FLYWHEEL_PRESETS),
        Param("inertia_law", choices=INERTIA_LAWS),
        Param("changing_ratio", "", 0.0, 1.0, optional=True),
        Param("ratio", "rad/m", design=(50.0, 5000.0)),
        Param("law", choices=FORCE_LAWS),
    )
    ROLE = "inertial"
    EXAMPLE = {}
    code = FLYWHEEL
    is_linear = False

    def scaled(self, factor):
        """``factor`` flywheels at the same speed: one with every inertia (rest, sliders)
        times ``factor``."""
        fw = self._fw
        fw = replace(
            fw,
            rest_inertia=fw.rest_inertia * factor,
            slider_mass=fw.slider_mass * factor,
            spring_stiffness=fw.spring_stiffness * factor,
        )
        return replace(self, flywheel=fw, changing_ratio=None)

    def rest_network(self):
        """An ideal inerter of the inertance at rest r^2 I_min (every force law: the
        speed-dependent part and the slider force are of second order about rest)."""
        return "b", {"b": self.inertance_min}

    def linear_regime(self):
        """Above the saturation speed (r |v| >= w_sat) the sliders rest on their stops:
        under the thesis and momentum laws the device is an ideal inerter of r^2 I_max
        there (the law's dI/dw is 0). None for ``slider-dynamics`` (smooth in its own
        states, no such region)."""
        if self.law == "slider-dynamics":
            return None
        from .inerter import Inerter

        row = self.row()
        me = row[1] ** 2 * (row[2] + row[3] * row[7] ** int(row[9]))
        return Inerter(inertance=float(me)), "velocity", float(row[8] / abs(row[1]))

    def __post_init__(self) -> None:
        if isinstance(self.flywheel, AdaptiveFlywheel):
            fw = self.flywheel
        else:
            self.PARAMETERS[0].check(self.flywheel)
            self.PARAMETERS[1].check(self.inertia_law)
            fw = make_flywheel(self.flywheel, law=self.inertia_law)
        if self.changing_ratio is not None:
            x = self.PARAMETERS[2].check(self.changing_ratio)
            if x >= 1.0:
                raise ParameterError("changing_ratio", self.changing_ratio, "a number in (0, 1)")
            fw = fw.with_changing_ratio(x)
        object.__setattr__(self, "ratio", float(self.PARAMETERS[3].check(self.ratio)))
        self.PARAMETERS[4].check(self.law)
        if not isinstance(self.slider, SliderDynamics):
            raise ParameterError("slider", self.slider, "a SliderDynamics")
        if self.law == "slider-dynamics" and fw.power != 2:
            raise ParameterError("law", self.law, "'thesis' or 'momentum' for a power-1 flywheel")
        object.__setattr__(self, "_fw", fw)

    @property
    def wheel(self) -> AdaptiveFlywheel:
        """The flywheel actually used (preset and changing ratio applied)."""
        return self._fw

    @property
    def inertance_min(self) -> float:
        """r^2 I_min [kg], the inertance at rest."""
        return self.ratio**2 * self._fw.inertia_min

    def row(self):
        fw = self._fw
        cs = kc = cc = 0.0
        if self.law == "slider-dynamics":
            co = self.slider.coefficients(fw)
            cs, kc, cc = co[6], co[7], co[8]
        return self._row(
            LAW_CODES[self.law], self.ratio, fw.rest_inertia, fw.inertia_coefficient,
            fw.spring_stiffness, fw.slider_mass, fw.slider_min, fw.slider_max,
            fw.saturation_speed, float(fw.power), float(fw.n_sliders), cs, kc, cc,
        )  # fmt: skip

    @property
    def internal_states(self):
        return ("slider_radius", "slider_rate") if self.law == "slider-dynamics" else ()

    def initial_internal_state(self):
        return (self._fw.slider_min, 0.0) if self.law == "slider-dynamics" else ()
