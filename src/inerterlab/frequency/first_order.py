"""Harmonic balance of first-order state equations x' = f(t, x, u(t)) (AFT, Newton, Hill).

A system here is any object with

``n_states``
    The number n of states taking part in the balance.
``rhs``
    A compiled (numba) function ``rhs(t, x, road, int_table, float_table, out) -> bool``
    writing f into ``out`` (False when it could not, e.g. an internal force balance
    failed: the point then fails as non-finite); ``road`` holds the input u = [displacement, velocity, acceleration]
    at time t. It is called with arrays of length ``work_size`` >= n (states past n are
    held at zero and their derivatives ignored, so a right-hand side that also carries
    states which do not feed back, such as the filters of a metric, is used unchanged).
``int_table``, ``float_table`` (or ``tables`` = both)
    Its parameters (int64 and float64 vectors, contiguous).
``work_size`` (optional, default n), ``state_scales`` (optional: typical magnitude of
    each state, for the finite-difference steps), ``jacobian`` (optional: a compiled
    ``jacobian(t, x, road, int_table, float_table, out)`` writing df/dx, n x n),
    ``rest_state`` or ``initial_state()`` (optional, the cold start),
    ``nonlinearity_degree`` (aliasing rule).

The input is a sine of amplitude A: u = [A sin(tau), A Omega cos(tau), -A Omega^2 sin(tau)],
tau = Omega t. Every state is a truncated Fourier series,
x_i(tau) = a0 + sum_h a_h cos(h tau) + b_h sin(h tau), stored state by state as
X = [X_1, ..., X_n], X_i = [a0, a1, b1, ..., aH, bH]. The residual is

    R_i = Omega D X_i - F f_i(x(tau_k)),     k = 0 .. N-1,

with D the derivative of the coefficients in tau and F the projection of N samples on
the harmonics; its Jacobian is exact up to the state Jacobian df/dx at the samples,

    dR_i/dX_j = Omega D delta_ij - F diag(df_i/dx_j (tau_k)) E,

where df/dx comes from ``jacobian`` or, without it, from central differences of
``rhs`` at each sample (step 1e-6 of the state's size). Newton with a backtracking line
search on ||R|| solves it; the scanning and continuation drivers of
:mod:`inerterlab.frequency.response` run unchanged on this engine.

Stability (Hill's method for first-order systems): a perturbation e^(lambda t) q(t)
with q periodic solves lambda Q = -(dR/dX) Q, so the Floquet exponents are eigenvalues
of -dR/dX. Each true exponent appears with copies shifted by multiples of i Omega; the
n eigenvalues nearest the real axis are taken as the exponents (one copy of each) and
the largest real part decides stability. The exponents converge with far fewer
harmonics than the response, so the Hill matrix may be restricted to the harmonics
0..H_s of every state (docs/model.md §7).

The right-hand side is handed to the compiled kernels as a first-class function of a
fixed signature (:data:`RHS_SIGNATURE`), so the kernels compile once and are cached on
disk whatever the system is.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types

from ..errors import ParameterError
from ..resources import check_memory
from .harmonic import FourierBasis, check_samples, default_samples, fourier_basis

__all__ = [
    "RHS_SIGNATURE",
    "JACOBIAN_SIGNATURE",
    "FirstOrderEngine",
    "make_first_order_engine",
    "is_first_order",
    "brute_force_point",
    "monodromy_multipliers",
    "rhs_samples",
]

_f8 = types.float64
_v = types.float64[::1]
_iv = types.int64[::1]
_m = types.float64[:, ::1]
#: rhs(t, x, road, int_table, float_table, out) -> ok (False: f could not be evaluated)
RHS_SIGNATURE = types.boolean(_f8, _v, _v, _iv, _v, _v)
#: jacobian(t, x, road, int_table, float_table, out) -> None, out[i, j] = df_i/dx_j
JACOBIAN_SIGNATURE = types.void(_f8, _v, _v, _iv, _v, _m)
_RHS = types.FunctionType(RHS_SIGNATURE)
_JAC = types.FunctionType(JACOBIAN_SIGNATURE)
_b1 = types.boolean
_i8 = types.int64
_a1 = types.Array(types.bool_, 1, "C")

FD_STEP = 1e-6  # central-difference step, relative to the state's size


def _no_jacobian_py(t, x, road, itab, ftab, out):  # pragma: no cover - never called
    """Placeholder handed to the kernels when the system has no analytic Jacobian."""
    out[:, :] = 0.0


# ---------------------------------------------------------------------------------
# compiled kernels (the system's functions are arguments, typed by their signature)


@njit(cache=True)
def _road(amp, omega, tau, road):
    s = math.sin(tau)
    road[0] = amp * s
    road[1] = amp * omega * math.cos(tau)
    road[2] = -amp * omega * omega * s


@njit(cache=True)
def _state_samples(X, n, ET):
    """xs[i, k] = x_i(tau_k) from the coefficients X (n blocks of m)."""
    m, N = ET.shape
    xs = np.empty((n, N))
    for i in range(n):
        xs[i] = X[i * m : (i + 1) * m] @ ET
    return xs


@njit(cache=True)
def _rhs_samples(rhs, itab, ftab, work, n, xs, omega, amp, tau):
    """f(t_k, x(tau_k), u(tau_k)) for every sample, shape (n, N)."""
    N = tau.shape[0]
    x = np.zeros(work)
    out = np.zeros(work)
    road = np.empty(3)
    f = np.empty((n, N))
    for k in range(N):
        for i in range(n):
            x[i] = xs[i, k]
        _road(amp, omega, tau[k], road)
        if rhs(tau[k] / omega, x, road, itab, ftab, out):
            for i in range(n):
                f[i, k] = out[i]
        else:
            for i in range(n):
                f[i, k] = np.nan
    return f


@njit(cache=True)
def _rhs_and_jacobian(
    rhs, jac, has_jac, itab, ftab, work, n, xs, omega, amp, tau, scales, central=True
):  # fmt: skip
    """f at the samples (n, N) and df/dx at the samples (n, n, N) (central or forward
    differences without an analytic Jacobian)."""
    N = tau.shape[0]
    x = np.zeros(work)
    out = np.zeros(work)
    outp = np.zeros(work)
    road = np.empty(3)
    f = np.empty((n, N))
    A = np.empty((n, n, N))
    Jk = np.zeros((n, n))
    for k in range(N):
        for i in range(n):
            x[i] = xs[i, k]
        _road(amp, omega, tau[k], road)
        t = tau[k] / omega
        good = rhs(t, x, road, itab, ftab, out)
        for i in range(n):
            f[i, k] = out[i] if good else np.nan
        if has_jac:
            jac(t, x, road, itab, ftab, Jk)
            for i in range(n):
                for j in range(n):
                    A[i, j, k] = Jk[i, j]
        else:
            for j in range(n):
                xj = x[j]
                h = FD_STEP * max(abs(xj), scales[j])
                x[j] = xj + h
                rhs(t, x, road, itab, ftab, outp)
                if central:
                    x[j] = xj - h
                    rhs(t, x, road, itab, ftab, out)
                    x[j] = xj
                    for i in range(n):
                        A[i, j, k] = (outp[i] - out[i]) / (2.0 * h)
                else:
                    x[j] = xj
                    for i in range(n):
                        A[i, j, k] = (outp[i] - f[i, k]) / h
    return f, A


@njit(cache=True)
def _project_residual(X, omega, f, n, D, F):
    m = D.shape[0]
    R = np.empty(n * m)
    for i in range(n):
        R[i * m : (i + 1) * m] = omega * (D @ X[i * m : (i + 1) * m]) - F @ f[i]
    return R


@njit(cache=True)
def _assemble_jacobian(A, omega, n, E, D, F, hs):
    """dR/dX restricted to the harmonics 0..hs of every state (hs = H: the full matrix).

    Block (i, j) is Omega D delta_ij - F diag(A_ij) E; a block whose A_ij is the same at
    every sample is -A_ij times the identity (F E = I)."""
    N, m = E.shape
    ms = 2 * hs + 1
    J = np.zeros((n * ms, n * ms))
    G = np.empty((N, ms))
    for i in range(n):
        for j in range(n):
            a0 = A[i, j, 0]
            const = True
            for k in range(1, N):
                if A[i, j, k] != a0:
                    const = False
                    break
            if const:
                if a0 != 0.0:
                    for c in range(ms):
                        J[i * ms + c, j * ms + c] = -a0
            else:
                for k in range(N):
                    a = A[i, j, k]
                    for c in range(ms):
                        G[k, c] = a * E[k, c]
                for r in range(ms):
                    for c in range(ms):
                        acc = 0.0
                        for k in range(N):
                            acc += F[r, k] * G[k, c]
                        J[i * ms + r, j * ms + c] = -acc
        for r in range(ms):
            for c in range(ms):
                J[i * ms + r, i * ms + c] += omega * D[r, c]
    return J


@njit(cache=True)
def fo_residual(rhs, itab, ftab, work, n, X, omega, amp, tau, ET, D, F):
    """R(X) at Omega."""
    xs = _state_samples(X, n, ET)
    f = _rhs_samples(rhs, itab, ftab, work, n, xs, omega, amp, tau)
    return _project_residual(X, omega, f, n, D, F)


@njit(cache=True)
def fo_residual_jacobian(
    rhs, jac, has_jac, itab, ftab, work, n, X, omega, amp, tau, E, ET, D, F, scales
):
    """R(X) and dR/dX at Omega."""
    xs = _state_samples(X, n, ET)
    f, A = _rhs_and_jacobian(rhs, jac, has_jac, itab, ftab, work, n, xs, omega, amp, tau, scales)
    hh = (E.shape[1] - 1) // 2
    return _project_residual(X, omega, f, n, D, F), _assemble_jacobian(A, omega, n, E, D, F, hh)


@njit(cache=True)
def _newton_step(J, R):
    """-J^-1 R; where J is singular (a state whose mean value the equations leave free,
    e.g. a node held by a damper and an inerter only) the least-squares step of
    smallest norm, which leaves such a mean where it is."""
    ok = True
    try:
        dX = np.linalg.solve(J, -R)
    except Exception:  # noqa: BLE001 - LAPACK reports a singular matrix
        ok = False
        dX = np.zeros_like(R)
    if ok and np.all(np.isfinite(dX)):
        # reject the solve when it amplifies round-off (near-singular J)
        if _norm(dX) * 1e-12 * np.max(np.abs(J)) <= _norm(R) + 1e-300:
            return dX
    return np.linalg.lstsq(J, -R, rcond=1e-12)[0]


@njit(cache=True)
def _norm(v):
    return math.sqrt(np.sum(v * v))


@njit(cache=True)
def fo_newton(
    rhs, jac, has_jac, itab, ftab, work, n, X0, omega, amp, tau, E, ET, D, F, scales,
    rtol, max_iter, scale,
):  # fmt: skip
    """Newton with backtracking on ||R||: X, converged, iterations, ||R||, code.

    Codes as in :mod:`inerterlab.frequency._kernels`: 0 ok, 1 iteration limit,
    2 singular Jacobian, 3 no descent, 4 non-finite values.
    """
    X = X0.copy()
    R, J = fo_residual_jacobian(
        rhs, jac, has_jac, itab, ftab, work, n, X, omega, amp, tau, E, ET, D, F, scales
    )
    rn = _norm(R)
    for it in range(max_iter):
        if not np.isfinite(rn):
            return X, False, it, rn, 4
        dX = _newton_step(J, R)
        if not np.all(np.isfinite(dX)):
            return X, False, it, rn, 2
        step = 1.0
        accepted = False
        Xn = X
        rnn = rn
        for _ in range(12):
            Xn = X + step * dX
            Rn = fo_residual(rhs, itab, ftab, work, n, Xn, omega, amp, tau, ET, D, F)
            rnn = _norm(Rn)
            if np.isfinite(rnn) and (rnn <= (1.0 - 1e-4 * step) * rn or rnn < 1e-300):
                accepted = True
                break
            step *= 0.5
        if not accepted:
            small = _norm(dX) <= 1e3 * rtol * (_norm(X) + scale)
            return X, small, it, rn, 0 if small else 3
        X = Xn
        rn = rnn
        if step == 1.0 and _norm(dX) <= rtol * (_norm(X) + scale):
            return X, True, it + 1, rn, 0
        R, J = fo_residual_jacobian(
            rhs, jac, has_jac, itab, ftab, work, n, X, omega, amp, tau, E, ET, D, F, scales
        )
        rn = _norm(R)
    return X, False, max_iter, rn, 1


@njit(cache=True)
def _chord(
    rhs, itab, ftab, work, n, X0, omega, amp, tau, ET, D, F, Jinv, rtol, scale, max_iter
):  # fmt: skip
    """Quasi-Newton iterations from the inverse Jacobian of a nearby point, improved by
    Broyden's rank-one updates (Jinv is updated in place and carried to the next point).
    Gives up as soon as a step does not shrink the previous one by half. Returns X,
    converged, iterations, ||R||."""
    X = X0.copy()
    prev = np.inf
    R = fo_residual(rhs, itab, ftab, work, n, X, omega, amp, tau, ET, D, F)
    rn = _norm(R)
    for it in range(max_iter):
        if not np.isfinite(rn):
            return X, False, it, rn
        dX = -(Jinv @ R)
        size = _norm(dX)
        if size > 0.5 * prev:
            return X, False, it, rn
        X = X + dX
        prev = size
        if size <= rtol * (_norm(X) + scale):
            return X, True, it + 1, rn
        Rn = fo_residual(rhs, itab, ftab, work, n, X, omega, amp, tau, ET, D, F)
        u = Jinv @ (Rn - R)
        den = dX @ u
        if den != 0.0:
            v = dX @ Jinv
            Jinv += np.outer((dX - u) / den, v)
        R = Rn
        rn = _norm(R)
    return X, False, max_iter, rn


@njit(cache=True)
def fo_sweep(
    rhs, jac, has_jac, itab, ftab, work, n, omegas, X_start, X_cold, amp, tau, E, ET, D, F,
    scales, rtol, max_iter, scale, warm,
):  # fmt: skip
    """Solve at each frequency in order (same strategy as ``_kernels.sweep``).

    With ``warm`` a point is first tried by chord iterations with the inverse Jacobian of
    an earlier point (a few residual evaluations when the frequency step is small), then
    by full Newton."""
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
    Jinv = np.zeros((m, m))
    have_jinv = False
    for i in range(n_pts):
        w = omegas[i]
        if warm:
            guess = X_last.copy()
            if w_prev > 0.0 and w_last != w_prev:
                guess = X_last + (X_last - X_prev) * ((w - w_last) / (w_last - w_prev))
        else:
            guess = X_cold.copy()
        conv = False
        it = 0
        c = 0
        rn = np.inf
        X = guess
        if warm and have_jinv:
            X, conv, it, rn = _chord(
                rhs, itab, ftab, work, n, guess, w, amp, tau, ET, D, F, Jinv, rtol, scale, 12
            )
            if not conv:
                X = guess
        if not conv:
            X, conv, its, rn, c = fo_newton(
                rhs, jac, has_jac, itab, ftab, work, n, guess, w, amp, tau, E, ET, D, F,
                scales, rtol, max_iter, scale,
            )  # fmt: skip
            it += its
            if conv and warm:
                _, J = fo_residual_jacobian(
                    rhs, jac, has_jac, itab, ftab, work, n, X, w, amp, tau, E, ET, D, F, scales
                )
                Jinv = np.ascontiguousarray(np.linalg.pinv(J, rcond=1e-12))
                have_jinv = np.all(np.isfinite(Jinv))
        if not conv and warm and w_last > 0.0:
            Xs = X_last.copy()
            conv = True
            for s in range(1, 9):
                ws = w_last + (w - w_last) * s / 8
                Xs, cs, its, rn, c = fo_newton(
                    rhs, jac, has_jac, itab, ftab, work, n, Xs, ws, amp, tau, E, ET, D, F,
                    scales, rtol, max_iter, scale,
                )  # fmt: skip
                it += its
                if not cs:
                    conv = False
                    break
            X = Xs
            if not conv:
                X, conv, its, rn, c = fo_newton(
                    rhs, jac, has_jac, itab, ftab, work, n, X_cold, w, amp, tau, E, ET, D, F,
                    scales, rtol, max_iter, scale,
                )  # fmt: skip
                it += its
            have_jinv = False
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


@njit(cache=True)
def fo_relative_residuals(rhs, itab, ftab, work, n, omegas, C, amp, tau, ET, D, F):
    """||R(X_i)|| / ||R(0)|| for each row of C."""
    n_pts, m = C.shape
    out = np.empty(n_pts)
    zero = np.zeros(m)
    for i in range(n_pts):
        X = np.ascontiguousarray(C[i])
        a = _norm(fo_residual(rhs, itab, ftab, work, n, X, omegas[i], amp, tau, ET, D, F))
        b = _norm(fo_residual(rhs, itab, ftab, work, n, zero, omegas[i], amp, tau, ET, D, F))
        out[i] = a / b if b > 0.0 else a
    return out


@njit(cache=True)
def fo_hill_matrices(
    rhs, jac, has_jac, itab, ftab, work, n, omegas, C, ok, amp, tau, ET, Es, Ds, Fs, scales
):  # fmt: skip
    """-dR/dX in the basis Es (harmonics 0..hs) sampled at the phases ``tau`` (which may
    be denser than the balance's: the state Jacobian jumps where the flywheel saturates,
    and the quadrature of a jump converges only as 1/N), for every converged point
    (shape (P, n (2 hs + 1), n (2 hs + 1)); NaN where not converged). ``ET`` synthesises
    the states at ``tau`` from the H-harmonic coefficients. Its eigenvalues approximate
    the Floquet exponents and their copies shifted by i k Omega."""
    n_pts = omegas.shape[0]
    ms = Es.shape[1]
    hs = (ms - 1) // 2
    out = np.full((n_pts, n * ms, n * ms), np.nan)
    for p in range(n_pts):
        if not ok[p]:
            continue
        w = omegas[p]
        X = np.ascontiguousarray(C[p])
        xs = _state_samples(X, n, ET)
        _, A = _rhs_and_jacobian(
            rhs, jac, has_jac, itab, ftab, work, n, xs, w, amp, tau, scales, False
        )
        out[p] = -_assemble_jacobian(A, w, n, Es, Ds, Fs, hs)
    return out


@njit(cache=True)
def fo_derivative_samples(rhs, itab, ftab, work, n, omegas, C, amp, tau, ET):
    """States and their derivatives f at the samples for every point: (P, n, N) each."""
    n_pts = omegas.shape[0]
    N = tau.shape[0]
    xs_all = np.empty((n_pts, n, N))
    f_all = np.empty((n_pts, n, N))
    for p in range(n_pts):
        X = np.ascontiguousarray(C[p])
        xs = _state_samples(X, n, ET)
        xs_all[p] = xs
        f_all[p] = _rhs_samples(rhs, itab, ftab, work, n, xs, omegas[p], amp, tau)
    return xs_all, f_all


@njit(cache=True)
def interpolant_half_peak_to_peak(samples, a0, a, b):
    """Half peak-to-peak of the trigonometric interpolants of periodic samples.

    ``samples`` (P, K) at phases 2 pi k / K; ``a0`` (P,), ``a``, ``b`` (P, Hd) their
    cos/sin coefficients of harmonics 1..Hd. Each extreme starts at the extreme sample
    and is refined by Newton on the interpolant (exact for a sampled trigonometric
    polynomial of degree <= Hd)."""
    n_pts, K = samples.shape
    Hd = a.shape[1]
    out = np.empty(n_pts)
    for p in range(n_pts):
        k_hi = 0
        k_lo = 0
        for k in range(K):
            if samples[p, k] > samples[p, k_hi]:
                k_hi = k
            if samples[p, k] < samples[p, k_lo]:
                k_lo = k
        ext = np.empty(2)
        for e in range(2):
            k0 = k_hi if e == 0 else k_lo
            t = 2.0 * math.pi * k0 / K
            best = samples[p, k0]
            for _ in range(6):
                c1 = math.cos(t)
                s1 = math.sin(t)
                c = c1
                s = s1
                val = a0[p]
                d1 = 0.0
                d2 = 0.0
                for h in range(Hd):
                    q = h + 1.0
                    val += a[p, h] * c + b[p, h] * s
                    d1 += q * (-a[p, h] * s + b[p, h] * c)
                    d2 -= q * q * (a[p, h] * c + b[p, h] * s)
                    c, s = c * c1 - s * s1, s * c1 + c * s1
                if (e == 0 and val > best) or (e == 1 and val < best):
                    best = val
                if d2 == 0.0:
                    break
                dt = -d1 / d2
                if abs(dt) > 2.0 * math.pi / K:
                    break
                t += dt
            ext[e] = best
        out[p] = 0.5 * (ext[0] - ext[1])
    return out


@njit(cache=True)
def fo_compiled_outputs(outfn, itab, ftab, work, n, n_out, omegas, C, amp, tau, ET):
    """A system's compiled outputs ``outfn(t, x, road, itab, ftab, out)`` at the phases
    tau for every point: (P, n_out, K) (NaN where it reports a failure)."""
    n_pts = omegas.shape[0]
    K = tau.shape[0]
    res = np.empty((n_pts, n_out, K))
    x = np.zeros(work)
    out = np.zeros(n_out)
    road = np.empty(3)
    for p in range(n_pts):
        X = np.ascontiguousarray(C[p])
        xs = _state_samples(X, n, ET)
        for k in range(K):
            for i in range(n):
                x[i] = xs[i, k]
            _road(amp, omegas[p], tau[k], road)
            good = outfn(tau[k] / omegas[p], x, road, itab, ftab, out)
            for j in range(n_out):
                res[p, j, k] = out[j] if good else np.nan
    return res


# ---------------------------------------------------------------------------------
# brute force on the same right-hand side: fixed-step RK4, period by period


@njit(cache=True)
def _rk4_period(rhs, itab, ftab, work, n, y0, omega, amp, n_steps, xs_out):
    """One forcing period with n_steps RK4 steps from y0; states at the step starts."""
    h = 2.0 * math.pi / omega / n_steps
    y = np.zeros(work)
    y[:n] = y0[:n]
    k1 = np.zeros(work)
    k2 = np.zeros(work)
    k3 = np.zeros(work)
    k4 = np.zeros(work)
    yt = np.zeros(work)
    road = np.empty(3)
    for s in range(n_steps):
        t = s * h
        for i in range(n):
            xs_out[i, s] = y[i]
        _road(amp, omega, omega * t, road)
        rhs(t, y, road, itab, ftab, k1)
        for i in range(n):
            yt[i] = y[i] + 0.5 * h * k1[i]
        _road(amp, omega, omega * (t + 0.5 * h), road)
        rhs(t + 0.5 * h, yt, road, itab, ftab, k2)
        for i in range(n):
            yt[i] = y[i] + 0.5 * h * k2[i]
        rhs(t + 0.5 * h, yt, road, itab, ftab, k3)
        for i in range(n):
            yt[i] = y[i] + h * k3[i]
        _road(amp, omega, omega * (t + h), road)
        rhs(t + h, yt, road, itab, ftab, k4)
        for i in range(n):
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
    return y[:n].copy()


@njit(cache=True)
def fo_brute_point(rhs, itab, ftab, work, n, y0, omega, amp, n_steps, rtol, max_periods, scales):
    """Integrate from y0 until the periodic orbit settles (as ``_kernels.brute_point``:
    the change of the state over one period, each state relative to its size, and the
    distance to the orbit estimated from the contraction between periods, below ``rtol``
    for two periods running). Returns (end state, samples of the last period (n, n_steps),
    settled, periods, distance)."""
    y = y0[:n].copy()
    xs = np.empty((n, n_steps))
    prev = np.inf
    dist = np.inf
    calm = 0
    for k in range(max_periods):
        yn = _rk4_period(rhs, itab, ftab, work, n, y, omega, amp, n_steps, xs)
        change = 0.0
        for i in range(n):
            size = max(np.max(np.abs(xs[i])), scales[i])
            change = max(change, abs(yn[i] - y[i]) / size)
        rho = change / prev if prev > 0.0 else 0.0
        prev = change
        dist = change * rho / (1.0 - rho) if rho < 0.999 else np.inf
        dist = max(dist, change)
        y = yn
        if dist < rtol:
            calm += 1
        else:
            calm = 0
        if calm >= 2:
            return y, xs, True, k + 1, dist
    return y, xs, False, max_periods, dist


@njit(cache=True)
def fo_monodromy(rhs, itab, ftab, work, n, y0, omega, amp, n_steps, scales):
    """Monodromy matrix of the one-period RK4 map at y0 by central differences."""
    M = np.empty((n, n))
    xs = np.empty((n, n_steps))
    for j in range(n):
        h = 1e-6 * max(abs(y0[j]), scales[j])
        yp = y0[:n].copy()
        ym = y0[:n].copy()
        yp[j] += h
        ym[j] -= h
        fp = _rk4_period(rhs, itab, ftab, work, n, yp, omega, amp, n_steps, xs)
        fm = _rk4_period(rhs, itab, ftab, work, n, ym, omega, amp, n_steps, xs)
        for i in range(n):
            M[i, j] = (fp[i] - fm[i]) / (2.0 * h)
    return M


# ---------------------------------------------------------------------------------
# entry points typed with the function signatures (compiled on first use, cached)

_SYS = (_RHS, _JAC, _b1, _iv, _v, _i8, _i8)  # rhs, jac, has_jac, itab, ftab, work, n
_SYS_R = (_RHS, _iv, _v, _i8, _i8)  # rhs, itab, ftab, work, n
_ENTRY_TYPES = {
    "fo_residual": (*_SYS_R, _v, _f8, _f8, _v, _m, _m, _m),
    "fo_residual_jacobian": (*_SYS, _v, _f8, _f8, _v, _m, _m, _m, _m, _v),
    "fo_newton": (*_SYS, _v, _f8, _f8, _v, _m, _m, _m, _m, _v, _f8, _i8, _f8),
    "fo_sweep": (*_SYS, _v, _v, _v, _f8, _v, _m, _m, _m, _m, _v, _f8, _i8, _f8, _b1),
    "fo_relative_residuals": (*_SYS_R, _v, _m, _f8, _v, _m, _m, _m),
    "fo_hill_matrices": (*_SYS, _v, _m, _a1, _f8, _v, _m, _m, _m, _m, _v),
    "fo_derivative_samples": (*_SYS_R, _v, _m, _f8, _v, _m),
    "_rhs_samples": (*_SYS_R, _m, _f8, _f8, _v),
    "fo_compiled_outputs": (*_SYS_R, _i8, _v, _m, _f8, _v, _m),
    "fo_brute_point": (*_SYS_R, _v, _f8, _f8, _i8, _f8, _i8, _v),
    "fo_monodromy": (*_SYS_R, _v, _f8, _f8, _i8, _v),
}
_TYPED: dict = {}


def _placeholder_jacobian():
    fn = _TYPED.get("no_jacobian")
    if fn is None:
        fn = njit(JACOBIAN_SIGNATURE, cache=True)(_no_jacobian_py)
        _TYPED["no_jacobian"] = fn
    return fn


def kernel(name: str):
    """The compiled entry point ``name`` typed for first-class system functions."""
    fn = _TYPED.get(name)
    if fn is None:
        fn = njit(_ENTRY_TYPES[name], cache=True)(globals()[name].py_func)
        _TYPED[name] = fn
    return fn


# ---------------------------------------------------------------------------------
# engine


def system_tables(system):
    """(int table, float table) of a first-order system."""
    if hasattr(system, "int_table"):
        return system.int_table, system.float_table
    return system.tables


def rest_state(system):
    """The system's rest state (``rest_state`` or ``initial_state()``), or None."""
    rest = getattr(system, "rest_state", None)
    if rest is None and callable(getattr(system, "initial_state", None)):
        rest = system.initial_state()
    return None if rest is None else np.asarray(rest, dtype=float)


def is_first_order(system) -> bool:
    """True for a system given by first-order state equations (``n_states`` and ``rhs``)."""
    return hasattr(system, "rhs") and hasattr(system, "n_states") and not hasattr(system, "kernel")


class FirstOrderEngine:
    """Harmonic-balance engine of a first-order system under a sine input of amplitude A.

    Offers the interface of the second-order engines (``residual``,
    ``residual_jacobian``, ``newton``, ``sweep``, ``relative_residuals``) so the
    scanning and continuation drivers use it unchanged, plus :meth:`stability`.
    """

    def __init__(self, system, basis: FourierBasis, amplitude: float):
        n = int(system.n_states)
        if n < 1:
            raise ParameterError("n_states", n, "an integer >= 1")
        self.system = system
        self.basis = basis
        self.n_dof = n
        self.amplitude = float(amplitude)
        self.work = int(getattr(system, "work_size", n))
        if self.work < n:
            raise ParameterError("work_size", self.work, f"an integer >= n_states = {n}")
        self.rhs = system.rhs
        jac = getattr(system, "jacobian", None)
        self.has_jac = jac is not None
        self.jac = jac if jac is not None else _placeholder_jacobian()
        itab, ftab = system_tables(system)
        self.itab = np.array(itab, dtype=np.int64)  # writable, contiguous copies
        self.ftab = np.array(ftab, dtype=float)
        sc = getattr(system, "state_scales", None)
        self.scales = np.ones(n) if sc is None else np.ascontiguousarray(np.asarray(sc, float)[:n])
        self.ET = np.ascontiguousarray(basis.E.T)
        self.D = np.ascontiguousarray(basis.F @ basis.E1)
        self.E = np.ascontiguousarray(basis.E)
        self.F = np.ascontiguousarray(basis.F)
        self.tau = np.ascontiguousarray(basis.tau)

    # the common prefix of the kernel arguments
    def _a(self):
        return (self.rhs, self.jac, self.has_jac, self.itab, self.ftab, self.work, self.n_dof)

    def _r(self):
        return (self.rhs, self.itab, self.ftab, self.work, self.n_dof)

    def cold_start(self) -> np.ndarray:
        """The rest state as constant terms (zeros when the system gives none)."""
        m = self.basis.size
        X = np.zeros(self.n_dof * m)
        rest = rest_state(self.system)
        if rest is not None:
            X[::m] = np.asarray(rest, dtype=float)[: self.n_dof]
        return X

    def residual(self, X, omega):
        return kernel("fo_residual")(
            *self._r(), np.ascontiguousarray(X, dtype=float), float(omega), self.amplitude,
            self.tau, self.ET, self.D, self.F,
        )  # fmt: skip

    def residual_jacobian(self, X, omega):
        return kernel("fo_residual_jacobian")(
            *self._a(), np.ascontiguousarray(X, dtype=float), float(omega), self.amplitude,
            self.tau, self.E, self.ET, self.D, self.F, self.scales,
        )  # fmt: skip

    def newton(self, X0, omega, rtol, max_iter, scale):
        return kernel("fo_newton")(
            *self._a(), np.ascontiguousarray(X0, dtype=float), float(omega), self.amplitude,
            self.tau, self.E, self.ET, self.D, self.F, self.scales, float(rtol),
            int(max_iter), float(scale),
        )  # fmt: skip

    def sweep(self, omegas, X_start, rtol, max_iter, scale, warm, X_cold=None):
        cold = self.cold_start() if X_cold is None else X_cold
        return kernel("fo_sweep")(
            *self._a(), np.ascontiguousarray(omegas, dtype=float),
            np.ascontiguousarray(X_start, dtype=float), np.ascontiguousarray(cold, dtype=float),
            self.amplitude, self.tau, self.E, self.ET, self.D, self.F, self.scales,
            float(rtol), int(max_iter), float(scale), bool(warm),
        )  # fmt: skip

    def relative_residuals(self, omegas, C):
        return kernel("fo_relative_residuals")(
            *self._r(), np.ascontiguousarray(omegas, dtype=float),
            np.ascontiguousarray(C, dtype=float), self.amplitude, self.tau, self.ET, self.D,
            self.F,
        )  # fmt: skip

    def stability(self, omegas, C, ok, harmonics: int | None = None, samples: int = 256):
        """Floquet exponents by Hill's method with the harmonics 0..``harmonics``
        (default all) and the state Jacobian at ``samples`` phases (at least the
        balance's N): (max Re lambda [1/s] over the n eigenvalues nearest the real
        axis, NaN where unknown; those eigenvalues, (P, n) complex)."""
        hs = self.basis.harmonics if harmonics is None else int(harmonics)
        if not 0 <= hs <= self.basis.harmonics:
            raise ParameterError(
                "stability_harmonics", harmonics, f"0 .. harmonics = {self.basis.harmonics}"
            )
        ns = max(int(samples), self.basis.n_samples)
        bs = fourier_basis(hs, ns)
        ET = np.ascontiguousarray(fourier_basis(self.basis.harmonics, ns).E.T)
        omegas = np.ascontiguousarray(omegas, dtype=float)
        ok = np.ascontiguousarray(ok, dtype=np.bool_)
        H = kernel("fo_hill_matrices")(
            *self._a(), omegas, np.ascontiguousarray(C, dtype=float), ok, self.amplitude,
            np.ascontiguousarray(bs.tau), ET, np.ascontiguousarray(bs.E),
            np.ascontiguousarray(bs.F @ bs.E1), np.ascontiguousarray(bs.F), self.scales,
        )  # fmt: skip
        n = self.n_dof
        best = np.full(len(omegas), np.nan)
        exps = np.full((len(omegas), n), np.nan + 0j)
        good = ok & np.all(np.isfinite(H), axis=(1, 2))
        if good.any():
            lam = np.linalg.eigvals(H[good])
            w = omegas[good][:, None]
            # the copy of each exponent nearest the real axis, n of them (as for the
            # second-order engines)
            order = np.argsort(np.abs(lam.imag) / w, axis=1, kind="stable")
            near = np.take_along_axis(lam, order[:, :n], axis=1)
            exps[good] = near
            best[good] = np.max(near.real, axis=1)
        return best, exps

    def compiled_outputs(self, outfn, n_out, omegas, C, tau):
        """A compiled output function at the phases tau of every point, (P, n_out, K)."""
        tau = np.ascontiguousarray(tau, dtype=float)
        ET = np.ascontiguousarray(fourier_basis(self.basis.harmonics, len(tau)).E.T)
        return kernel("fo_compiled_outputs")(
            outfn, self.itab, self.ftab, self.work, self.n_dof, int(n_out),
            np.ascontiguousarray(omegas, dtype=float), np.ascontiguousarray(C, dtype=float),
            self.amplitude, tau, ET,
        )  # fmt: skip

    def samples(self, omegas, C, tau=None):
        """States and derivatives at the phases ``tau`` (default the N samples) of every
        point, (P, n, K) each."""
        if tau is None:
            tau, ET = self.tau, self.ET
        else:
            tau = np.ascontiguousarray(tau, dtype=float)
            ET = np.ascontiguousarray(fourier_basis(self.basis.harmonics, len(tau)).E.T)
        return kernel("fo_derivative_samples")(
            *self._r(), np.ascontiguousarray(omegas, dtype=float),
            np.ascontiguousarray(C, dtype=float), self.amplitude, tau, ET,
        )  # fmt: skip


def make_first_order_engine(
    system, harmonics: int, n_samples: int | None, amplitude: float
) -> FirstOrderEngine:
    """The engine for a first-order ``system`` (checks as :func:`harmonic.make_engine`)."""
    if not isinstance(harmonics, int | np.integer) or isinstance(harmonics, bool) or harmonics < 1:
        raise ParameterError("harmonics", harmonics, "an integer >= 1")
    degree = int(getattr(system, "nonlinearity_degree", 3))
    n = default_samples(int(harmonics), degree) if n_samples is None else int(n_samples)
    check_samples(int(harmonics), n, degree)
    size = (2 * int(harmonics) + 1) * int(system.n_states)
    check_memory(
        float(n) * size * 3,
        what="harmonic-balance basis (samples x harmonics)",
        parameter="harmonics" if n_samples is None else "n_samples",
        value=harmonics if n_samples is None else n_samples,
    )
    check_memory(
        float(size) ** 2 * 8,
        what="Jacobian and stability matrices",
        parameter="harmonics",
        value=harmonics,
    )
    return FirstOrderEngine(system, fourier_basis(int(harmonics), n), amplitude)


def brute_force_point(
    system,
    omega: float,
    amplitude: float,
    *,
    steps_per_period: int = 4000,
    rtol: float = 1e-10,
    max_periods: int = 2000,
    initial_state=None,
):
    """Steady state of ``system`` at Omega [rad/s] by RK4 on its own right-hand side.

    Returns (end state, state samples of the last period (n, steps), settled, periods).
    """
    n = int(system.n_states)
    work = int(getattr(system, "work_size", n))
    sc = getattr(system, "state_scales", None)
    scales = np.ones(n) if sc is None else np.ascontiguousarray(np.asarray(sc, float)[:n])
    y0 = np.zeros(n) if initial_state is None else np.asarray(initial_state, dtype=float)
    if initial_state is None and rest_state(system) is not None:
        y0 = rest_state(system)[:n].copy()
    it, ft = system_tables(system)
    itab, ftab = np.array(it, dtype=np.int64), np.array(ft, dtype=float)
    y, xs, ok, periods, _ = kernel("fo_brute_point")(
        system.rhs, itab, ftab, work, n, np.ascontiguousarray(y0), float(omega),
        float(amplitude), int(steps_per_period), float(rtol), int(max_periods), scales,
    )  # fmt: skip
    return y, xs, bool(ok), int(periods)


def rhs_samples(system, omega, amplitude, xs, tau):
    """f at the states xs (n, K) and phases tau (K,) under the sine input: (n, K)."""
    n = int(system.n_states)
    return kernel("_rhs_samples")(
        system.rhs, np.array(system_tables(system)[0], dtype=np.int64),
        np.array(system_tables(system)[1], dtype=float), int(getattr(system, "work_size", n)), n,
        np.ascontiguousarray(xs, dtype=float), float(omega), float(amplitude),
        np.ascontiguousarray(tau, dtype=float),
    )  # fmt: skip


def monodromy_multipliers(system, omega, amplitude, state0, *, steps_per_period=4000):
    """Floquet multipliers of the orbit through ``state0`` (RK4 monodromy, central
    differences): independent of the harmonic balance."""
    n = int(system.n_states)
    work = int(getattr(system, "work_size", n))
    sc = getattr(system, "state_scales", None)
    scales = np.ones(n) if sc is None else np.ascontiguousarray(np.asarray(sc, float)[:n])
    M = kernel("fo_monodromy")(
        system.rhs, np.array(system_tables(system)[0], dtype=np.int64),
        np.array(system_tables(system)[1], dtype=float), work, n,
        np.ascontiguousarray(state0, dtype=float), float(omega), float(amplitude),
        int(steps_per_period), scales,
    )  # fmt: skip
    return np.linalg.eigvals(M)
