"""One-degree-of-freedom templates in implicit form: a body on a spring, a damper and an
adaptive-flywheel inerter over a moving base (thesis (7.1), chapter 7) and the Duffing
oscillator.

Each is a scalar residual r(tau, x, x', x'') = 0 of the phase tau = Omega t with its
exact partial derivatives dr/dx, dr/dx', dr/dx'' (:func:`residual_partials`), the form
the harmonic balance balances exactly (the flywheel's effective mass changes within a
cycle, so balancing x'' = -r/m instead would move the amplitudes at the level of the
truncation). On the states (x, v) the template gives:

``terms``
    r_0 = x' - v, r_1 = r(tau, x, v, v') and their partials at every phase sample
    (``TERMS_SIGNATURE`` of :mod:`inerterlab.frequency.first_order`);
``rhs``
    x' = v, v' = -r(tau, x, v, 0) / (dr/dx'') (r is affine in x''), for time integration
    (``RHS_SIGNATURE``).

The flywheel's inertia law is the elements' own
(:func:`inerterlab.elements.adaptive_flywheel.inertia_law`); the chapter-7 body is the
core's ``base_excited(M, "k | c | afw")`` (tests/test_frequency_ch7.py holds the two to
the same accelerations).

System codes and parameter vectors ``p`` (``float_table``; ``int_table`` = [code]):

0 Duffing, m x'' + c x' + k x + g x^3 = P cos(tau): p = [m, c, k, g, P]
1 body over a moving base X0 = B sin(tau), (7.1):
  p = [M, K, C, B, ratio, I_rest, coef, k_s, m_s, l_min, l_max, omega_sat, power,
       law (0 thesis, 1 momentum), has_inerter (0/1)]
"""

from __future__ import annotations

import math

from numba import njit

from .._views import borrow
from ..elements.adaptive_flywheel import inertia_law
from ._kernel import road_layout

__all__ = ["DUFFING", "BASE_EXCITED", "residual_partials", "terms", "rhs"]

DUFFING, BASE_EXCITED = 0, 1
#: where the frequency is in the road vector ``rhs`` reads (one road, no held sides):
#: the core's one layout (:func:`inerterlab.systems._kernel.road_layout`)
FREQ_SLOT = road_layout(1, 0)[1]


@njit(cache=True, inline="always")
def residual_partials(sys_id, p, tau, omega, x0, x0d, x0dd, x, xd, xdd):
    """Residual r and its partials dr/dx, dr/dx', dr/dx'' at one time sample.

    ``sys_id`` 0: Duffing, p = [m, c, k, g, P]; 1: body over a moving base with an
    adaptive-flywheel inerter, (7.1), with the base's displacement, velocity and
    acceleration x0, x0', x0''.
    """
    if sys_id == DUFFING:
        m, c, k, g, force = p[0], p[1], p[2], p[3], p[4]
        r = m * xdd + c * xd + k * x + g * x * x * x - force * math.cos(tau)
        return r, k + 3.0 * g * x * x, c, m
    # body over a moving base with an adaptive-flywheel inerter, (7.1)
    body, stiff, damp = p[0], p[1], p[2]
    v = xd - x0d
    a = xdd - x0dd
    me = 0.0
    dme = 0.0
    if p[14] > 0.5:
        ratio = p[4]
        w = ratio * abs(v)
        i0, i1, i2 = inertia_law(w, p[5], p[6], p[7], p[8], p[9], p[10], p[11], int(p[12]))
        if p[13] < 0.5:  # thesis law F = r^2 I(r|v|) v'
            j0 = i0
            j1 = i1
        else:  # momentum law F = r^2 (I + w dI/dw) v'
            j0 = i0 + w * i1
            j1 = 2.0 * i1 + w * i2
        me = ratio * ratio * j0
        sg = 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)
        dme = ratio * ratio * ratio * j1 * sg
    r = body * xdd + me * a + stiff * (x - x0) + damp * v
    return r, stiff, damp + dme * a, body + me


@njit(cache=True)
def terms(tau, omega, amp, xs, xds, itab, ftab, r, P, Q, partials):
    """The implicit form on (x, v): r_0 = x' - v, r_1 = r(tau, x, v, v') with (when
    ``partials``) their partials, at every sample; the base moves as amp sin(tau)."""
    sys_id = itab[0]
    p = borrow(ftab)  # no reference counting per sample
    for k in range(tau.shape[0]):
        s = math.sin(tau[k])
        r[0, k] = xds[0, k] - xs[1, k]
        r1, g0, g1, g2 = residual_partials(
            sys_id, p, tau[k], omega, amp * s, amp * omega * math.cos(tau[k]),
            -amp * omega * omega * s, xs[0, k], xs[1, k], xds[1, k],
        )  # fmt: skip
        r[1, k] = r1
        if not partials:
            continue
        P[0, 0, k] = 0.0
        P[0, 1, k] = -1.0
        Q[0, 0, k] = 1.0
        Q[0, 1, k] = 0.0
        P[1, 0, k] = g0
        P[1, 1, k] = g1
        Q[1, 0, k] = 0.0
        Q[1, 1, k] = g2
    return True


@njit(cache=True)
def rhs(t, y, road, itab, ftab, out):
    """x' = v, v' = -r(tau, x, v, 0) / (dr/dx'') (r is affine in x''), tau = Omega t;
    ``road`` = [X0, X0', X0'', Omega] (Omega at :data:`FREQ_SLOT`)."""
    omega = road[FREQ_SLOT]
    r0, _, _, m = residual_partials(
        itab[0], ftab, omega * t, omega, road[0], road[1], road[2], y[0], y[1], 0.0
    )
    out[0] = y[1]
    out[1] = -r0 / m
    return True
