"""One-way clutch: a rectified shaft drives an adaptive flywheel through a free-wheel
(thesis ch. 5.3, the rectifier device's motor).

The shaft turns at r |v| [rad/s] for either sign of the relative velocity v (the
rectifier), the flywheel at omega_f, its own state. The clutch is

* engaged while the shaft drives the flywheel: omega_f = r |v|, the force is that of the
  adaptive-flywheel inerter (:mod:`.adaptive_flywheel`, ``thesis`` or ``momentum`` law)
  plus the bearing drag seen through the shaft, F = m_e(v) v' + c_d r^2 v;
* free while the flywheel overruns the shaft (omega_f > r |v|): no force, and the
  flywheel slows down under its bearing drag (:func:`.bearing_drag.drag_torque`),
  J omega_f' = -c_d omega_f (J = I(omega_f), or I + omega dI/domega for ``momentum``).

Switching functions (the integrator locates their zeros): engaged, the torque the
clutch passes, s F with s = sgn v (it disengages where that would turn negative, the
flywheel having to be braked); free, r |v| - omega_f (it engages where the shaft catches
up). Where the element is a network's only inertance at a node, that node is massless
while the clutch is free; the model core then takes its velocity from the force balance
of the node (:mod:`inerterlab.systems._kernel`).

For small motions about rest there is no linearisation: without drag the flywheel is
spun to r times the largest speed and then runs free, an open circuit, which is what the
linear analyses see (:meth:`OneWayClutch.rest_network`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numba as nb

from ..errors import ParameterError
from ._base import Param
from .adaptive_flywheel import AdaptiveFlywheelInerter, flywheel_inertance, inertia_law
from .bearing_drag import drag_torque

__all__ = ["OneWayClutch", "clutch_engaged", "clutch_rate", "clutch_switch", "CLUTCH"]

#: variant code of the one-way clutch in the flywheel row (row[14]); row[15] = c_d
CLUTCH = 2.0
#: relative overrun below which the clutch counts as engaged when no side is held
ENGAGE_RTOL = 1e-10


@nb.njit(cache=True, inline="always")
def clutch_engaged(tab, o, v, wf, side):
    """True if engaged: ``side`` > 0 engaged, < 0 free (the mode the integrator holds),
    0 from the state (omega_f not above r |v|)."""
    if side != 0.0:
        return side > 0.0
    w = abs(tab[o + 1] * v)
    return wf - w <= ENGAGE_RTOL * max(wf, w)


@nb.njit(cache=True, inline="always")
def clutch_force(tab, o, v, engaged):
    """(m_e [kg], force other than m_e v' [N]) of the clutch: the flywheel inerter and
    the bearing drag through the shaft when engaged, nothing when free."""
    if not engaged:
        return 0.0, 0.0
    me, _ = flywheel_inertance(tab, o, v, 0.0, 0.0)
    r = tab[o + 1]
    return me, r * drag_torque(tab[o + 15], r * v)


@nb.njit(cache=True, inline="always")
def clutch_rate(tab, o, v, a, wf, engaged):
    """omega_f' [rad/s^2]: r sgn(v) v' engaged, -c_d omega_f / J free."""
    r = tab[o + 1]
    if engaged:
        return r * a if v >= 0.0 else -r * a
    i0, i1, _ = inertia_law(
        wf, tab[o + 2], tab[o + 3], tab[o + 4], tab[o + 5], tab[o + 6], tab[o + 7], tab[o + 8],
        int(tab[o + 9]),
    )  # fmt: skip
    j = i0 if tab[o] == 0.0 else i0 + wf * i1
    return -drag_torque(tab[o + 15], wf) / j


@nb.njit(cache=True, inline="always")
def clutch_switch(tab, o, v, force, wf, engaged):
    """Engaged: the torque passed, sgn(v) F [N], raised by 1e-9 (|F| + 1 N) so that the
    instant of engagement, where F may be zero to round-off, counts as engaged; free:
    r |v| - omega_f [rad/s]."""
    if engaged:
        return (force if v >= 0.0 else -force) + 1e-9 * (abs(force) + 1.0)
    return abs(tab[o + 1] * v) - wf


@dataclass(frozen=True, kw_only=True)
class OneWayClutch(AdaptiveFlywheelInerter):
    """Adaptive flywheel behind a rectifier and a one-way clutch, with bearing ``drag``
    c_d [N m s/rad] >= 0; the other parameters as :class:`AdaptiveFlywheelInerter`
    (``law`` ``thesis`` or ``momentum``)."""

    drag: float = 0.0

    prefix = "owc"
    description = "flywheel behind a one-way clutch"
    PARAMETERS = (
        *AdaptiveFlywheelInerter.PARAMETERS,
        Param("drag", "N m s/rad", low_open=False),
    )
    EXAMPLE = {"drag": 2e-3}

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "drag", float(self.PARAMETERS[5].check(self.drag)))
        if self.law == "slider-dynamics":
            raise ParameterError(
                "law", self.law, "'thesis' or 'momentum' behind a one-way clutch"
            )

    def row(self):
        r = super().row()
        r[14] = CLUTCH
        r[15] = self.drag
        return r

    @property
    def internal_states(self):
        return ("flywheel_speed",)

    def initial_internal_state(self):
        return (0.0,)

    def scaled(self, factor):
        base = super().scaled(factor)
        return dataclasses.replace(base, drag=self.drag * factor)

    def linear_regime(self):
        return None

    def rest_network(self):
        """None: an open circuit (see the module notes)."""
        return None
