"""The compiled law of every flywheel-row element, for the system right-hand side.

An element of kernel code FLYWHEEL packs the adaptive flywheel's row (laws and
inertia, :mod:`.adaptive_flywheel`) and a variant in row[14]: 0 the flywheel inerter,
:data:`.screw_backlash.GATED` the ball screw's contact rule, :data:`.one_way_clutch.CLUTCH`
the one-way clutch. The core's kernel asks this module only, so it never looks at a
variant.
"""

from __future__ import annotations

import math

import numba as nb

from .adaptive_flywheel import (
    flywheel_inertance,
    flywheel_inertance_side,
    flywheel_switch,
    slider_derivative,
)
from .one_way_clutch import CLUTCH, clutch_engaged, clutch_force, clutch_rate, clutch_switch
from .screw_backlash import GATED, contact_argument, in_contact

__all__ = ["inertial_law", "inertial_rate", "inertial_switch", "inertial_switch_reads_force"]


@nb.njit(cache=True, inline="always")
def inertial_law(tab, o, xr, v, x, so, dx, side):
    """(m_e [kg], force other than m_e a [N]) at relative displacement ``xr`` [m] and
    velocity ``v`` [m/s]; ``x`` the state, ``so`` the offset of the element's own states
    (-1 for none), ``side`` the side of its kink the integrator holds (0 for none).
    Writes the own states' rates that do not need the acceleration into ``dx``."""
    variant = tab[o + 14]
    if variant == CLUTCH:
        return clutch_force(tab, o, v, clutch_engaged(tab, o, v, x[so], side))
    f = 0.0
    if so >= 0:  # slider-dynamics: the slider radius and rate are states
        me, f = flywheel_inertance(tab, o, v, x[so], x[so + 1])
        dx[so] = x[so + 1]
        dx[so + 1] = slider_derivative(tab, o, x[so], x[so + 1], v)
    elif side != 0.0 and variant == 0.0:  # held on one side of its saturation kink
        me = flywheel_inertance_side(tab, o, v, side)
    else:
        me, f = flywheel_inertance(tab, o, v, 0.0, 0.0)
    if variant == GATED and not in_contact(tab, o, xr, v, side):
        return 0.0, 0.0
    return me, f


@nb.njit(cache=True, inline="always")
def inertial_rate(tab, o, v, a, x, so, side):
    """Rate of an own state that needs the relative acceleration ``a`` [m/s^2] (the
    clutch's flywheel speed), or NaN where the element has none."""
    if tab[o + 14] != CLUTCH:
        return math.nan
    return clutch_rate(tab, o, v, a, x[so], clutch_engaged(tab, o, v, x[so], side))


@nb.njit(cache=True, inline="always")
def inertial_switch_reads_force(tab, o):
    """Whether :func:`inertial_switch` reads the element's force (the clutch's torque),
    which needs the whole right-hand side; the others read the relative motion only."""
    return tab[o + 14] == CLUTCH


@nb.njit(cache=True, inline="always")
def inertial_switch(tab, o, xr, v, force, x, so, side):
    """(g, g0, argument, kind): the switching function at the state (a flywheel's
    saturation, the screw's contact, the clutch's torque or overrun), its value at rest,
    its argument and how it is read: 0 none, 1 even in its argument (two signed halves,
    see :func:`inerterlab.systems._kernel.switches`), 2 signed as it is."""
    variant = tab[o + 14]
    if variant == CLUTCH:
        eng = clutch_engaged(tab, o, v, x[so], side)
        return clutch_switch(tab, o, v, force, x[so], eng), 0.0, 0.0, 2
    if variant == GATED:
        a = contact_argument(tab, o, xr, v)
        return abs(a) - tab[o + 15], -tab[o + 15], a, 1
    if tab[o] == 2.0:
        return 1.0, 1.0, v, 0
    return flywheel_switch(tab, o, v), flywheel_switch(tab, o, 0.0), v, 1
