"""Compiled quarter-car kernels: right-hand side, road-jump impulse, Dormand-Prince 5(4),
exact steps through the linear phases.

Everything here is a numba function of plain floats and arrays, laid out by the
``P_*`` indices of :mod:`.model`. The integrator is an adaptive explicit Runge-Kutta
pair of Dormand and Prince (order 5 with an embedded order-4 error estimate, FSAL),
the step-size control of Hairer, Norsett and Wanner (Solving ODEs I, II.4, the PI
controller of DOPRI5 with beta = 0.04) and DOPRI5's order-4 continuous extension for
sampled output and peak refinement. Why this is hand-written and not taken from a
library: docs/decisions.md, "Quarter-car simulation backend".

The metric integrals (int a^2, int grip^2, int z^2, int a_w^2, int a_w^4) and the
8 states of the Wk filter are carried in the state vector, so no dense output is needed
for the RMS values, the VDV or the weighted acceleration. The last Wk section, the
100 Hz low pass (poles at 628 rad/s), would set the step size (accuracy under a sine,
the explicit stability limit h ~ 5 ms once the car settles): it is taken out of the
Runge-Kutta stages and advanced exactly after each accepted step, driven by the
continuous extension of its input (a quartic in theta): polynomial particular solution
plus the 2x2 matrix exponential, with int a_w^2 and int a_w^4 by 5-point Gauss-Legendre
quadrature. Kinks (saturation speed, tyre lift-off) end steps, see :func:`integrate`;
an attempt follows the inertia law on the side of the saturation kink it starts on,
continued smoothly past it, so a crossing attempt has an honest error estimate and a
continuous extension that places the crossing. Peaks of a3, a_w, z and the tyre force
are taken at every step end and at the step midpoint, and where a parabola through
those three values puts a larger maximum inside the step it is located by successive
parabolic interpolation on the continuous extension.

Where the car is linear (no inerter, a constant one, or a saturated flywheel under the
thesis or momentum law) the integrator takes exact steps of the matrix exponential
instead (section "Exact steps through the linear phases" below).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..slider_dynamics import slider_state_derivative
from .model import (
    P_BAH,
    P_BRANCH,
    P_C,
    P_CC,
    P_CS,
    P_CT,
    P_FFH,
    P_GRIP,
    P_ICOEF,
    P_IM,
    P_IMT,
    P_IREST,
    P_K,
    P_KC,
    P_KH,
    P_KIND,
    P_KS,
    P_KSLMIN,
    P_KT,
    P_LAW,
    P_LIFT,
    P_LMAX,
    P_LMIN,
    P_M,
    P_MS,
    P_MT,
    P_MU,
    P_NPHYS,
    P_NSL,
    P_POW,
    P_R,
    P_R2,
    P_VEPS,
    P_W,
    P_WSAT,
)

# Every helper below works in place on arrays it is handed and allocates nothing, so
# it is compiled without numba's reference counting: with it, each call from the
# integrator paid an atomic increment and decrement per array argument, about 40 ns
# per call of the right-hand side (decisions.md, "Quarter-car simulation speed")
leaf = nb.njit(cache=True, _nrt=False)

N_PEAKS = 7  # a3, -a3, a_w, -a_w, z, -z, tyre force K_t (X2-X1) + C_t (V2-X1')

# Dormand-Prince 5(4) tableau
C2, C3, C4, C5 = 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0
A21 = 1.0 / 5.0
A31, A32 = 3.0 / 40.0, 9.0 / 40.0
A41, A42, A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
A51, A52, A53, A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
A61, A62, A63, A64, A65 = (
    9017.0 / 3168.0,
    -355.0 / 33.0,
    46732.0 / 5247.0,
    49.0 / 176.0,
    -5103.0 / 18656.0,
)
B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0
E1, E3, E4, E5, E6, E7 = (
    71.0 / 57600.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
)
D1, D3, D4, D5, D6, D7 = (
    -12715105075.0 / 11282082432.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
)

# status codes of integrate()
OK, TOO_MANY_STEPS, STEP_TOO_SMALL, NOT_FINITE = 0, 1, 2, 3


@leaf
def road(seg, t):
    """X1 [m] and X1' [m/s] on segment ``seg`` at time t."""
    if seg[2] == 0.0:
        return seg[3] + seg[4] * (t - seg[0]), seg[4]
    arg = seg[6] * t + seg[7]
    return seg[3] + seg[5] * math.sin(arg), seg[5] * seg[6] * math.cos(arg)


@leaf
def _slider_radius(p, w):
    w = abs(w)
    if w < p[P_WSAT]:
        return p[P_KS] * p[P_LMIN] / (p[P_KS] - p[P_MS] * w * w)
    return p[P_LMAX]


@leaf
def inertia(p, w):
    """I(|w|) [kg m^2] of the packed flywheel."""
    l = _slider_radius(p, w)
    if p[P_POW] == 2.0:
        return p[P_IREST] + p[P_ICOEF] * l * l
    return p[P_IREST] + p[P_ICOEF] * l


@leaf
def momentum_inertia(p, w):
    """I + |w| dI/d|w| [kg m^2]."""
    return _branch_inertia(p, w, True, -1.0)


@leaf
def _slider_primitive(p, a):
    """int_0^a l(s)^power ds for 0 <= a <= w_sat (closed form of (3.9))."""
    k, m, lmin = p[P_KS], p[P_MS], p[P_LMIN]
    al2 = k / m
    al = math.sqrt(al2)
    c = k * lmin / m
    lg = math.log((al + a) / (al - a))
    if p[P_POW] == 2.0:
        return c * c * (a / (2.0 * al2 * (al2 - a * a)) + lg / (4.0 * al2 * al))
    return c * lg / (2.0 * al)


@leaf
def inertia_integral(p, w):
    """H(w) = int_0^w I(|s|) ds [kg m^2 rad/s], odd in w."""
    a = abs(w)
    ws = p[P_WSAT]
    if a <= ws:
        h = p[P_IREST] * a + p[P_ICOEF] * _slider_primitive(p, a)
    else:
        h = p[P_IREST] * ws + p[P_ICOEF] * _slider_primitive(p, ws) + inertia(p, ws) * (a - ws)
    return h if w >= 0.0 else -h


@leaf
def _law_inertia(p, w, momentum):
    """:func:`_branch_inertia` on the side of the kink set in p[P_BRANCH]."""
    return _branch_inertia(p, w, momentum, p[P_BRANCH])


@leaf
def _branch_inertia(p, w, momentum, br):
    """I(|w|) or, with ``momentum``, I + |w| dI/d|w| [kg m^2] on the side of the
    saturation kink chosen by ``br`` (0 below, 1 above, -1 where |w| is). Below, the
    slider formula is continued past w_sat (its pole kept away), so that a step that
    crosses the kink integrates a smooth right-hand side and its continuous extension
    places the crossing accurately."""
    w = abs(w)
    if br == 1.0 or (br < 0.0 and w >= p[P_WSAT]):
        return inertia(p, p[P_WSAT])
    k, m, a = p[P_KS], p[P_MS], p[P_LMIN]
    d = k - m * w * w
    if w >= p[P_WSAT] and d < 0.1 * k:
        d = 0.1 * k
    l = k * a / d
    if p[P_POW] == 2.0:
        i = p[P_IREST] + p[P_ICOEF] * l * l
    else:
        i = p[P_IREST] + p[P_ICOEF] * l
    if not momentum:
        return i
    dl = 2.0 * k * a * m * w / (d * d)
    if p[P_POW] == 2.0:
        di = p[P_ICOEF] * 2.0 * l * dl
    else:
        di = p[P_ICOEF] * dl
    return i + w * di


@leaf
def _inertance(p, v, y, j0):
    """(m_e [kg], extra force g [N]) of the inertia law at branch velocity v [m/s]."""
    r = p[P_R]
    law = p[P_LAW]
    if law == 0.0:
        return r * r * _law_inertia(p, r * v, False), 0.0
    if law == 1.0:
        return r * r * _law_inertia(p, r * v, True), 0.0
    if law == 2.0:
        l, ld = y[j0], y[j0 + 1]
        return r * r * (p[P_IREST] + p[P_ICOEF] * l * l), 2.0 * p[P_ICOEF] * r * r * l * ld * v
    return r * r * p[P_IREST], 0.0


@leaf
def branch_velocity(force, b, ff, eps):
    """u solving b u + F tanh(u/eps) = force (safeguarded Newton, to round-off)."""
    lo = (force - ff) / b
    hi = (force + ff) / b
    u = force / (b + ff / eps)
    if u < lo or u > hi:
        u = 0.5 * (lo + hi)
    for _ in range(200):
        th = math.tanh(u / eps)
        g = b * u + ff * th - force
        if g > 0.0:
            hi = u
        elif g < 0.0:
            lo = u
        else:
            return u
        dg = b + ff / eps * (1.0 - th * th)
        un = u - g / dg
        if not (lo <= un <= hi):
            un = 0.5 * (lo + hi)
        if abs(un - u) <= 2e-16 * abs(un) + 1e-300 or hi - lo <= 4e-16 * abs(u):
            return un
        u = un
    return u


@leaf
def rhs(t, y, dy, p, seg, wk):
    """Write f(t, y) into dy; return the body acceleration a3 [m/s^2]."""
    return _rhs(t, y, dy, p, seg, wk, True)


@leaf
def _rhs(t, y, dy, p, seg, wk, low_pass):
    """f(t, y); with ``low_pass=False`` the last Wk section (the 100 Hz low pass) and the
    integrals of a_w^2, a_w^4 get zero derivatives: :func:`integrate` advances them
    exactly after each step (:func:`_lp_setup`)."""
    x1, v1 = road(seg, t)
    return _rhs_road(x1, v1, y, dy, p, wk, low_pass)


@leaf
def _stage_roads(seg, t, h, tn, rx, rv):
    """Road X1, X1' at the Dormand-Prince stage times t + (C2, C3, C4, C5) h and at tn
    -> rx[0:5], rv[0:5]. On a sine segment one sine and cosine at t and the stages by
    the addition theorem, with the short rotations by their Taylor series (a few
    ulps; the sine and cosine of every stage cost a fifth of the right-hand side)."""
    if seg[2] == 0.0:
        for i in range(5):
            ts = tn if i == 4 else t + (C2, C3, C4, C5)[i] * h
            rx[i] = seg[3] + seg[4] * (ts - seg[0])
            rv[i] = seg[4]
        return
    w = seg[6]
    arg = w * t + seg[7]
    sa = math.sin(arg)
    ca = math.cos(arg)
    for i in range(5):
        d = w * ((tn - t) if i == 4 else (C2, C3, C4, C5)[i] * h)
        if abs(d) < 0.05:
            d2 = d * d
            sd = d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0 * (1.0 - d2 / 72.0))))
            cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0)))
        else:
            sd = math.sin(d)
            cd = math.cos(d)
        rx[i] = seg[3] + seg[5] * (sa * cd + ca * sd)
        rv[i] = seg[5] * w * (ca * cd - sa * sd)


@leaf
def _rhs_road(x1, v1, y, dy, p, wk, low_pass):
    """:func:`_rhs` with the road displacement x1 and velocity v1 given."""
    n = int(p[P_NPHYS])
    kind = p[P_KIND]
    x2, v2, x3, v3 = y[0], y[1], y[2], y[3]
    z = x3 - x2
    v = v3 - v2
    fs = p[P_K] * z + p[P_C] * v
    ft = p[P_KT] * (x2 - x1) + p[P_CT] * (v2 - v1)
    if p[P_LIFT] != 0.0 and ft > p[P_W]:
        ft = p[P_W]
    im, imt = p[P_IM], p[P_IMT]
    if kind == 0.0:
        a3 = -fs * im
        a2 = (fs - ft) * imt
    elif kind == 1.0:
        law = p[P_LAW]
        if law == 0.0:
            # the thesis law inline (the common case): m_e = r^2 I(r|v|)
            w = abs(p[P_R] * v)
            br = p[P_BRANCH]
            if br == 0.0 or (br < 0.0 and w < p[P_WSAT]):
                d = p[P_KS] - p[P_MS] * w * w
                if w >= p[P_WSAT] and d < 0.1 * p[P_KS]:
                    d = 0.1 * p[P_KS]  # the continuation past w_sat, see _law_inertia
                l = p[P_KSLMIN] / d
            else:
                l = p[P_LMAX]
            if p[P_POW] == 2.0:
                l = l * l
            me = p[P_R2] * (p[P_IREST] + p[P_ICOEF] * l)
            g = 0.0
        elif law == 3.0:
            me = p[P_R2] * p[P_IREST]
            g = 0.0
        else:
            me, g = _inertance(p, v, y, 4)
        mu = p[P_MU]
        arel = (ft * imt - (fs + g) * mu) / (1.0 + me * mu)
        fin = me * arel + g
        a3 = -(fs + fin) * im
        a2 = (fs + fin - ft) * imt
        if law == 2.0:
            ldd, _ = slider_state_derivative(
                y[4], y[5], p[P_R] * v, p[P_NSL], p[P_MS], p[P_KS], p[P_LMIN], p[P_LMAX],
                p[P_CS], p[P_KC], p[P_CC],
            )  # fmt: skip
            dy[4] = y[5]
            dy[5] = ldd
    elif kind == 2.0:
        fd = p[P_KH] * y[4]
        u = branch_velocity(fd, p[P_BAH], p[P_FFH], p[P_VEPS])
        dy[4] = v - u
        a3 = -(fs + fd) * im
        a2 = (fs + fd - ft) * imt
    else:
        fd = p[P_KH] * y[4]
        u = y[5]
        me, g = _inertance(p, u, y, 6)
        dy[4] = v - u
        dy[5] = (fd - p[P_BAH] * u - p[P_FFH] * math.tanh(u / p[P_VEPS]) - g) / me
        if p[P_LAW] == 2.0:
            ldd, _ = slider_state_derivative(
                y[6], y[7], p[P_R] * u, p[P_NSL], p[P_MS], p[P_KS], p[P_LMIN], p[P_LMAX],
                p[P_CS], p[P_KC], p[P_CC],
            )  # fmt: skip
            dy[6] = y[7]
            dy[7] = ldd
        a3 = -(fs + fd) * im
        a2 = (fs + fd - ft) * imt
    dy[0] = v2
    dy[1] = a2
    dy[2] = v3
    dy[3] = a3
    grip = p[P_GRIP] * (x2 - x1)
    # Wk filter: cascade of four second-order sections (metrics.wk_sections)
    u = a3
    nsec = 4 if low_pass else 3
    for s in range(nsec):
        i = n + 3 + 2 * s
        w0 = wk[s, 0]
        q1 = y[i]
        q2 = y[i + 1]
        dy[i] = w0 * q2
        dy[i + 1] = w0 * (u - q1) - wk[s, 1] * q2
        u = wk[s, 4] * u + wk[s, 2] * q1 + wk[s, 3] * q2
    dy[n] = a3 * a3
    dy[n + 1] = grip * grip
    dy[n + 2] = z * z
    if low_pass:
        aw2 = u * u
        dy[n + 11] = aw2
        dy[n + 12] = aw2 * aw2
    else:
        dy[n + 9] = 0.0
        dy[n + 10] = 0.0
        dy[n + 11] = 0.0
        dy[n + 12] = 0.0
    return a3


@leaf
def apply_jump(p, y, jump):
    """Apply in place the tyre-damper impulse C_t * jump of a road step [m]."""
    imp = p[P_CT] * jump
    if imp == 0.0 or (p[P_LIFT] != 0.0 and imp < 0.0):
        return
    M, Mt = p[P_M], p[P_MT]
    if p[P_KIND] != 1.0:
        y[1] += imp / Mt
        return
    v0 = y[3] - y[1]
    mu = 1.0 / M + 1.0 / Mt
    law = p[P_LAW]
    r = p[P_R]
    if law == 2.0 or law == 3.0:
        me, _ = _inertance(p, v0, y, 4)
        dv = -(imp / Mt) / (1.0 + mu * me)
        P = me * dv
    else:
        lo = min(v0, v0 - imp / Mt)
        hi = max(v0, v0 - imp / Mt)
        v1 = v0 - (imp / Mt) / (1.0 + mu * r * r * inertia(p, r * v0))
        P = 0.0
        for _ in range(200):
            if law == 0.0:
                P = r * (inertia_integral(p, r * v1) - inertia_integral(p, r * v0))
                dP = r * r * inertia(p, r * v1)
            else:
                P = r * r * (inertia(p, r * v1) * v1 - inertia(p, r * v0) * v0)
                dP = r * r * momentum_inertia(p, r * v1)
            g = v1 - v0 + imp / Mt + mu * P
            if g > 0.0:
                hi = v1
            elif g < 0.0:
                lo = v1
            else:
                break
            vn = v1 - g / (1.0 + mu * dP)
            if not (lo <= vn <= hi):
                vn = 0.5 * (lo + hi)
            if abs(vn - v1) <= 2e-16 * abs(vn) + 1e-300:
                v1 = vn
                break
            v1 = vn
        if law == 0.0:
            P = r * (inertia_integral(p, r * v1) - inertia_integral(p, r * v0))
        else:
            P = r * r * (inertia(p, r * v1) * v1 - inertia(p, r * v0) * v0)
    y[3] -= P / M
    y[1] += (imp + P) / Mt


@leaf
def _quantities(t, y, p, seg, wk, a3, q):
    n = int(p[P_NPHYS])
    aw = a3
    for s in range(4):
        i = n + 3 + 2 * s
        aw = wk[s, 4] * aw + wk[s, 2] * y[i] + wk[s, 3] * y[i + 1]
    z = y[2] - y[0]
    x1, v1 = road(seg, t)
    q[0] = a3
    q[1] = -a3
    q[2] = aw
    q[3] = -aw
    q[4] = z
    q[5] = -z
    q[6] = p[P_KT] * (y[0] - x1) + p[P_CT] * (y[1] - v1)


@leaf
def _switching(p, y, t, seg, sw_a, sw_b, v_sat):
    """Switching functions: |v| - v_sat (inertia law) and tyre force - static load."""
    g1 = 0.0
    if sw_a >= 0:
        v = y[sw_a] - (y[sw_b] if sw_b >= 0 else 0.0)
        g1 = abs(v) - v_sat
    g2 = 0.0
    if p[P_LIFT] != 0.0:
        x1, v1 = road(seg, t)
        g2 = p[P_KT] * (y[0] - x1) + p[P_CT] * (y[1] - v1) - p[P_W]
    return g1, g2


@leaf
def _dense_at(y, r2, r3, r4, r5, th, i):
    """Component i of the Dormand-Prince continuous extension at theta (see _dense)."""
    return y[i] + th * (r2[i] + (1.0 - th) * (r3[i] + th * (r4[i] + (1.0 - th) * r5[i])))


@leaf
def _switching_dense(p, y, r2, r3, r4, r5, th, t, seg, sw_a, sw_b, v_sat, which):
    """One switching function of :func:`_switching` on the continuous extension at
    theta, evaluating only the components it needs (the kink search calls it ~40
    times per crossing)."""
    if which == 0:
        v = _dense_at(y, r2, r3, r4, r5, th, sw_a)
        if sw_b >= 0:
            v -= _dense_at(y, r2, r3, r4, r5, th, sw_b)
        return abs(v) - v_sat
    x1, v1 = road(seg, t)
    x2 = _dense_at(y, r2, r3, r4, r5, th, 0)
    v2 = _dense_at(y, r2, r3, r4, r5, th, 1)
    return p[P_KT] * (x2 - x1) + p[P_CT] * (v2 - v1) - p[P_W]


@leaf
def _dense_coefficients(y, ynew, k1, k3, k4, k5, k6, k7, h, r2, r3, r4, r5):
    for i in range(y.size):
        yd = ynew[i] - y[i]
        bs = h * k1[i] - yd
        r2[i] = yd
        r3[i] = bs
        r4[i] = yd - h * k7[i] - bs
        r5[i] = h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i])


@leaf
def _dense(y, r2, r3, r4, r5, th, out):
    th1 = 1.0 - th
    for i in range(y.size):
        out[i] = y[i] + th * (r2[i] + th1 * (r3[i] + th * (r4[i] + th1 * r5[i])))


@leaf
def _err_norm(y, ynew, k1, k3, k4, k5, k6, k7, h, rtol, atol, nrk):
    """RMS over all y.size states of the scaled error; only the first ``nrk`` can be
    nonzero (the exact low pass and the a_w integrals are advanced outside the stages)."""
    s = 0.0
    for i in range(nrk):
        e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])
        sc = atol[i] + rtol * max(abs(y[i]), abs(ynew[i]))
        s += (e / sc) ** 2
    return math.sqrt(s / y.size)


@leaf
def _initial_step(t, y, f0, p, seg, wk, rtol, atol, span, ytmp, f1, order, low_pass):
    """Initial step of Hairer, Norsett and Wanner (II.4), as scipy's select_initial_step;
    ``order`` is the order of the error estimator."""
    d0 = 0.0
    d1 = 0.0
    for i in range(y.size):
        sc = atol[i] + rtol * abs(y[i])
        d0 += (y[i] / sc) ** 2
        d1 += (f0[i] / sc) ** 2
    d0 = math.sqrt(d0 / y.size)
    d1 = math.sqrt(d1 / y.size)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, span)
    for i in range(y.size):
        ytmp[i] = y[i] + h0 * f0[i]
    _rhs(t + h0, ytmp, f1, p, seg, wk, low_pass)
    d2 = 0.0
    for i in range(y.size):
        sc = atol[i] + rtol * abs(y[i])
        d2 += ((f1[i] - f0[i]) / sc) ** 2
    d2 = math.sqrt(d2 / y.size) / h0
    dm = max(d1, d2)
    h1 = max(1e-6, h0 * 1e-3) if dm <= 1e-15 else (0.01 / dm) ** (1.0 / (order + 1.0))
    return min(100.0 * h0, h1, span)


# 5-point Gauss-Legendre rule on [0, 1]
GL_X = np.array(
    [
        0.5 - 0.5 * 0.9061798459386640,
        0.5 - 0.5 * 0.5384693101056831,
        0.5,
        0.5 + 0.5 * 0.5384693101056831,
        0.5 + 0.5 * 0.9061798459386640,
    ]
)
GL_W = 0.5 * np.array(
    [0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
     0.2369268850561891]
)  # fmt: skip
# below this h * w0 the polynomial particular solution loses digits (1/(h w0)^4):
# such short steps advance the low pass with the Dormand-Prince stages instead
LP_EXACT_MIN = 0.05


@leaf
def _lp_input(y, yn, k1, k3, k4, k5, k6, k7, h, wk, n, lpw):
    """Input u(theta) of the low pass over the step as a quartic in theta -> lpw[1:6].

    u = c1 q1 + c2 q2 of the third Wk section (strictly proper), whose states follow
    the Dormand-Prince continuous extension y + th r2 + th (1-th) r3 + th^2 (1-th) r4
    + th^2 (1-th)^2 r5 (the same interpolant as :func:`_dense`).
    """
    for k in range(5):
        lpw[1 + k] = 0.0
    for j in range(2):
        i = n + 7 + j
        c = wk[2, 2 + j]
        r2 = yn[i] - y[i]
        r3 = h * k1[i] - r2
        r4 = r2 - h * k7[i] - r3
        r5 = h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i])
        lpw[1] += c * y[i]
        lpw[2] += c * (r2 + r3)
        lpw[3] += c * (-r3 + r4 + r5)
        lpw[4] += c * (-r4 - 2.0 * r5)
        lpw[5] += c * r5


@leaf
def _lp_input_r(y, r2, r3, r4, r5, wk, n, lpw):
    """:func:`_lp_input` from continuous-extension coefficients already at hand (a step
    cut by :func:`_truncate`)."""
    for k in range(5):
        lpw[1 + k] = 0.0
    for j in range(2):
        i = n + 7 + j
        c = wk[2, 2 + j]
        lpw[1] += c * y[i]
        lpw[2] += c * (r2[i] + r3[i])
        lpw[3] += c * (-r3[i] + r4[i] + r5[i])
        lpw[4] += c * (-r4[i] - 2.0 * r5[i])
        lpw[5] += c * r5[i]


@leaf
def _truncate(y, yn, r2, r3, r4, r5, th, nrk):
    """Cut a step at theta = th: yn <- the continuous extension there, and r2..r5 <- the
    extension over the cut step in its own theta (the quartic y(th phi) written again
    in the basis phi, phi (1-phi), phi^2 (1-phi), phi^2 (1-phi)^2), first nrk states."""
    t2 = th * th
    t3 = t2 * th
    t4 = t3 * th
    for i in range(nrk):
        a1 = (r2[i] + r3[i]) * th
        a2 = (-r3[i] + r4[i] + r5[i]) * t2
        a3 = (-r4[i] - 2.0 * r5[i]) * t3
        a4 = r5[i] * t4
        n5 = a4
        n4 = -a3 - 2.0 * a4
        n3 = n4 + n5 - a2
        r2[i] = a1 - n3
        r3[i] = n3
        r4[i] = n4
        r5[i] = n5
        yn[i] = y[i] + a1 + a2 + a3 + a4


@leaf
def _lp_u(lpw, th):
    return lpw[1] + th * (lpw[2] + th * (lpw[3] + th * (lpw[4] + th * lpw[5])))


@leaf
def _lp_setup(x1, x2, h, wk, lpw):
    """Advance the 100 Hz low pass q1' = w0 q2, q2' = w0 (u - q1) - a1 q2 over one step.

    With the input a quartic in theta (lpw[1:6]) the solution is exact: a polynomial
    particular solution P(theta) plus exp(theta h A) (x0 - P(0)). Very short steps
    (h w0 < LP_EXACT_MIN) use the Dormand-Prince stages on the two states instead.
    Returns (q1, q2, int a_w^2 dt, int a_w^4 dt) over the step; lpw keeps what
    :func:`_lp_at` needs for values inside the step.
    """
    w0, a1 = wk[3, 0], wk[3, 1]
    c1, c2, d = wk[3, 2], wk[3, 3], wk[3, 4]
    if h * w0 >= LP_EXACT_MIN:
        lpw[0] = 1.0
        # P_4 = (U_4, 0); P_k = A^-1 (k+1) P_{k+1} / h + (U_k, 0), A^-1 b = (-1, 0)
        px = lpw[5]
        py = 0.0
        lpw[10] = px
        lpw[15] = py
        for k in range(3, -1, -1):
            qx = (k + 1) * px / h
            qy = (k + 1) * py / h
            px = (-a1 * qx - w0 * qy) / (w0 * w0) + lpw[1 + k]
            py = qx / w0
            lpw[6 + k] = px
            lpw[11 + k] = py
        dx = x1 - lpw[6]
        dy = x2 - lpw[11]
        lpw[16] = dx
        lpw[17] = dy
        lpw[18] = h
        # exp(tau A) = exp(sig tau) (cos(wd tau) I + sin(wd tau)/wd (A - sig I)) at the
        # nodes: three evaluations, the others by the addition theorems
        sig = -0.5 * a1
        wd = math.sqrt(w0 * w0 - sig * sig)
        ev = lpw[20:26]
        cv = lpw[26:32]
        sv = lpw[32:38]
        for j in range(3):
            tau = GL_X[j] * h
            ev[j] = math.exp(sig * tau)
            cv[j] = math.cos(wd * tau)
            sv[j] = math.sin(wd * tau)
        e1 = ev[2] * ev[2]
        co1 = 2.0 * cv[2] * cv[2] - 1.0
        si1 = 2.0 * sv[2] * cv[2]
        for j in range(2):
            # ev[4 - j] = exp(sig (1 - x_j) h) <= ev[j]: zero where ev[j] underflowed (a
            # step of seconds, as on a flat road, where 0/0 would stop the run)
            ev[4 - j] = e1 / ev[j] if ev[j] > 0.0 else 0.0
            cv[4 - j] = co1 * cv[j] + si1 * sv[j]
            sv[4 - j] = si1 * cv[j] - co1 * sv[j]
        ev[5], cv[5], sv[5] = e1, co1, si1
        s2 = 0.0
        s4 = 0.0
        q1 = q2 = 0.0
        for j in range(6):
            th = GL_X[j] if j < 5 else 1.0
            sn = sv[j] / wd
            px = lpw[6] + th * (lpw[7] + th * (lpw[8] + th * (lpw[9] + th * lpw[10])))
            py = lpw[11] + th * (lpw[12] + th * (lpw[13] + th * (lpw[14] + th * lpw[15])))
            q1 = px + ev[j] * (cv[j] * dx + sn * (-sig * dx + w0 * dy))
            q2 = py + ev[j] * (cv[j] * dy + sn * (-w0 * dx + (-a1 - sig) * dy))
            if j < 5:
                aw = c1 * q1 + c2 * q2 + d * _lp_u(lpw, th)
                aw2 = aw * aw
                s2 += GL_W[j] * aw2
                s4 += GL_W[j] * aw2 * aw2
        return q1, q2, h * s2, h * s4
    # Dormand-Prince stages (the tableau of integrate) on the two states
    lpw[0] = 0.0
    lpw[18] = h
    cs = (0.0, C2, C3, C4, C5, 1.0)
    sx = lpw[20:26]
    sy = lpw[26:32]
    g2 = lpw[32:38]
    for st in range(6):
        xs, ys = x1, x2
        if st == 1:
            xs += h * A21 * sx[0]
            ys += h * A21 * sy[0]
        elif st == 2:
            xs += h * (A31 * sx[0] + A32 * sx[1])
            ys += h * (A31 * sy[0] + A32 * sy[1])
        elif st == 3:
            xs += h * (A41 * sx[0] + A42 * sx[1] + A43 * sx[2])
            ys += h * (A41 * sy[0] + A42 * sy[1] + A43 * sy[2])
        elif st == 4:
            xs += h * (A51 * sx[0] + A52 * sx[1] + A53 * sx[2] + A54 * sx[3])
            ys += h * (A51 * sy[0] + A52 * sy[1] + A53 * sy[2] + A54 * sy[3])
        elif st == 5:
            xs += h * (A61 * sx[0] + A62 * sx[1] + A63 * sx[2] + A64 * sx[3] + A65 * sx[4])
            ys += h * (A61 * sy[0] + A62 * sy[1] + A63 * sy[2] + A64 * sy[3] + A65 * sy[4])
        u = _lp_u(lpw, cs[st])
        sx[st] = w0 * ys
        sy[st] = w0 * (u - xs) - a1 * ys
        aw = c1 * xs + c2 * ys + d * u
        g2[st] = aw * aw
    xn = x1 + h * (B1 * sx[0] + B3 * sx[2] + B4 * sx[3] + B5 * sx[4] + B6 * sx[5])
    yn = x2 + h * (B1 * sy[0] + B3 * sy[2] + B4 * sy[3] + B5 * sy[4] + B6 * sy[5])
    i2 = h * (B1 * g2[0] + B3 * g2[2] + B4 * g2[3] + B5 * g2[4] + B6 * g2[5])
    i4 = h * (
        B1 * g2[0] ** 2 + B3 * g2[2] ** 2 + B4 * g2[3] ** 2 + B5 * g2[4] ** 2 + B6 * g2[5] ** 2
    )
    # cubic Hermite data for values inside the step
    lpw[6], lpw[7] = x1, x2
    lpw[8], lpw[9] = h * sx[0], h * sy[0]
    lpw[10], lpw[11] = xn, yn
    lpw[12] = h * w0 * yn
    lpw[13] = h * (w0 * (_lp_u(lpw, 1.0) - xn) - a1 * yn)
    return xn, yn, i2, i4


@leaf
def _lp_at(lpw, th, wk):
    """Low-pass states (q1, q2) at theta in [0, 1] of the step set up by _lp_setup."""
    if lpw[0] == 0.0:
        t2 = th * th
        t3 = t2 * th
        h00 = 2.0 * t3 - 3.0 * t2 + 1.0
        h10 = t3 - 2.0 * t2 + th
        h01 = -2.0 * t3 + 3.0 * t2
        h11 = t3 - t2
        return (
            h00 * lpw[6] + h10 * lpw[8] + h01 * lpw[10] + h11 * lpw[12],
            h00 * lpw[7] + h10 * lpw[9] + h01 * lpw[11] + h11 * lpw[13],
        )
    w0, a1 = wk[3, 0], wk[3, 1]
    sig = -0.5 * a1
    wd = math.sqrt(w0 * w0 - sig * sig)
    tau = th * lpw[18]
    e = math.exp(sig * tau)
    c = math.cos(wd * tau)
    sn = math.sin(wd * tau) / wd
    dx, dy = lpw[16], lpw[17]
    px = lpw[6] + th * (lpw[7] + th * (lpw[8] + th * (lpw[9] + th * lpw[10])))
    py = lpw[11] + th * (lpw[12] + th * (lpw[13] + th * (lpw[14] + th * lpw[15])))
    return (
        px + e * (c * dx + sn * (-sig * dx + w0 * dy)),
        py + e * (c * dy + sn * (-w0 * dx + (-a1 - sig) * dy)),
    )


@leaf
def _peak_probe(y, r2, r3, r4, r5, lpw, t, h, xv, yd, ks, p, seg, wk, i_lp, qt, j):
    """Quantity j of :func:`_quantities` at theta = xv on the continuous extension."""
    _dense(y, r2, r3, r4, r5, xv, yd)
    yd[i_lp], yd[i_lp + 1] = _lp_at(lpw, xv, wk)
    a3v = _rhs(t + xv * h, yd, ks, p, seg, wk, False)
    _quantities(t + xv * h, yd, p, seg, wk, a3v, qt)
    return qt[j]


@leaf
def _shrink_bracket(x_1, f_1, x_2, f_2, x_3, f_3, xv, fv):
    """The bracket x_1 < x_2 < x_3 of a maximum (f_2 largest) after a probe at xv."""
    if xv < x_2:
        if fv >= f_2:
            return x_1, f_1, xv, fv, x_2, f_2
        return xv, fv, x_2, f_2, x_3, f_3
    if fv >= f_2:
        return x_2, f_2, xv, fv, x_3, f_3
    return x_1, f_1, x_2, f_2, xv, fv


@leaf
def _refine_peak(
    y, r2, r3, r4, r5, lpw, t, h, yd, ks, p, seg, wk, i_lp, qt, j, fa, fm, fb, peaks,
):  # fmt: skip
    """Raise peaks[j] to the maximum of quantity j inside the step, bracketed by the
    values fa, fm, fb at theta = 0, 1/2, 1: successive parabolic interpolation, then
    golden-section steps, which finish corners (tyre lift-off) where the parabolas
    converge slowly. Returns the number of right-hand side calls."""
    x_1, x_2, x_3 = 0.0, 0.5, 1.0
    f_1, f_2, f_3 = fa, fm, fb
    nev = 0
    for _ in range(30):
        den = (x_2 - x_1) * (f_2 - f_3) - (x_2 - x_3) * (f_2 - f_1)
        if den == 0.0:
            break
        num = (x_2 - x_1) ** 2 * (f_2 - f_3) - (x_2 - x_3) ** 2 * (f_2 - f_1)
        xv = x_2 - 0.5 * num / den
        if not (x_1 < xv < x_3) or abs(xv - x_2) < 1e-9 or x_3 - x_1 <= 1e-9:
            break
        fv = _peak_probe(y, r2, r3, r4, r5, lpw, t, h, xv, yd, ks, p, seg, wk, i_lp, qt, j)
        nev += 1
        if fv > peaks[j]:
            peaks[j] = fv
        x_1, f_1, x_2, f_2, x_3, f_3 = _shrink_bracket(x_1, f_1, x_2, f_2, x_3, f_3, xv, fv)
    for _ in range(60):
        if x_3 - x_1 <= 1e-9:
            break
        if x_2 - x_1 > x_3 - x_2:
            xv = x_2 - 0.381966 * (x_2 - x_1)
        else:
            xv = x_2 + 0.381966 * (x_3 - x_2)
        fv = _peak_probe(y, r2, r3, r4, r5, lpw, t, h, xv, yd, ks, p, seg, wk, i_lp, qt, j)
        nev += 1
        if fv > peaks[j]:
            peaks[j] = fv
        x_1, f_1, x_2, f_2, x_3, f_3 = _shrink_bracket(x_1, f_1, x_2, f_2, x_3, f_3, xv, fv)
    return nev


@leaf
def _first_kink(p, y, yn, r2, r3, r4, r5, t, h, tn, seg, sw_a, sw_b, v_sat, lift):
    """(crossed, theta just past the first kink) of an attempted step.

    The switching functions are compared at the two ends; for the inertia law also the
    sign of the velocity: both ends saturated with v changing sign means |v| dipped
    below the saturation speed in between (a reversal inside one step). Crossings are
    then located by bisection on the continuous extension (coefficients r2..r5 set by
    the caller when this returns crossed)."""
    ga1, ga2 = _switching(p, y, t, seg, sw_a, sw_b, v_sat)
    gb1, gb2 = _switching(p, yn, tn, seg, sw_a, sw_b, v_sat)
    c1 = sw_a >= 0 and (ga1 > 0.0) != (gb1 > 0.0)
    rev = False
    if sw_a >= 0 and not c1 and ga1 > 0.0:
        va = y[sw_a] - (y[sw_b] if sw_b >= 0 else 0.0)
        vb = yn[sw_a] - (yn[sw_b] if sw_b >= 0 else 0.0)
        rev = (va > 0.0) != (vb > 0.0)
    c2 = lift and (ga2 > 0.0) != (gb2 > 0.0)
    return c1, rev, c2, ga1, ga2


@leaf
def _locate_kinks(p, y, r2, r3, r4, r5, t, h, seg, sw_a, sw_b, v_sat, c1, rev, c2, ga1, ga2):
    """Theta just past the first crossing found by :func:`_first_kink` (1.0 if none)."""
    best = 1.0
    hi1 = 1.0
    if rev:
        # the velocity's zero inside the step is below saturation: the first crossing
        # lies between the step start and it
        lo, hi = 0.0, 1.0
        va = y[sw_a] - (y[sw_b] if sw_b >= 0 else 0.0)
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            vm = _dense_at(y, r2, r3, r4, r5, mid, sw_a)
            if sw_b >= 0:
                vm -= _dense_at(y, r2, r3, r4, r5, mid, sw_b)
            if abs(vm) <= v_sat:
                hi = mid
                break
            if (vm > 0.0) == (va > 0.0):
                lo = mid
            else:
                hi = mid
            if hi - lo < 1e-12:
                break
        hi1 = hi
        c1 = True
    for which in range(2):
        if (which == 0 and not c1) or (which == 1 and not c2):
            continue
        lo = 0.0
        hi = hi1 if which == 0 else 1.0
        glo = ga1 if which == 0 else ga2
        ghi = _switching_dense(p, y, r2, r3, r4, r5, hi, t + hi * h, seg, sw_a, sw_b, v_sat, which)
        if (ghi > 0.0) == (glo > 0.0):
            # no sign change on the extension (a crossing seen only at the step ends)
            best = min(best, hi)
            continue
        # Illinois (modified regula falsi): superlinear, the bracket kept
        side = 0
        for _ in range(60):
            mid = hi - ghi * (hi - lo) / (ghi - glo)
            if not (lo < mid < hi):
                mid = 0.5 * (lo + hi)
            gm = _switching_dense(
                p, y, r2, r3, r4, r5, mid, t + mid * h, seg, sw_a, sw_b, v_sat, which
            )
            if (gm > 0.0) == (glo > 0.0):
                lo, glo = mid, gm
                if side == -1:
                    ghi *= 0.5
                side = -1
            else:
                hi, ghi = mid, gm
                if side == 1:
                    glo *= 0.5
                side = 1
            if hi - lo < 1e-12:
                break
        best = min(best, hi)
    return best


# ---------------------------------------------------------------------------------------
# Exact steps through the linear phases
#
# While the flywheel is saturated (``afw`` with the thesis or momentum law and
# |r v| >= w_sat), and always for ``traditional`` and ``cfw``, the quarter car with its
# Wk filter is a linear time-invariant system driven by the road, and every road
# segment (affine or offset sine) is itself the output of a small linear system. The
# state z = (x2, v2, x3, v3, 8 Wk states, road generator g) then obeys z' = M z exactly,
# and a step of length ``h`` is the matrix exponential exp(M h) applied to z: no
# truncation error, no step-size control.
#
# The road generator is g = (x_a, x_o, v_r) with road displacement x_a + x_o and road
# velocity v_r, and g' = (alpha v_r, (1 - alpha) v_r, -omega^2 x_o): alpha = 1, omega = 0
# for an affine segment and alpha = 0 for a sine of angular frequency omega. M thus
# depends on the segment only through (alpha, omega), and is set up once per distinct pair.
#
# Steps come in four lengths, 10, 5, 2.5 and 1.25 ms (levels 0-3). The outputs (relative
# velocity, body acceleration, Wk-weighted acceleration, deflection, grip, tyre force)
# at the start, the Gauss-Legendre nodes and the end of a step are rows r exp(M s)
# applied to z, precomputed once; the metric integrals are the Gauss-Legendre sums
# (12, 8, 8, 6 nodes: at most 1.3e-7 relative error on the fastest transient of the Wk
# filter, its 100 Hz section, raised to the fourth power, alone; 1e-11 on the metrics
# after a bump), the peaks the largest of those values, refined on the polynomial
# through them. A step is taken only when the relative velocity stays above the
# saturation speed (with a margin) at every point, so it never crosses the kink of the
# inertia law; the longest such step is taken, and if none is, the Dormand-Prince
# integrator below goes on. See docs/decisions.md, "Quarter-car simulation speed:
# exact steps through the linear phases".
#
# (In this file, not a module of its own: numba's cache of integrate() is keyed to this
# file only and would keep stale copies of helpers changed elsewhere.)
# ---------------------------------------------------------------------------------------

# dot products and matrix products may be reassociated (vectorised): round-off only
vleaf = nb.njit(cache=True, _nrt=False, fastmath={"reassoc", "contract"})

X_NZ = 15  # x2, v2, x3, v3, 8 Wk states, road generator (x_a, x_o, v_r)
X_NCAR = 4
X_IG = 12  # first generator index
# outputs
X_O_V, X_O_A3, X_O_AW, X_O_Z, X_O_GRIP, X_O_FT = 0, 1, 2, 3, 4, 5
X_NO = 6
#: the longest exact step [s] and the number of levels (halvings)
X_H_EXACT = 0.01
X_N_LEVELS = 4
X_FINE_AFTER_JUMP = 0.02  # [s] shortest exact steps after a body velocity jump
#: Gauss-Legendre nodes per level (10, 5, 2.5, 1.25 ms)
X_N_GAUSS = (12, 8, 8, 6)
X_N_POINTS_MAX = max(X_N_GAUSS) + 2
#: terms of the Taylor series of a row times exp(M r), |r| <= 0.625 ms (14 already
#: reach the round-off of the matrix exponential)
X_N_TAYLOR = 16
#: the relative velocity must exceed the saturation speed by this factor at every
#: point of an exact step
X_SAT_MARGIN = 1.1


def x_level_tables():
    """Per level: point positions in [0, 1] (start, Gauss nodes, end), quadrature
    weights (zero at start and end) and barycentric interpolation weights."""
    xs = np.zeros((X_N_LEVELS, X_N_POINTS_MAX))
    wq = np.zeros((X_N_LEVELS, X_N_POINTS_MAX))
    bw = np.zeros((X_N_LEVELS, X_N_POINTS_MAX))
    npts = np.zeros(X_N_LEVELS, dtype=np.int64)
    for lev, ng in enumerate(X_N_GAUSS):
        x, w = np.polynomial.legendre.leggauss(ng)
        pts = np.r_[0.0, 0.5 * (x + 1.0), 1.0]
        n = pts.size
        xs[lev, :n] = pts
        wq[lev, 1 : n - 1] = 0.5 * w
        for i in range(n):
            bw[lev, i] = 1.0 / np.prod(pts[i] - np.delete(pts, i))
        bw[lev, :n] /= np.max(np.abs(bw[lev, :n]))
        npts[lev] = n
    return xs, wq, bw, npts


X_XS, X_WQ, X_BW, X_NPTS = x_level_tables()


@leaf
def x_build_matrix(p, wk, me, alpha, omega, M, rows):
    """Fill M (X_NZ x X_NZ) and the output rows (X_NO x X_NZ) of the linear phase with
    effective inertance ``me`` [kg] (unused without an inerter)."""
    for i in range(X_NZ):
        for j in range(X_NZ):
            M[i, j] = 0.0
    for o in range(X_NO):
        for j in range(X_NZ):
            rows[o, j] = 0.0
    im, imt, mu = p[P_IM], p[P_IMT], p[P_MU]
    d = me / (1.0 + me * mu) if p[P_KIND] == 1.0 else 0.0
    cf = 1.0 - d * mu  # coefficient of fs in fs + f_inerter
    ct = d * imt  # coefficient of ft in fs + f_inerter
    # fs = K (x3 - x2) + C (v3 - v2); ft = KT (x2 - x_a - x_o) + CT (v2 - v_r)
    fs = rows[X_O_Z]  # scratch, set to the deflection row below
    ft = rows[X_O_FT]
    fs[0] = -p[P_K]
    fs[2] = p[P_K]
    fs[1] = -p[P_C]
    fs[3] = p[P_C]
    ft[0] = p[P_KT]
    ft[X_IG] = -p[P_KT]
    ft[X_IG + 1] = -p[P_KT]
    ft[1] = p[P_CT]
    ft[X_IG + 2] = -p[P_CT]
    for j in range(X_NZ):
        s = cf * fs[j] + ct * ft[j]
        M[3, j] = -im * s
        M[1, j] = imt * (s - ft[j])
        rows[X_O_A3, j] = M[3, j]
    M[0, 1] = 1.0
    M[2, 3] = 1.0
    # Wk: four second-order sections in cascade, input a3 (metrics.wk_sections)
    u = rows[X_O_AW]
    for j in range(X_NZ):
        u[j] = rows[X_O_A3, j]
    for s in range(4):
        i = X_NCAR + 2 * s
        w0 = wk[s, 0]
        M[i, i + 1] = w0
        for j in range(X_NZ):
            M[i + 1, j] = w0 * u[j]
        M[i + 1, i] -= w0
        M[i + 1, i + 1] -= wk[s, 1]
        for j in range(X_NZ):
            u[j] = wk[s, 4] * u[j]
        u[i] += wk[s, 2]
        u[i + 1] += wk[s, 3]
    # road generator
    M[X_IG, X_IG + 2] = alpha
    M[X_IG + 1, X_IG + 2] = 1.0 - alpha
    M[X_IG + 2, X_IG + 1] = -omega * omega
    # the remaining outputs
    for j in range(X_NZ):
        fs[j] = 0.0
    fs[0] = -1.0
    fs[2] = 1.0
    rows[X_O_V, 1] = -1.0
    rows[X_O_V, 3] = 1.0
    g = p[P_GRIP]
    rows[X_O_GRIP, 0] = g
    rows[X_O_GRIP, X_IG] = -g
    rows[X_O_GRIP, X_IG + 1] = -g


@nb.njit(cache=True)
def x_expm(A, h, out, w1):
    """out = exp(A h) by scaling and squaring of a Taylor series (A, out, w1 square)."""
    n = A.shape[0]
    norm = 0.0
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += abs(A[i, j])
        norm = max(norm, s)
    norm *= h
    sq = 0
    while norm > 0.25:
        norm *= 0.5
        sq += 1
    hs = h / 2.0**sq
    # Horner: I + As (I + As/2 (I + ... (I + As/K))), truncation below 0.25^15/15!
    for i in range(n):
        for j in range(n):
            out[i, j] = 1.0 if i == j else 0.0
    for k in range(14, 0, -1):
        c = hs / k
        np.dot(A, out, w1)
        for i in range(n):
            for j in range(n):
                out[i, j] = c * w1[i, j] + (1.0 if i == j else 0.0)
    for _ in range(sq):
        np.dot(out, out, w1)
        for i in range(n):
            for j in range(n):
                out[i, j] = w1[i, j]


@nb.njit(cache=True)
def x_setup(p, wk, me, alpha, omega, M, rows, E, P, RT, T, W, w1):
    """Build M and the rows; E[lev] = exp(M h_lev); RT[lev, k, i X_NO + o] = component k
    of rows[o] exp(M s_i) at the points s_i of each level. P (9 x X_NZ x X_NZ: exp(M k
    sigma)), T (X_N_TAYLOR x X_NO x X_NZ), W (X_NO x X_NZ) and w1 are work space."""
    x_build_matrix(p, wk, me, alpha, omega, M, rows)
    nb_ = 2 ** (X_N_LEVELS - 1)
    sig = X_H_EXACT / nb_  # the shortest step
    x_expm(M, sig, E[X_N_LEVELS - 1], w1)
    for lev in range(X_N_LEVELS - 2, -1, -1):
        np.dot(E[lev + 1], E[lev + 1], E[lev])
    # P[k] = exp(M k sigma), k = 0..8
    for i in range(X_NZ):
        for j in range(X_NZ):
            P[0, i, j] = 1.0 if i == j else 0.0
            P[1, i, j] = E[X_N_LEVELS - 1, i, j]
    for k in range(2, nb_ + 1):
        np.dot(P[k - 1], P[1], P[k])
    # Taylor coefficients rows[o] M^k / k!
    for o in range(X_NO):
        for j in range(X_NZ):
            T[0, o, j] = rows[o, j]
    for k in range(1, X_N_TAYLOR):
        np.dot(T[k - 1], M, T[k])
        T[k] /= k
    W2 = np.empty((X_NO, X_NZ))
    for lev in range(X_N_LEVELS):
        h = X_H_EXACT / 2.0**lev
        for ip in range(X_NPTS[lev]):
            s_pt = X_XS[lev, ip] * h
            # nearest multiple of sigma, then the Taylor series over |r| <= sigma / 2
            kk = int(s_pt / sig + 0.5)
            kk = min(max(kk, 0), nb_)
            r = s_pt - kk * sig
            W[:] = T[X_N_TAYLOR - 1]
            for k in range(X_N_TAYLOR - 2, -1, -1):
                for o in range(X_NO):
                    for j in range(X_NZ):
                        W[o, j] = T[k, o, j] + r * W[o, j]
            np.dot(W, P[kk], W2)
            for o in range(X_NO):
                c = ip * X_NO + o
                for j in range(X_NZ):
                    RT[lev, j, c] = W2[o, j]


@vleaf
def x_outputs(RT, lev, z, F):
    """F[i X_NO + o] = output o at point i of the level: RT[lev, :, i X_NO + o] . z."""
    nr = X_NPTS[lev] * X_NO
    for c in range(nr):
        F[c] = 0.0
    for k in range(X_NZ):
        zk = z[k]
        for c in range(nr):
            F[c] += RT[lev, k, c] * zk


@leaf
def x_saturated(F, lev, v_sat):
    """True when |v| >= X_SAT_MARGIN v_sat with one sign at every point of the step."""
    lim = X_SAT_MARGIN * v_sat
    pos = F[X_O_V] > 0.0
    for ip in range(X_NPTS[lev]):
        v = F[ip * X_NO + X_O_V]
        if (v > 0.0) != pos or abs(v) < lim:
            return False
    return True


@vleaf
def x_propagate(E, lev, z, zn):
    """zn = E[lev] z."""
    for i in range(X_NZ):
        s = 0.0
        for k in range(X_NZ):
            s += E[lev, i, k] * z[k]
        zn[i] = s


@leaf
def x_interp(F, o, lev, th):
    """Polynomial through the step's points of output o, at theta in [0, 1]
    (barycentric form)."""
    num = 0.0
    den = 0.0
    for ip in range(X_NPTS[lev]):
        d = th - X_XS[lev, ip]
        if d == 0.0:
            return F[ip * X_NO + o]
        c = X_BW[lev, ip] / d
        num += c * F[ip * X_NO + o]
        den += c
    return num / den


@leaf
def x_refine(F, o, sign, lev, ip, peak):
    """Largest value of sign * the polynomial of output o next to point ip, where the
    parabola through ip and its neighbours puts a maximum above ``peak``: successive
    parabolic interpolation, kept inside the bracket; else the value at ip."""
    npt = X_NPTS[lev]
    f_ip = sign * F[ip * X_NO + o]
    if ip == 0:
        i1, i2, i3 = 0, 1, 2
        lo, hi = X_XS[lev, 0], X_XS[lev, 1]
    elif ip == npt - 1:
        i1, i2, i3 = npt - 3, npt - 2, npt - 1
        lo, hi = X_XS[lev, npt - 2], X_XS[lev, npt - 1]
    else:
        i1, i2, i3 = ip - 1, ip, ip + 1
        lo, hi = X_XS[lev, ip - 1], X_XS[lev, ip + 1]
    x1, x2, x3 = X_XS[lev, i1], X_XS[lev, i2], X_XS[lev, i3]
    f1 = sign * F[i1 * X_NO + o]
    f2 = sign * F[i2 * X_NO + o]
    f3 = sign * F[i3 * X_NO + o]
    best = f_ip
    for it in range(12):
        d1 = x2 - x1
        d3 = x2 - x3
        p1 = d1 * (f2 - f3)
        p3 = d3 * (f2 - f1)
        den = p1 - p3
        if den == 0.0:
            break
        xv = x2 - 0.5 * (d1 * p1 - d3 * p3) / den
        if not (lo < xv < hi):
            break
        if it == 0:
            # the parabola's own maximum: nothing to gain unless it exceeds the peak
            # (the polynomial's maximum differs from it by far less than its height)
            a = ((f3 - f2) / (x3 - x2) - (f2 - f1) / (x2 - x1)) / (x3 - x1)
            if a >= 0.0:
                break
            top = f1 + (xv - x1) * ((f2 - f1) / (x2 - x1) + a * (xv - x2))
            if top <= peak:
                break
        fv = sign * x_interp(F, o, lev, xv)
        if fv > best:
            best = fv
        if abs(xv - x2) < 1e-13:
            break
        # keep three points around the best one
        if xv < x2:
            if fv > f2:
                x3, f3 = x2, f2
                x2, f2 = xv, fv
            else:
                x1, f1 = xv, fv
        else:
            if fv > f2:
                x1, f1 = x2, f2
                x2, f2 = xv, fv
            else:
                x3, f3 = xv, fv
    return best


@leaf
def _exact_metrics(F, lev, h, y, n, peaks, refine_peaks):
    """Metric integrals and peaks over one exact step of length h at level ``lev``
    from the outputs at its points."""
    s_a = 0.0
    s_g = 0.0
    s_z = 0.0
    s_w2 = 0.0
    s_w4 = 0.0
    npt = X_NPTS[lev]
    for j in range(1, npt - 1):
        w = X_WQ[lev, j]
        c = j * X_NO
        a = F[c + X_O_A3]
        g = F[c + X_O_GRIP]
        z = F[c + X_O_Z]
        aw2 = F[c + X_O_AW] * F[c + X_O_AW]
        s_a += w * a * a
        s_g += w * g * g
        s_z += w * z * z
        s_w2 += w * aw2
        s_w4 += w * aw2 * aw2
    y[n] += h * s_a
    y[n + 1] += h * s_g
    y[n + 2] += h * s_z
    y[n + 11] += h * s_w2
    y[n + 12] += h * s_w4
    for q in range(4):
        o = X_O_A3 if q == 0 else (X_O_AW if q == 1 else (X_O_Z if q == 2 else X_O_FT))
        jmax = 0
        jmin = 0
        fmax = F[o]
        fmin = fmax
        for j in range(1, npt):
            f = F[j * X_NO + o]
            if f > fmax:
                fmax, jmax = f, j
            elif f < fmin:
                fmin, jmin = f, j
        for side in range(1 if q == 3 else 2):
            k = 2 * q + side  # peaks: a3, -a3, a_w, -a_w, z, -z, tyre force
            fb = fmax if side == 0 else -fmin
            jb = jmax if side == 0 else jmin
            if fb > peaks[k]:
                peaks[k] = fb
            # a maximum between points exceeds the largest point value by about
            # (w delta)^2 / 8 of the amplitude: far below 1 %
            if refine_peaks and fb >= peaks[k] - 0.01 * abs(peaks[k]):
                f = x_refine(F, o, 1.0 if side == 0 else -1.0, lev, jb, peaks[k])
                if f > peaks[k]:
                    peaks[k] = f


def x_buffers(n_p, n_wk):
    """Empty buffers for :func:`integrate`'s exact-step set-up, to keep between calls:
    (xkey, M, rows, E, P, RT, T) for ``n_p`` packed parameters and a Wk table of
    ``n_wk`` values; xkey all NaN (matches no set-up)."""
    return (
        np.full(n_p + 3 + n_wk, np.nan),
        np.empty((X_NZ, X_NZ)),
        np.empty((X_NO, X_NZ)),
        np.empty((X_N_LEVELS, X_NZ, X_NZ)),
        np.empty((2 ** (X_N_LEVELS - 1) + 1, X_NZ, X_NZ)),
        np.empty((X_N_LEVELS, X_NZ, X_N_POINTS_MAX * X_NO)),
        np.empty((X_N_TAYLOR, X_NO, X_NZ)),
    )


@leaf
def _x_key_matches(xkey, p, me, alpha, omega, wk, n_p, n_wk):
    """Whether ``xkey`` is the key of (p but its branch slot, me, alpha, omega, wk)."""
    if xkey.size != n_p + 3 + n_wk:
        return False
    for i in range(n_p):
        if i != P_BRANCH and xkey[i] != p[i]:
            return False
    if xkey[n_p] != me or xkey[n_p + 1] != alpha or xkey[n_p + 2] != omega:
        return False
    c = n_p + 3
    for i in range(wk.shape[0]):
        for j in range(wk.shape[1]):
            if xkey[c] != wk[i, j]:
                return False
            c += 1
    return True


@leaf
def _x_key_store(xkey, p, me, alpha, omega, wk, n_p):
    for i in range(n_p):
        xkey[i] = p[i]
    xkey[P_BRANCH] = 0.0
    xkey[n_p] = me
    xkey[n_p + 1] = alpha
    xkey[n_p + 2] = omega
    c = n_p + 3
    for i in range(wk.shape[0]):
        for j in range(wk.shape[1]):
            xkey[c] = wk[i, j]
            c += 1


@nb.njit(cache=True)
def integrate(
    p, segs, y0, x1_initial, t_end, rtol, atol, wk, sample_times, out_y, out_a3,
    peaks, stats, jumps, jump_tol, refine_peaks, max_steps, exact,
    xkey, Mx, rows_x, E_x, P_x, R_x, T_x,
):  # fmt: skip
    """Integrate from t = 0 to ``t_end`` segment by segment; return a status code.

    ``y0`` (physical + metric states) is overwritten with the final state. Samples
    at ``sample_times`` (sorted) go to ``out_y``/``out_a3``; ``peaks`` (7 values,
    see ``N_PEAKS``) receives the maxima; ``stats`` = [steps, rejected, rhs calls,
    attempts redone to end on a kink, exact steps, steps ended on a kink, exact-step
    set-ups built]. A sample on
    a segment edge gets the value after the edge. ``exact``: take exact steps through
    the linear phases.

    A road difference between segments above ``jump_tol`` [m] is a step (below it,
    round-off). ``jumps`` (one value per segment) receives the jump of the body velocity V3 [m/s]
    at the segment's start, where the road steps and the inerter passes part of the
    tyre-damper impulse to the body. The body acceleration then holds a Dirac of that
    weight; the Wk filter, strictly proper, takes it as a jump of its states by its
    input vector times the velocity jump (section by section: B_s = [0, w0_s] times
    the direct gains of the sections before it), so a_w, int a_w^2 and int a_w^4 stay
    exact. int a3^2 and the peak of a3 are then not finite; the driver reports them so.

    ``xkey, Mx, rows_x, E_x, P_x, R_x, T_x`` hold the exact-step set-up
    (:func:`x_setup`) between calls (:func:`x_buffers`): ``xkey`` is what it was built
    from (p but its branch slot, m_e, the road's alpha and omega, the Wk sections), and
    it is rebuilt only when that differs, so a sweep computes it once per distinct
    linear system and road kind, not once per point.
    """
    n = y0.size
    # the key of the set-up the caller's buffers hold, before p's branch slot is used
    n_p = p.size
    n_wk = wk.size
    y = y0
    # a private copy: the integrator sets the inertia law's branch, P_BRANCH
    p = p.copy()
    p[P_BRANCH] = -1.0
    # the stages skip the last four states (100 Hz low pass, int a_w^2, int a_w^4):
    # their derivatives are zero there and they are set after each accepted step
    nrk = n - 4
    K = np.empty((7, n))
    k1 = K[0]
    k2 = K[1]
    k3 = K[2]
    k4 = K[3]
    k5 = K[4]
    k6 = K[5]
    k7 = K[6]
    R = np.empty((4, n))
    r2 = R[0]
    r3 = R[1]
    r4 = R[2]
    r5 = R[3]
    ks = np.empty(n)
    yt = np.empty(n)
    yn = np.empty(n)
    yd = np.empty(n)
    qa = np.empty(N_PEAKS)
    qb = np.empty(N_PEAKS)
    qm = np.empty(N_PEAKS)
    qt = np.empty(N_PEAKS)
    lpw = np.zeros(52)
    i_lp = y0.size - 4  # low-pass states, then int a_w^2, int a_w^4
    for j in range(N_PEAKS):
        peaks[j] = -np.inf
    ns = sample_times.size
    isamp = 0
    nsteps = 0
    nrej = 0
    nfev = 0
    nevents_redo = 0
    h = 0.0
    facold = 1e-4
    x_prev = x1_initial
    beta = 0.04
    expo1 = 0.2 - 0.75 * beta
    status = OK
    # switching surface of the inertia law: |r v| = w_sat, where dI/dw jumps. Steps
    # are shortened to end on it, so no step integrates across the kink.
    sw_a, sw_b = -1, -1
    if p[P_LAW] == 0.0 or p[P_LAW] == 1.0:
        if p[P_KIND] == 1.0:
            sw_a, sw_b = 3, 1
        elif p[P_KIND] == 3.0:
            sw_a, sw_b = 5, -1
    v_sat = p[P_WSAT] / p[P_R] if sw_a >= 0 else 0.0
    lift = p[P_LIFT] != 0.0  # the tyre force capped at the static load: another kink
    # exact steps through the linear phases (x_* helpers above): no inerter, a constant
    # one, or a saturated flywheel under the thesis or momentum law; not with lift-off
    exact_on = (
        exact
        and not lift
        and (
            p[P_KIND] == 0.0
            or (p[P_KIND] == 1.0 and (p[P_LAW] == 0.0 or p[P_LAW] == 1.0 or p[P_LAW] == 3.0))
        )
    )
    me_lin = 0.0
    if p[P_KIND] == 1.0:
        me_lin = p[P_R2] * (p[P_IREST] if p[P_LAW] == 3.0 else inertia(p, p[P_WSAT]))
    w1_x = np.empty((X_NZ, X_NZ))
    w2_x = np.empty((X_NO, X_NZ))
    z_x = np.empty(X_NZ)
    zn_x = np.empty(X_NZ)
    F_x = np.empty(X_N_POINTS_MAX * X_NO)
    need_k1 = False
    nexact = 0
    nkink_steps = 0
    nsetup = 0  # exact-step set-ups built by this call
    i_wk = n - 13 + 3
    n_phys = n - 13
    h_event = 0.0
    event_tries = 0
    rx = np.empty(5)  # road at the stage times (_stage_roads)
    rv = np.empty(5)
    h_side = np.zeros(2)  # last step-size proposal below / above the saturation speed
    natural_next = False
    fine_until = -1.0
    for iseg in range(segs.shape[0]):
        seg = segs[iseg]
        t0 = seg[0]
        t1 = min(seg[1], t_end)
        xs, _ = road(seg, t0)
        jump = xs - x_prev
        p[P_BRANCH] = -1.0
        jumps[iseg] = 0.0
        # a difference at round-off level between the end of one segment and the start
        # of the next (a ramp or half-cosine edge, a sampled road) is not a step
        if abs(jump) > jump_tol:
            v3_before = y[3]
            apply_jump(p, y, jump)
            dv3 = y[3] - v3_before
            jumps[iseg] = dv3
            if dv3 != 0.0:
                fine_until = t0 + X_FINE_AFTER_JUMP
                # the Dirac dv3 delta(t) in a3 drives the Wk cascade: each section's
                # second state jumps by w0 times the Dirac weight reaching it
                g = dv3
                for s in range(4):
                    y[i_wk + 2 * s + 1] += wk[s, 0] * g
                    g *= wk[s, 4]
        x_prev, _ = road(seg, t1)
        if t1 <= t0:
            continue
        t = t0
        a3a = _rhs(t, y, k1, p, seg, wk, False)
        nfev += 1
        need_k1 = False
        _quantities(t, y, p, seg, wk, a3a, qa)
        for j in range(N_PEAKS):
            if qa[j] > peaks[j]:
                peaks[j] = qa[j]
        while isamp < ns and sample_times[isamp] <= t0:
            for i in range(n):
                out_y[isamp, i] = y[i]
            out_a3[isamp] = a3a
            isamp += 1
        if h == 0.0:
            h = _initial_step(t, y, k1, p, seg, wk, rtol, atol, t1 - t0, yt, k2, 4.0, False)
            nfev += 1
        final = t1 >= t_end
        while t < t1:
            if exact_on and (sw_a < 0 or abs(y[3] - y[1]) >= X_SAT_MARGIN * v_sat):
                # the longest step that ends before the segment end and the next sample
                t_lim = t1 - 1e-12 * max(1.0, abs(t1))
                if isamp < ns:
                    t_lim = min(t_lim, sample_times[isamp] - 1e-12 * max(1.0, abs(t1)))
                # just after a body velocity jump the Wk filter rings fast (its 12.5 and
                # 100 Hz sections): shortest exact steps there, so the Gauss-Legendre
                # sums of a_w^2 and a_w^4 stay exact to round-off
                lev = X_N_LEVELS - 2 if t < fine_until else 0
                while lev < X_N_LEVELS and t + X_H_EXACT / 2.0**lev > t_lim:
                    lev += 1
            else:
                lev = X_N_LEVELS
            if lev < X_N_LEVELS:
                alpha = 1.0 if seg[2] == 0.0 else 0.0
                omega = 0.0 if seg[2] == 0.0 else seg[6]
                if not _x_key_matches(xkey, p, me_lin, alpha, omega, wk, n_p, n_wk):
                    xkey[n_p] = np.nan  # no valid set-up until the key is stored
                    x_setup(p, wk, me_lin, alpha, omega, Mx, rows_x, E_x, P_x, R_x, T_x, w2_x, w1_x)
                    _x_key_store(xkey, p, me_lin, alpha, omega, wk, n_p)
                    nsetup += 1
                for i in range(4):
                    z_x[i] = y[i]
                for i in range(8):
                    z_x[4 + i] = y[i_wk + i]
                if seg[2] == 0.0:
                    z_x[X_IG] = seg[3] + seg[4] * (t - seg[0])
                    z_x[X_IG + 1] = 0.0
                    z_x[X_IG + 2] = seg[4]
                else:
                    arg = seg[6] * t + seg[7]
                    z_x[X_IG] = seg[3]
                    z_x[X_IG + 1] = seg[5] * math.sin(arg)
                    z_x[X_IG + 2] = seg[5] * seg[6] * math.cos(arg)
                # the longest step that stays saturated throughout
                while lev < X_N_LEVELS:
                    x_outputs(R_x, lev, z_x, F_x)
                    if sw_a < 0 or x_saturated(F_x, lev, v_sat):
                        break
                    lev += 1
                if lev < X_N_LEVELS:
                    h_lev = X_H_EXACT / 2.0**lev
                    _exact_metrics(F_x, lev, h_lev, y, n_phys, peaks, refine_peaks)
                    x_propagate(E_x, lev, z_x, zn_x)
                    for i in range(4):
                        y[i] = zn_x[i]
                    for i in range(8):
                        y[i_wk + i] = zn_x[4 + i]
                    t = t + h_lev
                    nsteps += 1
                    nexact += 1
                    need_k1 = True
                    je = X_NPTS[lev] - 1
                    qa[0] = F_x[je * X_NO + X_O_A3]
                    qa[1] = -qa[0]
                    qa[2] = F_x[je * X_NO + X_O_AW]
                    qa[3] = -qa[2]
                    qa[4] = F_x[je * X_NO + X_O_Z]
                    qa[5] = -qa[4]
                    qa[6] = F_x[je * X_NO + X_O_FT]
                    if nsteps >= max_steps:
                        status = TOO_MANY_STEPS
                        break
                    continue
            if sw_a >= 0:
                # each attempt follows the inertia law on the side of the kink it starts
                # on, continued smoothly past it: a step that crosses then has a smooth
                # right-hand side, an honest error estimate and a continuous extension
                # that places the crossing (the step is then cut there, below)
                vv = y[sw_a] - (y[sw_b] if sw_b >= 0 else 0.0)
                brn = 1.0 if abs(vv) > v_sat else 0.0
                if natural_next:
                    brn = -1.0
                    natural_next = False
                if brn != p[P_BRANCH]:
                    p[P_BRANCH] = brn
                    need_k1 = True
            if need_k1:
                _rhs(t, y, k1, p, seg, wk, False)
                nfev += 1
                need_k1 = False
            h_prop = h
            last = False
            event_step = False
            if h_event > 0.0:
                h = h_event
                h_event = 0.0
                event_step = True
            elif t + h >= t1 - 1e-13 * max(1.0, abs(t1)):
                h = t1 - t
                last = True
            tn = t1 if last else t + h
            _stage_roads(seg, t, h, tn, rx, rv)
            for i in range(nrk):
                yt[i] = y[i] + h * A21 * k1[i]
            _rhs_road(rx[0], rv[0], yt, k2, p, wk, False)
            for i in range(nrk):
                yt[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i])
            _rhs_road(rx[1], rv[1], yt, k3, p, wk, False)
            for i in range(nrk):
                yt[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i])
            _rhs_road(rx[2], rv[2], yt, k4, p, wk, False)
            for i in range(nrk):
                yt[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
            _rhs_road(rx[3], rv[3], yt, k5, p, wk, False)
            for i in range(nrk):
                yt[i] = y[i] + h * (
                    A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]
                )
            _rhs_road(rx[4], rv[4], yt, k6, p, wk, False)
            for i in range(nrk):
                yn[i] = y[i] + h * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i])
            a3b = _rhs_road(rx[4], rv[4], yn, k7, p, wk, False)
            nfev += 6
            err = _err_norm(y, yn, k1, k3, k4, k5, k6, k7, h, rtol, atol, nrk)
            if not math.isfinite(err):
                if h < 1e-14 * max(1.0, t):
                    status = NOT_FINITE
                    break
                h *= 0.1
                nrej += 1
                continue
            fac11 = err**expo1 if err > 0.0 else 0.0
            # a kink inside the step is looked for in every attempt, accepted or not: a
            # step across a kink fails the error test by orders of magnitude, and
            # shrinking it by the controller costs several rejections per kink, while
            # the continuous extension of the failed step already places the crossing
            # well enough to end the next attempt on it
            crossed = False
            truncated = False
            if sw_a >= 0 or lift:
                c1, rev, c2, ga1, ga2 = _first_kink(
                    p, y, yn, r2, r3, r4, r5, t, h, tn, seg, sw_a, sw_b, v_sat, lift
                )
                crossed = c1 or rev or c2
                if crossed:
                    _dense_coefficients(y, yn, k1, k3, k4, k5, k6, k7, h, r2, r3, r4, r5)
                    best = _locate_kinks(
                        p, y, r2, r3, r4, r5, t, h, seg, sw_a, sw_b, v_sat, c1, rev, c2, ga1, ga2
                    )
                    # an attempt that was itself cut at a crossing may end a little past
                    # it (crossing placed on a less accurate extension): accept a kink in
                    # its last 1e-9 of the step (or last 1e-12 s), redo at most twice more
                    past = (1.0 - best) * h
                    if best < 1.0 - 1e-9 and past > 1e-12 * max(1.0, abs(t)):
                        if (
                            (c1 or rev)
                            and not c2
                            and p[P_BRANCH] >= 0.0
                            and err <= 1.0
                            and best * h > 1e-12 * max(1.0, abs(t))
                        ):
                            # a saturation crossing inside an accepted attempt on one
                            # branch: the solution up to it is the attempt's continuous
                            # extension, so keep the step up to just past the crossing
                            # (its state from the extension, as solvers stopping at an
                            # event do) instead of redoing the attempt
                            _truncate(y, yn, r2, r3, r4, r5, best, nrk)
                            h = best * h
                            tn = t + h
                            last = False
                            a3b = _rhs(tn, yn, k7, p, seg, wk, False)
                            nfev += 1
                            truncated = True
                        elif event_tries < 3:
                            # redo the step ending just past the first crossing
                            h_event = max(best * h, 1e-13 * max(1.0, abs(t)))
                            h = h_prop
                            nevents_redo += 1
                            event_tries += 1
                            continue
                        elif (c1 or rev) and p[P_BRANCH] >= 0.0:
                            # a saturation crossing this attempt would keep: the continued
                            # branch is wrong past it, so redo it on the law itself, as if
                            # without branches
                            natural_next = True
                            nevents_redo += 1
                            continue
            if err <= 1.0:
                nsteps += 1
                # the 100 Hz low pass of Wk and the a_w integrals, exactly over the step
                if truncated:
                    _lp_input_r(y, r2, r3, r4, r5, wk, n - 13, lpw)
                else:
                    _lp_input(y, yn, k1, k3, k4, k5, k6, k7, h, wk, n - 13, lpw)
                q1n, q2n, i2, i4 = _lp_setup(y[i_lp], y[i_lp + 1], h, wk, lpw)
                yn[i_lp] = q1n
                yn[i_lp + 1] = q2n
                yn[i_lp + 2] = y[i_lp + 2] + i2
                yn[i_lp + 3] = y[i_lp + 3] + i4
                if truncated:
                    # continuous extension of the last four states as _dense_coefficients
                    # makes it for states with zero stage derivatives
                    for i in range(nrk, n):
                        d = yn[i] - y[i]
                        r2[i] = d
                        r3[i] = -d
                        r4[i] = 2.0 * d
                        r5[i] = 0.0
                # dense output for samples and peak refinement
                need_samples = isamp < ns and (
                    sample_times[isamp] < tn or (final and last and sample_times[isamp] <= tn)
                )
                _quantities(tn, yn, p, seg, wk, a3b, qb)
                near = False
                if refine_peaks:
                    # an interior maximum exceeds the larger end value by about
                    # (h w)^2/8 of the amplitude: far below 1 % at the steps taken
                    for j in range(N_PEAKS):
                        if max(qa[j], qb[j]) >= peaks[j] - 0.01 * abs(peaks[j]):
                            near = True
                            break
                if (need_samples or near) and not truncated:
                    # (again when a kink search set them: the last four states of yn
                    # were only set now)
                    _dense_coefficients(y, yn, k1, k3, k4, k5, k6, k7, h, r2, r3, r4, r5)
                while isamp < ns and (
                    sample_times[isamp] < tn or (final and last and sample_times[isamp] <= tn)
                ):
                    th = (sample_times[isamp] - t) / h
                    _dense(y, r2, r3, r4, r5, th, yd)
                    yd[i_lp], yd[i_lp + 1] = _lp_at(lpw, th, wk)
                    a3s = _rhs(sample_times[isamp], yd, ks, p, seg, wk, False)
                    nfev += 1
                    for i in range(n):
                        out_y[isamp, i] = yd[i]
                    out_a3[isamp] = a3s
                    isamp += 1
                if near:
                    # the step midpoint, and where a parabola through the three values
                    # puts a larger maximum inside the step, successive parabolic
                    # interpolation on the continuous extension
                    _dense(y, r2, r3, r4, r5, 0.5, yd)
                    yd[i_lp], yd[i_lp + 1] = _lp_at(lpw, 0.5, wk)
                    a3m = _rhs(t + 0.5 * h, yd, ks, p, seg, wk, False)
                    nfev += 1
                    _quantities(t + 0.5 * h, yd, p, seg, wk, a3m, qm)
                    for j in range(N_PEAKS):
                        fa, fm, fb = qa[j], qm[j], qb[j]
                        if max(fa, fm, fb) > peaks[j]:
                            peaks[j] = max(fa, fm, fb)
                        c2p = 2.0 * fa - 4.0 * fm + 2.0 * fb
                        c1p = -3.0 * fa + 4.0 * fm - fb
                        if c2p >= 0.0:
                            continue
                        thv = -c1p / (2.0 * c2p)
                        if thv <= 0.0 or thv >= 1.0 or fa + c1p * thv + c2p * thv * thv <= peaks[j]:
                            continue
                        nfev += _refine_peak(
                            y, r2, r3, r4, r5, lpw, t, h, yd, ks, p, seg, wk, i_lp, qt, j,
                            fa, fm, fb, peaks,
                        )  # fmt: skip
                else:
                    for j in range(N_PEAKS):
                        if qb[j] > peaks[j]:
                            peaks[j] = qb[j]
                event_tries = 0
                reg_b = 0
                if sw_a >= 0:
                    vb = yn[sw_a] - (yn[sw_b] if sw_b >= 0 else 0.0)
                    reg_b = 1 if abs(vb) >= v_sat else 0
                if (event_step and crossed) or truncated:
                    nkink_steps += 1
                    # a step cut short just past a kink says nothing about the step size
                    # the smooth solution allows: carry on with the proposal made before
                    # it, or with the last one made on this side of the saturation kink.
                    # Only if the step did end past the kink: one ending just short of
                    # it leaves the FSAL derivative on the old side, and a long next step
                    # would carry that error while the embedded estimate (weight E1 on k1,
                    # 70x below B1) barely sees it (a jump in the momentum law)
                    hnew = h_prop
                    if sw_a >= 0 and h_side[reg_b] > 0.0:
                        hnew = h_side[reg_b]
                else:
                    fac = fac11 / facold**beta
                    # safety factor 0.9, 0.8 below the saturation speed: there the error
                    # per step grows along the transit (the inertance steepens towards
                    # w_sat) and 0.9 had a third of the attempts rejected
                    fac = max(0.1, min(5.0, fac / (0.9 if p[P_BRANCH] != 0.0 else 0.8)))
                    hnew = h / fac
                    facold = max(err, 1e-4)
                    if sw_a >= 0 and err > 1e-3:
                        # remembered only from steps the error limits, not from steps
                        # still growing after a short one
                        h_side[reg_b] = hnew
                    if event_step and sw_a >= 0 and not lift:
                        # ended just short of the saturation kink (located on the
                        # continuous extension of a failed attempt): step onto it by
                        # linear extrapolation of |v| - v_sat, then go on as above
                        ab = k7[sw_a] - (k7[sw_b] if sw_b >= 0 else 0.0)
                        g = abs(vb) - v_sat
                        gd = ab if vb > 0.0 else -ab
                        if g * gd < 0.0:
                            dt = -g / gd * (1.0 + 1e-6) + 1e-13 * max(1.0, abs(tn))
                            if dt < h_prop and tn + dt < t1:
                                h_event = dt
                                hnew = h_prop
                for i in range(n):
                    y[i] = yn[i]
                    k1[i] = k7[i]
                for j in range(N_PEAKS):
                    qa[j] = qb[j]
                t = tn
                h = max(hnew, h_prop) if last else hnew
                if nsteps >= max_steps:
                    status = TOO_MANY_STEPS
                    break
            else:
                nrej += 1
                h = h / min(5.0, fac11 / 0.9)
                if h < 1e-14 * max(1.0, abs(t)):
                    status = STEP_TOO_SMALL
                    break
        if status != OK:
            break
        if t1 >= t_end:
            break
    stats[0] = nsteps
    stats[1] = nrej
    stats[2] = nfev
    stats[3] = nevents_redo
    stats[4] = nexact
    stats[5] = nkink_steps
    stats[6] = nsetup
    return status
