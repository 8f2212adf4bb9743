"""Numba kernels of the harmonic-balance engine for the built-in one-degree-of-freedom systems.

Kept while it is faster than the one engine of :mod:`inerterlab.frequency.first_order`
on these systems (docs/decisions.md); their physics, :func:`residual_partials`, is the one
the implicit form ``system.first_order()`` evaluates on that engine, whose RK4 period
integrator is also their brute force.

Every built-in system is a scalar residual r(tau, x, x', x'') of the phase
tau = Omega t with its exact partial derivatives; the kernels here assemble the
alternating frequency-time (AFT) residual and its analytic Jacobian and run Newton with
a backtracking line search on the residual norm.

System codes (``sys_id``) and their parameter vectors ``p``:

0 Duffing, x'' + c x' + k x + g x^3 = P cos(tau) with mass ``m``:
  p = [m, c, k, g, P]
1 body on spring, damper and inerter over a moving base (7.1), X0 = B sin(tau):
  p = [M, K, C, B, ratio, I_rest, coef, k_s, m_s, l_min, l_max, omega_sat, power,
       law (0 thesis, 1 momentum), has_inerter (0/1)]
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# the inertia law with its first and second derivatives, written once in elements/
from ..elements.adaptive_flywheel import inertia_law


@njit(cache=True, inline="always")
def residual_partials(sys_id, p, tau, omega, x0, x0d, x0dd, x, xd, xdd):
    """Residual r and its partials dr/dx, dr/dx', dr/dx'' at one time sample.

    ``sys_id`` 0: Duffing, p = [m, c, k, g, P]; 1: body over a moving base with an
    adaptive-flywheel inerter, (7.1), p as :meth:`InerterSuspension.parameters`, with the
    base's displacement, velocity and acceleration x0, x0', x0''.
    """
    if sys_id == 0:
        m, c, k, g, force = p[0], p[1], p[2], p[3], p[4]
        r = m * xdd + c * xd + k * x + g * x * x * x - force * math.cos(tau)
        return r, k + 3.0 * g * x * x, c, m
    # sys_id == 1: body over a moving base with an adaptive-flywheel inerter, (7.1)
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


@njit(cache=True, inline="always")
def evaluate(sys_id, p, tau, omega, x, xd, xdd):
    """Residual r and its partials dr/dx, dr/dx', dr/dx'' at one time sample (the base
    of system 1 moves as B sin(tau), B = p[3])."""
    base = p[3] if sys_id == 1 else 0.0
    s = math.sin(tau)
    return residual_partials(
        sys_id, p, tau, omega, base * s, base * omega * math.cos(tau), -base * omega * omega * s,
        x, xd, xdd,
    )  # fmt: skip


# ---------------------------------------------------------------------------------
# AFT residual and Jacobian


@njit(cache=True)
def samples(X, omega, E, E1, E2):
    """x, x', x'' at the time samples from the coefficient vector X."""
    x = E @ X
    xd = omega * (E1 @ X)
    xdd = omega * omega * (E2 @ X)
    return x, xd, xdd


@njit(cache=True)
def residual(sys_id, p, X, omega, tau, E, E1, E2, F):
    """Harmonic-balance residual R(X) (Fourier coefficients of r(t))."""
    x, xd, xdd = samples(X, omega, E, E1, E2)
    n = tau.shape[0]
    r = np.empty(n)
    for k in range(n):
        r[k] = evaluate(sys_id, p, tau[k], omega, x[k], xd[k], xdd[k])[0]
    return F @ r


@njit(cache=True)
def residual_jacobian(sys_id, p, X, omega, tau, E, E1, E2, F):
    """R(X) and dR/dX = F [diag(dr/dx) E + w diag(dr/dx') E1 + w^2 diag(dr/dx'') E2]."""
    x, xd, xdd = samples(X, omega, E, E1, E2)
    n, m = E.shape
    r = np.empty(n)
    G = np.empty((n, m))
    for k in range(n):
        rk, g0, g1, g2 = evaluate(sys_id, p, tau[k], omega, x[k], xd[k], xdd[k])
        r[k] = rk
        g1w = omega * g1
        g2w = omega * omega * g2
        for j in range(m):
            G[k, j] = g0 * E[k, j] + g1w * E1[k, j] + g2w * E2[k, j]
    return F @ r, F @ G


@njit(cache=True)
def hill_matrices(sys_id, p, X, omega, tau, E, E1, E2, F):
    """J0, J1, J2 of the quadratic Hill problem (lambda^2 J2 + lambda J1 + J0) q = 0."""
    x, xd, xdd = samples(X, omega, E, E1, E2)
    n, m = E.shape
    G0 = np.empty((n, m))
    G1 = np.empty((n, m))
    G2 = np.empty((n, m))
    for k in range(n):
        _, g0, g1, g2 = evaluate(sys_id, p, tau[k], omega, x[k], xd[k], xdd[k])
        for j in range(m):
            G0[k, j] = g0 * E[k, j] + omega * g1 * E1[k, j] + omega * omega * g2 * E2[k, j]
            G1[k, j] = g1 * E[k, j] + 2.0 * omega * g2 * E1[k, j]
            G2[k, j] = g2 * E[k, j]
    return F @ G0, F @ G1, F @ G2


@njit(cache=True)
def relative_residuals(sys_id, p, omegas, C, tau, E, E1, E2, F):
    """||R(X_i)|| / ||R(0)|| for each row X_i of C at frequency omegas[i]."""
    n_pts, m = C.shape
    out = np.empty(n_pts)
    zero = np.zeros(m)
    for i in range(n_pts):
        r = residual(sys_id, p, np.ascontiguousarray(C[i]), omegas[i], tau, E, E1, E2, F)
        r0 = residual(sys_id, p, zero, omegas[i], tau, E, E1, E2, F)
        a = np.sqrt(np.sum(r * r))
        b = np.sqrt(np.sum(r0 * r0))
        out[i] = a / b if b > 0.0 else a
    return out


@njit(cache=True)
def newton(sys_id, p, X0, omega, tau, E, E1, E2, F, rtol, max_iter, scale):
    """Newton with backtracking on ||R||; returns X, converged, iterations, ||R||, code.

    Converged when the update is below ``rtol * (||X|| + scale)`` and the residual is
    below ``1e3 * rtol * scale_R``. Codes: 0 ok, 1 iteration limit, 2 singular
    Jacobian, 3 no descent (line search failed), 4 non-finite values.
    """
    X = X0.copy()
    R, J = residual_jacobian(sys_id, p, X, omega, tau, E, E1, E2, F)
    rn = np.sqrt(np.sum(R * R))
    for it in range(max_iter):
        if not np.isfinite(rn):
            return X, False, it, rn, 4
        try:
            dX = np.linalg.solve(J, -R)
        except Exception:  # noqa: BLE001 - LAPACK reports a singular matrix
            return X, False, it, rn, 2
        if not np.all(np.isfinite(dX)):
            return X, False, it, rn, 2
        step = 1.0
        accepted = False
        for _ in range(12):
            Xn = X + step * dX
            Rn, Jn = residual_jacobian(sys_id, p, Xn, omega, tau, E, E1, E2, F)
            rnn = np.sqrt(np.sum(Rn * Rn))
            if np.isfinite(rnn) and (rnn <= (1.0 - 1e-4 * step) * rn or rnn < 1e-300):
                accepted = True
                break
            step *= 0.5
        if not accepted:
            # at the round-off floor a full step cannot reduce ||R|| any further
            small = np.sqrt(np.sum(dX * dX)) <= 1e3 * rtol * (np.sqrt(np.sum(X * X)) + scale)
            return X, small, it, rn, 0 if small else 3
        X = Xn
        R = Rn
        J = Jn
        rn = rnn
        if step == 1.0 and np.sqrt(np.sum(dX * dX)) <= rtol * (np.sqrt(np.sum(X * X)) + scale):
            return X, True, it + 1, rn, 0
    return X, False, max_iter, rn, 1


@njit(cache=True)
def sweep(sys_id, p, omegas, X_start, X_cold, tau, E, E1, E2, F, rtol, max_iter, scale, warm):
    """Solve at each frequency of ``omegas`` in order.

    With ``warm`` each point starts from the last converged solution, extrapolated
    linearly in frequency from the two last ones (the scanning method, (7.23)-(7.32));
    a point that fails is retried through up to 8 intermediate frequencies from the
    last converged point and then from ``X_cold`` (past a fold the response jumps to
    another branch, which a warm start cannot reach). Without ``warm`` every point starts from ``X_cold``.
    """
    n_pts = omegas.shape[0]
    m = X_start.shape[0]
    out = np.zeros((n_pts, m))
    ok = np.zeros(n_pts, dtype=np.bool_)
    iters = np.zeros(n_pts, dtype=np.int64)
    res = np.zeros(n_pts)
    code = np.zeros(n_pts, dtype=np.int64)
    X_last = X_start.copy()
    X_prev = X_start.copy()
    w_last = -1.0
    w_prev = -1.0
    for i in range(n_pts):
        w = omegas[i]
        if warm:
            guess = X_last.copy()
            if w_prev > 0.0 and w_last != w_prev:
                guess = X_last + (X_last - X_prev) * ((w - w_last) / (w_last - w_prev))
        else:
            guess = X_cold.copy()
        X, conv, it, rn, c = newton(sys_id, p, guess, w, tau, E, E1, E2, F, rtol, max_iter, scale)
        if not conv and warm and w_last > 0.0:
            # retry through intermediate frequencies from the last converged point
            Xs = X_last.copy()
            conv = True
            n_sub = 8
            for s in range(1, n_sub + 1):
                ws = w_last + (w - w_last) * s / n_sub
                Xs, cs, its, rn, c = newton(
                    sys_id, p, Xs, ws, tau, E, E1, E2, F, rtol, max_iter, scale
                )
                it += its
                if not cs:
                    conv = False
                    break
            X = Xs
            if not conv:
                # a jump (fold passed): start afresh from the cold start
                X, conv, its, rn, c = newton(
                    sys_id, p, X_cold, w, tau, E, E1, E2, F, rtol, max_iter, scale
                )
                it += its
        out[i] = X
        ok[i] = conv
        iters[i] = it
        res[i] = rn
        code[i] = c
        if conv:
            X_prev = X_last
            w_prev = w_last
            X_last = X
            w_last = w
    return out, ok, iters, res, code
