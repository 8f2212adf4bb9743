"""Compiled right-hand sides and the adaptive integrator of the device models.

One state vector serves every device and law::

    y = [x_k, v_a, l, l', W, D, omega_f]

x_k [m] deflection of the series spring, v_a [m/s] velocity through the inertance
branch (series devices), l [m] and l' [m/s] the slider radius and rate (law
``slider-dynamics``), W [J] work done on the device, D [J] energy dissipated,
omega_f [rad/s] flywheel speed of the one-way (free-wheeling) rectifier.

The integrator is an embedded Dormand-Prince 5(4) pair with error control on every
component (``rtol``, per-component ``atol``), stepping exactly onto each output time.
The free-wheeling rectifier is a hybrid system: a mode switch is located by halving
the step until it is shorter than ``event_tol`` seconds, so the result does not
depend on where the steps happened to fall.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ..elements.adaptive_flywheel import inertia_law
from ..slider_dynamics import rotor_torque, slider_state_derivative, stored_energy
from .motion import motion_at

# indices of the parameter vector P
SERIES, LAW, RATIO, STIFF, DAMP, FRIC, VEPS, BACKLASH, FREEWHEEL = range(9)
FW0 = 9  # rest, nm, k_s, m_s, l_min, l_max, omega_sat, power
SD0 = 17  # slider-dynamics coefficients (9)
FWDRAG = 26  # viscous drag of the flywheel bearing [N m s/rad]
NPAR = 27
NSTATE = 7


@nb.njit(cache=True)
def _slider_l(w, P):
    w = abs(w)
    if w >= P[FW0 + 6]:
        return P[FW0 + 5]
    k, m = P[FW0 + 2], P[FW0 + 3]
    return k * P[FW0 + 4] / (k - m * w * w)


@nb.njit(cache=True)
def _law(w, P):
    """I, dI/d|omega|, d2I/d|omega|2 at |omega| from the flywheel slots of ``P``: the law
    of :func:`inerterlab.elements.adaptive_flywheel.inertia_law`, written once."""
    return inertia_law(
        abs(w), P[FW0], P[FW0 + 1], P[FW0 + 2], P[FW0 + 3], P[FW0 + 4], P[FW0 + 5], P[FW0 + 6],
        int(P[FW0 + 7]),
    )  # fmt: skip


@nb.njit(cache=True)
def inertia(w, P):
    """I(|omega|) [kg m^2] of the quasi-static law."""
    return _law(w, P)[0]


@nb.njit(cache=True)
def momentum_inertia(w, P):
    """I + |omega| dI/d|omega| [kg m^2]."""
    i0, i1, _ = _law(w, P)
    return i0 + abs(w) * i1


@nb.njit(cache=True)
def quasi_static_energy(w, P):
    """1/2 I omega^2 + slider spring energy [J] at quasi-static speed ``w``."""
    l = _slider_l(w, P)
    n = P[SD0 + 1]
    return 0.5 * inertia(w, P) * w * w + 0.5 * n * P[FW0 + 2] * (l - P[FW0 + 4]) ** 2


@nb.njit(cache=True)
def _branch_velocity(fk, P):
    """v_a with b v_a + f tanh(v_a / eps) = fk (massless branch of the free-wheeling mode)."""
    b, f, eps = P[DAMP], P[FRIC], P[VEPS]
    lo, hi = (fk - f) / b, (fk + f) / b
    v = fk / (b + f / eps)
    if v < lo or v > hi:
        v = 0.5 * (lo + hi)
    for _ in range(100):
        th = math.tanh(v / eps)
        g = b * v + f * th - fk
        if g > 0.0:
            hi = v
        else:
            lo = v
        dg = b + f / eps * (1.0 - th * th)
        vn = v - g / dg
        if vn <= lo or vn >= hi:
            vn = 0.5 * (lo + hi)
        if abs(vn - v) <= 1e-15 + 1e-13 * abs(v):
            return vn
        v = vn
    return v


@nb.njit(cache=True)
def evaluate(t, y, mode, P, kind, par, tn, xn, vn, dy):
    """Fill ``dy`` with dy/dt; return (force [N], switch function, equivalent mass [kg])."""
    x, v, a = motion_at(t, kind, par, tn, xn, vn)
    r, k, b, f, eps = P[RATIO], P[STIFF], P[DAMP], P[FRIC], P[VEPS]
    law = int(P[LAW])
    for i in range(NSTATE):
        dy[i] = 0.0
    g = 1.0
    if P[SERIES] > 0.5:
        xk = y[0]
        force = k * xk
        if mode == 1:  # free-wheeling: massless branch, flywheel coasts
            va = _branch_velocity(force, P)
            fric = f * math.tanh(va / eps)
            cd = P[FWDRAG]
            jf = inertia(y[6], P) if law == 0 else momentum_inertia(y[6], P)
            dy[0] = v - va
            dy[4] = force * v
            dy[5] = b * va * va + fric * va + cd * y[6] * y[6]
            dy[6] = -cd * y[6] / jf
            g = y[6] - r * abs(va)
            return force, g, r * r * inertia(y[6], P)
        va = y[1]
        fric = f * math.tanh(va / eps)
        fin = force - b * va - fric - P[FWDRAG] * r * r * va
        dis = P[FWDRAG] * r * r * va * va
        if law == 0:
            me = r * r * inertia(r * va, P)
            dva = fin / me
        elif law == 1:
            me = r * r * inertia(r * va, P)
            dva = fin / (r * r * momentum_inertia(r * va, P))
        else:
            l, ld = y[2], y[3]
            om = r * va
            n, ms = P[SD0 + 1], P[SD0 + 2]
            jr = P[SD0] + n * ms * l * l
            me = r * r * jr
            dom = (fin / r - 2.0 * n * ms * l * ld * om) / jr
            dva = dom / r
            lacc, dis = slider_state_derivative(
                l,
                ld,
                om,
                n,
                ms,
                P[SD0 + 3],
                P[SD0 + 4],
                P[SD0 + 5],
                P[SD0 + 6],
                P[SD0 + 7],
                P[SD0 + 8],
            )
            dy[2] = ld
            dy[3] = lacc
        dy[0] = v - va
        dy[1] = dva
        dy[4] = force * v
        dy[5] = b * va * va + fric * va + dis
        if P[FREEWHEEL] > 0.5:
            # the one-way clutch transmits the branch force F_b = F - b v_a - friction
            # as a driving torque s F_b / r >= 0; a small tolerance keeps round-off at
            # the instant of engagement (F_b = 0) from switching straight back
            s = 1.0 if va >= 0.0 else -1.0
            dy[6] = r * s * dva
            g = s * (force - b * va - fric) + 1e-9 * (abs(force) + 1.0)
        return force, g, me
    # parallel model of the inverse screw (3.38), input x = x_1 - x_2
    fric = f * math.tanh(v / eps)
    elastic = k * x + b * v
    contact = P[BACKLASH] <= 0.0 or abs(elastic) >= k * P[BACKLASH]
    dis = 0.0
    if law == 0:
        me = r * r * inertia(r * v, P)
        fin = me * a
    elif law == 1:
        me = r * r * inertia(r * v, P)
        fin = r * r * momentum_inertia(r * v, P) * a
    else:
        l, ld = y[2], y[3]
        om, dom = r * v, r * a
        n, ms = P[SD0 + 1], P[SD0 + 2]
        me = r * r * (P[SD0] + n * ms * l * l)
        fin = r * rotor_torque(l, ld, om, dom, P[SD0], n, ms)
        lacc, dis = slider_state_derivative(
            l,
            ld,
            om,
            n,
            ms,
            P[SD0 + 3],
            P[SD0 + 4],
            P[SD0 + 5],
            P[SD0 + 6],
            P[SD0 + 7],
            P[SD0 + 8],
        )
        dy[2] = ld
        dy[3] = lacc
    if not contact:
        fin = 0.0
    force = elastic + fric + fin
    dy[0] = v  # track x and v so the stored energy can be read from the state
    dy[1] = a
    dy[4] = force * v
    dy[5] = b * v * v + fric * v + dis
    return force, g, me


# Dormand-Prince 5(4) tableau
_C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0])
_A = np.array(
    [
        [0, 0, 0, 0, 0, 0],
        [1 / 5, 0, 0, 0, 0, 0],
        [3 / 40, 9 / 40, 0, 0, 0, 0],
        [44 / 45, -56 / 15, 32 / 9, 0, 0, 0],
        [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0, 0],
        [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0],
        [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84],
    ]
)
_B5 = np.array([35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0])
_B4 = np.array([5179 / 57600, 0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40])


@nb.njit(cache=True)
def integrate(t_out, y0, mode0, P, kind, par, tn, xn, vn, rtol, atol, h_max, event_tol, max_steps):
    """Integrate from t_out[0] and record the outputs at every t_out.

    Returns (states [n, 7], force [n], equivalent mass [n], mode [n], status, steps);
    status 0 is success, 1 too many steps, 2 step size underflow.
    """
    n = t_out.shape[0]
    ys = np.empty((n, NSTATE))
    force = np.empty(n)
    meq = np.empty(n)
    modes = np.empty(n, dtype=np.int64)
    y = y0.copy()
    mode = mode0
    dy = np.empty(NSTATE)
    k = np.empty((7, NSTATE))
    ytmp = np.empty(NSTATE)
    y5 = np.empty(NSTATE)
    t = t_out[0]
    f0, _, m0 = evaluate(t, y, mode, P, kind, par, tn, xn, vn, dy)
    if mode == 1:
        y[1] = _branch_velocity(P[STIFF] * y[0], P)
    ys[0, :] = y
    force[0] = f0
    meq[0] = m0
    modes[0] = mode
    h = min(h_max, 1e-4 if n < 2 else t_out[1] - t_out[0])
    steps = 0
    for j in range(1, n):
        target = t_out[j]
        while t < target:
            if steps >= max_steps:
                return ys[:j], force[:j], meq[:j], modes[:j], 1, steps
            hh = min(h, target - t)
            last = hh >= target - t
            # stages
            for s in range(7):
                for i in range(NSTATE):
                    acc = y[i]
                    for q in range(s):
                        acc += hh * _A[s, q] * k[q, i]
                    ytmp[i] = acc
                evaluate(t + _C[s] * hh, ytmp, mode, P, kind, par, tn, xn, vn, dy)
                for i in range(NSTATE):
                    k[s, i] = dy[i]
            err = 0.0
            for i in range(NSTATE):
                y5i = y[i]
                e = 0.0
                for s in range(7):
                    y5i += hh * _B5[s] * k[s, i]
                    e += hh * (_B5[s] - _B4[s]) * k[s, i]
                y5[i] = y5i
                sc = atol[i] + rtol * max(abs(y[i]), abs(y5i))
                err = max(err, abs(e) / sc)
            steps += 1
            if not (err <= 1.0):
                fac = 0.2 if not math.isfinite(err) else max(0.2, 0.9 * err ** (-0.2))
                h = hh * fac
                if h < 1e-14 * max(1.0, abs(t)):
                    return ys[:j], force[:j], meq[:j], modes[:j], 2, steps
                continue
            # mode switch (free-wheeling rectifier): locate it by halving the step
            gnew = 1.0
            if P[FREEWHEEL] > 0.5:
                _, gnew, _ = evaluate(t + hh, y5, mode, P, kind, par, tn, xn, vn, dy)
            if gnew < 0.0:
                if hh > event_tol:
                    h = 0.5 * hh
                    continue
                for i in range(NSTATE):
                    y[i] = y5[i]
                t = target if last else t + hh
                if mode == 0:
                    mode = 1
                    y[6] = P[RATIO] * abs(y[1])
                else:
                    mode = 0
                    y[1] = _branch_velocity(P[STIFF] * y[0], P)
                    y[6] = P[RATIO] * abs(y[1])
                h = max(event_tol * 10.0, min(h_max, 1e-5))
                continue
            for i in range(NSTATE):
                y[i] = y5[i]
            t = target if last else t + hh
            fac = 5.0 if err == 0.0 else min(5.0, 0.9 * err ** (-0.2))
            h = min(h_max, hh * fac) if not last else max(h, min(h_max, hh * fac))
            if mode == 1:
                y[1] = _branch_velocity(P[STIFF] * y[0], P)
        f1, _, m1 = evaluate(t, y, mode, P, kind, par, tn, xn, vn, dy)
        ys[j, :] = y
        force[j] = f1
        meq[j] = m1
        modes[j] = mode
    return ys, force, meq, modes, 0, steps


@nb.njit(cache=True)
def flywheel_energy(y, mode, law, r, P):
    """Energy stored in the flywheel [J] for the state ``y`` (see :func:`evaluate`)."""
    if law == 2:
        return stored_energy(
            y[2],
            y[3],
            r * y[1],
            P[SD0],
            P[SD0 + 1],
            P[SD0 + 2],
            P[SD0 + 3],
            P[SD0 + 4],
            P[SD0 + 5],
            P[SD0 + 7],
        )
    w = y[6] if mode == 1 else r * y[1]
    if law == 1:
        return quasi_static_energy(w, P)
    return 0.5 * inertia(w, P) * w * w


@nb.njit(cache=True)
def flywheel_energies(ys, modes, law, r, P):
    """:func:`flywheel_energy` of every row of ``ys`` [J] (one compiled loop)."""
    n = ys.shape[0]
    out = np.empty(n)
    for i in range(n):
        out[i] = flywheel_energy(ys[i], modes[i], law, r, P)
    return out
