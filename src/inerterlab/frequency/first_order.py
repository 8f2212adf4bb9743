"""Harmonic balance of state equations (AFT, Newton, Hill): the one engine.

A system here is any object with

``n_states``
    The number n of states taking part in the balance.
``rhs``
    A compiled (numba) function ``rhs(t, x, road, int_table, float_table, out) -> bool``
    writing x' = f into ``out`` (False when it could not, e.g. an internal force balance
    failed: the point then fails as non-finite); ``road`` holds the input
    u = [displacement, velocity, acceleration] at time t and, last, Omega. It is called
    with arrays of length ``work_size`` >= n (states past n are held at zero and their
    derivatives ignored, so a right-hand side that also carries states which do not feed
    back, such as the filters of a metric, is used unchanged). The time integration
    (brute force, monodromy) and the outputs use it.
``int_table``, ``float_table`` (or ``tables`` = both)
    Its parameters (int64 and float64 vectors, contiguous).
``work_size`` (optional, default n), ``state_scales`` (optional: typical magnitude of
    each state, for the finite-difference steps and the settling test), ``jacobian``
    (optional: a compiled ``jacobian(t, x, road, int_table, float_table, out)`` writing
    df/dx, n x n), ``rest_state`` or ``initial_state()`` (optional, the cold start),
    ``nonlinearity_degree`` (aliasing rule).
``terms`` (optional)
    The equations in implicit form r(x, x') = 0, balanced instead of x' - f: a compiled
    ``terms(tau, Omega, A, xs, xds, int_table, float_table, r, P, Q, partials) -> bool``
    writing r (n, K) and, with ``partials``, P = dr/dx, Q = dr/dx' (n, n, K) at every
    phase tau_k = Omega t_k of the states xs and their derivatives xds (n, K), input
    amplitude A, in one call (NaN in r where it could not).
    A second-order system M(x, x') x'' + g = 0 written on (x, x') this way balances
    exactly its own residual, whatever M does within a cycle.
``velocity_of`` (optional)
    ``velocity_of[i] = j`` where x_i' = x_j identically (a position and its velocity),
    else -1. The velocity's coefficients are then Omega D X_i, not unknowns, and the
    position's equation is not balanced: the unknowns are halved for a mechanical system.

The input is a sine of amplitude A: u = [A sin(tau), A Omega cos(tau), -A Omega^2 sin(tau)],
tau = Omega t. Every state is a truncated Fourier series,
x_i(tau) = a0 + sum_h a_h cos(h tau) + b_h sin(h tau), stored block by block as
Y = [X_1, ..., X_nf] (the states that are unknowns), X_i = [a0, a1, b1, ..., aH, bH].
The residual of each balanced equation is

    R_i = Omega D X_i - F f_i(x(tau_k))         (explicit),
    R_i = F r_i(x(tau_k), x'(tau_k))            (implicit, ``terms``),   k = 0 .. N-1,

with D the derivative of the coefficients in tau and F the projection of N samples on
the harmonics; its Jacobian is exact up to the partials at the samples,

    dR_i/dX_j = sum over the states s given by X_j of F diag(dr_i/dx_s) Omega^o E_o
                + F diag(dr_i/dx_s') Omega^(o+1) E_(o+1)

(o = 0 for x_j itself, 1 for the velocity it carries; E_1, E_2 the phase derivatives of
the synthesis E; explicit: dr/dx = -df/dx, dr/dx' = I), where df/dx comes from
``jacobian`` or, without it, from central differences of ``rhs`` at each sample (step
1e-6 of the state's size). Newton with a backtracking line search on ||R|| solves it;
the scanning and continuation drivers of :mod:`inerterlab.frequency.response` run on
this engine for every system (a :class:`~inerterlab.frequency.UserSystem` with its residual
compiled by numba).

Stability (Hill's method): a perturbation e^(lambda t) q(t) with q periodic solves
lambda Qf q = -Jf q with Jf the Jacobian of every state's equation and Qf the
projection of dr/dx' (the identity for explicit systems), so the Floquet exponents are
eigenvalues of -Qf^-1 Jf. Each true exponent appears with copies shifted by multiples of
i Omega; the n eigenvalues nearest the real axis are taken as the exponents (one copy of
each) and the largest real part decides stability. The exponents converge with far fewer
harmonics than the response, so the Hill matrix may be restricted to the harmonics
0..H_s of every state (docs/model.md §7).

The system's functions are handed to the compiled kernels as first-class functions of
fixed signatures (:data:`RHS_SIGNATURE`, :data:`TERMS_SIGNATURE`), so the kernels compile
once and are cached on disk whatever the system is; one call per sample returns
everything the Newton iteration needs there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit, types

from .._views import borrow as _borrow
from ..errors import ParameterError
from ..systems._kernel import road_layout
from .harmonic import FourierBasis, checked_samples, fourier_basis

__all__ = [
    "RHS_SIGNATURE",
    "JACOBIAN_SIGNATURE",
    "TERMS_SIGNATURE",
    "FirstOrderSystem",
    "FirstOrderEngine",
    "make_first_order_engine",
    "is_first_order",
    "brute_force_point",
    "monodromy_multipliers",
    "rhs_samples",
    "half_peak_to_peak",
]

_f8 = types.float64
_v = types.float64[::1]
_iv = types.int64[::1]
_m = types.float64[:, ::1]
#: rhs(t, x, road, int_table, float_table, out) -> ok (False: f could not be evaluated)
RHS_SIGNATURE = types.boolean(_f8, _v, _v, _iv, _v, _v)
#: jacobian(t, x, road, int_table, float_table, out) -> None, out[i, j] = df_i/dx_j
JACOBIAN_SIGNATURE = types.void(_f8, _v, _v, _iv, _v, _m)
_a3 = types.float64[:, :, ::1]
#: terms(tau, omega, amplitude, xs, xds, int_table, float_table, r, P, Q, partials) -> ok,
#: over all samples: xs, xds, r (n, K), P, Q (n, n, K) (written when ``partials``)
TERMS_SIGNATURE = types.boolean(_v, _f8, _f8, _m, _m, _iv, _v, _m, _a3, _a3, types.boolean)
_RHS = types.FunctionType(RHS_SIGNATURE)
_JAC = types.FunctionType(JACOBIAN_SIGNATURE)
_TERMS = types.FunctionType(TERMS_SIGNATURE)
_b1 = types.boolean
_i8 = types.int64
_a1 = types.Array(types.bool_, 1, "C")

FD_STEP = 1e-6  # central-difference step, relative to the state's size


def _no_jacobian_py(t, x, road, itab, ftab, out):  # pragma: no cover - never called
    """Placeholder handed to the kernels when the system has no analytic Jacobian."""
    out[:, :] = 0.0


def _no_terms_py(tau, omega, amp, xs, xds, itab, ftab, r, P, Q, partials):  # pragma: no cover
    """Placeholder handed to the kernels when the system has no implicit form."""
    return False


# ---------------------------------------------------------------------------------
# compiled kernels (the system's functions are arguments, typed by their signature)


#
# ``lay`` (int64) describes which coefficients are unknown: lay[0] = n states,
# lay[1] = nf unknown blocks, then for every state j its block blk[j] (lay[2 + j]) and
# order ordr[j] (lay[2 + n + j]: x_j = (d/dt)^ordr x_blk, 0 or 1), then the state of
# every balanced equation rows[r] (lay[2 + 2 n + r], nf of them). A state j that is the
# derivative of a state i (x_i' = x_j) has no coefficients of its own: x_j = Omega D X_i,
# and the equation of i, satisfied by construction, is not balanced.
# ``mode``: 0 explicit x' = f with finite-difference df/dx, 1 explicit with ``jac``,
# 2 implicit r(x, x') = 0 with ``terms`` (r and its partials at every sample in one call).


#: the road vector of every system this engine drives (one road, then the frequency in
#: the free slot; no held sides): the core's one layout (:func:`.systems._kernel.road_layout`)
ROAD_LEN, FREQ_SLOT, _ = road_layout(1, 0)


@njit(cache=True, inline="always")
def _road(amp, omega, tau, road):
    s = math.sin(tau)
    road[0] = amp * s
    road[1] = amp * omega * math.cos(tau)
    road[2] = -amp * omega * omega * s
    road[FREQ_SLOT] = omega


@njit(cache=True, inline="always")
def _power(omega, k):
    if k == 0:
        return 1.0
    if k == 1:
        return omega
    return omega * omega


@njit(cache=True, inline="always")
def _mv(A, x):
    """A @ x; by loops when small (a BLAS call then costs more than its arithmetic)."""
    rows, cols = A.shape
    if rows * cols > 256:
        return A @ x
    out = np.zeros(rows)
    for i in range(rows):
        acc = 0.0
        for j in range(cols):
            acc += A[i, j] * x[j]
        out[i] = acc
    return out


@njit(cache=True, inline="always")
def _synth(Y, lay, omega, E, E1, E2, derivatives):
    """States xs (n, K) and, with ``derivatives``, their time derivatives xds (n, K) at
    the phases of E (K x m) from the unknown coefficients Y (each product E_k Y_c once)."""
    n, nf = lay[0], lay[1]
    K, m = E.shape
    xs = np.empty((n, K))
    xds = np.empty((n, K) if derivatives else (1, 1))
    for c in range(nf):
        need = np.zeros(3, dtype=np.bool_)
        for j in range(n):
            if lay[2 + j] == c:
                o = lay[2 + n + j]
                need[o] = True
                if derivatives:
                    need[o + 1] = True
        Yc = Y[c * m : (c + 1) * m]
        s0 = _mv(E, Yc) if need[0] else np.empty(0)
        s1 = omega * _mv(E1, Yc) if need[1] else np.empty(0)
        s2 = omega * omega * _mv(E2, Yc) if need[2] else np.empty(0)
        for j in range(n):
            if lay[2 + j] != c:
                continue
            o = lay[2 + n + j]
            xs[j] = s0 if o == 0 else s1
            if derivatives:
                xds[j] = s1 if o == 0 else s2
    return xs, xds


@njit(cache=True)
def _evaluate(
    rhs, jac, terms, mode, itab, ftab, work, lay, xs, xds, omega, amp, tau, scales, want,
    central,
):  # fmt: skip
    """r (n, K) at the samples (explicit systems: r = -f, the x' term is added by the
    projection), and with ``want`` P = dr/dx and Q = dr/dx' (n, n, K; explicit: P = -df/dx
    by ``jac`` or central/forward differences, Q unused). The callers pass ``want`` and
    ``central`` as ``np.bool_``: a literal ``True`` or ``False`` would compile this
    function once for each combination (three copies in a first frequency response)."""
    n = lay[0]
    K = tau.shape[0]
    r = np.empty((n, K))
    if mode == 2:  # one call for every sample
        P = np.empty((n, n, K) if want else (1, 1, 1))
        Q = np.empty((n, n, K) if want else (1, 1, 1))
        terms(tau, omega, amp, xs, xds, itab, ftab, r, P, Q, want)
        return r, P, Q
    x0 = np.zeros(work)
    out0 = np.zeros(work)
    outp0 = np.zeros(work)
    road0 = np.empty(ROAD_LEN)
    P = np.empty((n, n, K) if want else (1, 1, 1))
    Q = np.empty((1, 1, 1))
    Pk0 = np.zeros((n, n))
    x, out, outp, road, Pk = (
        _borrow(x0),
        _borrow(out0),
        _borrow(outp0),
        _borrow(road0),
        _borrow(Pk0),
    )
    itab, ftab = _borrow(itab), _borrow(ftab)
    for k in range(K):
        for i in range(n):
            x[i] = xs[i, k]
        _road(amp, omega, tau[k], road)
        t = tau[k] / omega
        good = rhs(t, x, road, itab, ftab, out)
        for i in range(n):
            r[i, k] = -out[i] if good else np.nan
        if not want:
            continue
        if mode == 1:
            jac(t, x, road, itab, ftab, Pk)
            for i in range(n):
                for j in range(n):
                    P[i, j, k] = -Pk[i, j]
            continue
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
                    P[i, j, k] = -(outp[i] - out[i]) / (2.0 * h)
            else:
                x[j] = xj
                for i in range(n):
                    P[i, j, k] = -(outp[i] + r[i, k]) / h
    return r, P, Q


@njit(cache=True, inline="always")
def _project(Y, omega, r, mode, lay, F, D1, D2):
    """The balance R of every balanced equation: F r_i (plus Omega^(o+1) D_(o+1) X for
    the x' term of an explicit equation)."""
    n, nf = lay[0], lay[1]
    m = F.shape[0]
    R = np.empty(nf * m)
    for q in range(nf):
        i = lay[2 + 2 * n + q]
        seg = _mv(F, r[i])
        if mode < 2:
            c = lay[2 + i]
            Yc = Y[c * m : (c + 1) * m]
            if lay[2 + n + i] == 0:
                seg += omega * (D1 @ Yc)
            else:
                seg += omega * omega * (D2 @ Yc)
        R[q * m : (q + 1) * m] = seg
    return R


@njit(cache=True, inline="always")
def _add_constant(J, r0, c0, a, k, D1, D2):
    """J[block] += a D_k (D_0 = I): the projection of a constant times E_k."""
    m = D1.shape[0]
    if k == 0:
        for s in range(m):
            J[r0 + s, c0 + s] += a
    else:
        Dk = D1 if k == 1 else D2
        for s in range(m):
            for u in range(m):
                J[r0 + s, c0 + u] += a * Dk[s, u]


@njit(cache=True, inline="always")
def _is_constant(A, i, j):
    a0 = A[i, j, 0]
    for k in range(1, A.shape[2]):
        if A[i, j, k] != a0:
            return False
    return True


@njit(cache=True, inline="always")
def _sums(W, coef):
    """W @ coef; by loops when small (a BLAS call then costs more than its arithmetic)."""
    rows, K = W.shape
    if rows * K > 512:
        return W @ coef
    S = np.zeros((rows, 3))
    for p in range(rows):
        for kk in range(K):
            w = W[p, kk]
            S[p, 0] += w * coef[kk, 0]
            S[p, 1] += w * coef[kk, 1]
            S[p, 2] += w * coef[kk, 2]
    return S


@njit(cache=True, inline="always")
def _fill_spectral(J, r0, c0, S, has, H):
    """J[block at (r0, c0)] += T(c_0) + T(c_1) D + T(c_2) D^2 with T(c) = F diag(c) E.

    ``S[:, k]`` = [a_0 .. a_2H, b_1 .. b_2H], the discrete Fourier sums of the samples
    c_k (a_p = sum_j c_j cos(p tau_j) / N, b_p with sin). A product of two trigonometric
    functions is a sum of two, so each entry of T is two of these sums (exact for the
    discrete sums, whatever N): with d = h - k and p = h + k,
    T[cos h, cos k] = a_d + a_p, T[sin h, sin k] = a_d - a_p,
    T[cos h, sin k] = b_p - b_d, T[sin h, cos k] = b_p + b_d (b_-d = -b_d), and the
    constant row and column are a_k, b_k and 2 a_h, 2 b_h (a_0 at the corner). D, the
    derivative of the coefficients, maps the cos column of harmonic k to -k times the
    sin column and the sin column to k times the cos column."""
    w0 = 1.0 if has[0] else 0.0
    w1 = 1.0 if has[1] else 0.0
    w2 = 1.0 if has[2] else 0.0
    for h in range(H + 1):
        for k in range(H + 1):
            p = h + k
            d = h - k
            ad = abs(d)
            # the sums of each coefficient: a_d, a_p, b_d (signed), b_p
            a_d0 = S[ad, 0] * w0
            a_p0 = S[p, 0] * w0
            a_d1 = S[ad, 1] * w1
            a_p1 = S[p, 1] * w1
            a_d2 = S[ad, 2] * w2
            a_p2 = S[p, 2] * w2
            b_p0 = S[2 * H + p, 0] * w0 if p > 0 else 0.0
            b_p1 = S[2 * H + p, 1] * w1 if p > 0 else 0.0
            b_p2 = S[2 * H + p, 2] * w2 if p > 0 else 0.0
            b_d0 = 0.0
            b_d1 = 0.0
            b_d2 = 0.0
            if d != 0:
                sg = 1.0 if d > 0 else -1.0
                b_d0 = sg * S[2 * H + ad, 0] * w0
                b_d1 = sg * S[2 * H + ad, 1] * w1
                b_d2 = sg * S[2 * H + ad, 2] * w2
            if h == 0 and k == 0:
                J[r0, c0] += a_p0
                continue
            if h == 0:  # constant row, columns cos k, sin k
                ck = c0 + 2 * k - 1
                J[r0, ck] += a_p0 - k * b_p1 - k * k * a_p2
                J[r0, ck + 1] += b_p0 + k * a_p1 - k * k * b_p2
                continue
            rc = r0 + 2 * h - 1
            if k == 0:  # constant column
                J[rc, c0] += 2.0 * a_p0
                J[rc + 1, c0] += 2.0 * b_p0
                continue
            ck = c0 + 2 * k - 1
            kk = k * k
            # T entries of each coefficient
            cc0, ss0, cs0, sc0 = a_d0 + a_p0, a_d0 - a_p0, b_p0 - b_d0, b_p0 + b_d0
            cc1, ss1, cs1, sc1 = a_d1 + a_p1, a_d1 - a_p1, b_p1 - b_d1, b_p1 + b_d1
            cc2, ss2, cs2, sc2 = a_d2 + a_p2, a_d2 - a_p2, b_p2 - b_d2, b_p2 + b_d2
            J[rc, ck] += cc0 - k * cs1 - kk * cc2
            J[rc, ck + 1] += cs0 + k * cc1 - kk * cs2
            J[rc + 1, ck] += sc0 - k * ss1 - kk * sc2
            J[rc + 1, ck + 1] += ss0 + k * sc1 - kk * ss2


@njit(cache=True)
def _jacobian(P, Q, mode, omega, lay, D1, D2, W):
    """dR/dY of the balanced equations in the unknown blocks. Block (q, c) sums, over
    the states j given by block c, F diag(P_ij) Omega^o E_o + F diag(Q_ij) Omega^(o+1)
    E_(o+1) (o the order of j; explicit equations: Q = identity, added as Omega D).

    The coefficients c_k of each E_k are summed per sample; with E_k = E D^k (D the
    derivative of the coefficients, exact), the block is T(c_0) + T(c_1) D + T(c_2) D^2,
    T(c) = F diag(c) E, and T(c) follows from the discrete Fourier sums of c up to
    harmonic 2H (one product with ``W``, (4H+1) x N): O(H N) per coefficient instead of
    the O(H^2 N) of forming F diag(c) E. A block whose terms are all constant in time is
    a sum of D_k directly (F E_k = D_k)."""
    n, nf = lay[0], lay[1]
    K = P.shape[2]
    m = D1.shape[0]
    H = (m - 1) // 2
    J = np.zeros((nf * m, nf * m))
    coef = np.zeros((K, 3))
    has = np.zeros(3, dtype=np.bool_)
    const = np.ones((2, n, n), dtype=np.bool_)
    for q in range(nf):
        i = lay[2 + 2 * n + q]
        for j in range(n):
            const[0, i, j] = _is_constant(P, i, j)
            if mode == 2:
                const[1, i, j] = _is_constant(Q, i, j)
    for q in range(nf):
        i = lay[2 + 2 * n + q]
        for c in range(nf):
            varying = False
            for j in range(n):
                if lay[2 + j] == c and not (const[0, i, j] and const[1, i, j]):
                    varying = True
            has[:] = False
            for j in range(n):
                if lay[2 + j] != c:
                    continue
                o = lay[2 + n + j]
                for which in range(2 if mode == 2 else 1):
                    A = P if which == 0 else Q
                    k = o + which
                    fac = _power(omega, k)
                    if const[which, i, j] and A[i, j, 0] == 0.0:
                        continue
                    if not varying:
                        _add_constant(J, q * m, c * m, A[i, j, 0] * fac, k, D1, D2)
                        continue
                    if has[k]:
                        for kk in range(K):
                            coef[kk, k] += A[i, j, kk] * fac
                    else:
                        for kk in range(K):
                            coef[kk, k] = A[i, j, kk] * fac
                        has[k] = True
            if varying:
                for k in range(3):
                    if not has[k]:
                        coef[:, k] = 0.0
                _fill_spectral(J, q * m, c * m, _sums(W, coef), has, H)
            if mode < 2 and lay[2 + i] == c:  # the x' term of an explicit equation
                k = lay[2 + n + i] + 1
                _add_constant(J, q * m, c * m, _power(omega, k), k, D1, D2)
    return J


def spectral_sums(basis) -> np.ndarray:
    """W, (4H+1) x N: W @ c gives [a_0 .. a_2H, b_1 .. b_2H] of samples c at the
    basis's phases (a_p = sum_j c_j cos(p tau_j) / N, b_p with sin)."""
    H, N = basis.harmonics, basis.n_samples
    p = np.arange(2 * H + 1)[:, None]
    tau = np.asarray(basis.tau)[None, :]
    return np.ascontiguousarray(
        np.vstack([np.cos(p * tau), np.sin(p[1:] * tau)]) / N, dtype=float
    )


@njit(cache=True)
def fo_residual(
    rhs, jac, terms, mode, itab, ftab, work, lay, Y, omega, amp, tau, E, E1, E2, F, D1, D2, W
):
    """R(Y) at Omega."""
    xs, xds = _synth(Y, lay, omega, E, E1, E2, mode == 2)
    r, _, _ = _evaluate(
        rhs, jac, terms, mode, itab, ftab, work, lay, xs, xds, omega, amp, tau, tau,
        np.bool_(False), np.bool_(True),
    )  # fmt: skip
    return _project(Y, omega, r, mode, lay, F, D1, D2)


@njit(cache=True)
def fo_residual_jacobian(
    rhs, jac, terms, mode, itab, ftab, work, lay, Y, omega, amp, tau, E, E1, E2, F, D1, D2, W,
    scales,
):  # fmt: skip
    """R(Y) and dR/dY at Omega."""
    R, P, Q = _residual_partials(
        rhs, jac, terms, mode, itab, ftab, work, lay, Y, omega, amp, tau, E, E1, E2, F, D1, D2,
        scales,
    )  # fmt: skip
    return R, _jacobian(P, Q, mode, omega, lay, D1, D2, W)


@njit(cache=True)
def _residual_partials(
    rhs, jac, terms, mode, itab, ftab, work, lay, Y, omega, amp, tau, E, E1, E2, F, D1, D2,
    scales,
):  # fmt: skip
    """R(Y) at Omega and the partials P, Q at the samples (see :func:`_evaluate`)."""
    xs, xds = _synth(Y, lay, omega, E, E1, E2, mode == 2)
    r, P, Q = _evaluate(
        rhs, jac, terms, mode, itab, ftab, work, lay, xs, xds, omega, amp, tau, scales,
        np.bool_(True), np.bool_(True),
    )  # fmt: skip
    return _project(Y, omega, r, mode, lay, F, D1, D2), P, Q


@njit(cache=True)
def _small_solve(J, b):
    """J^-1 b by Gaussian elimination with partial pivoting (for small J, where LAPACK's
    call costs more than its arithmetic); (x, False) when a pivot is exactly zero."""
    n = J.shape[0]
    A = J.copy()
    x = b.copy()
    for k in range(n):
        p = k
        best = abs(A[k, k])
        for i in range(k + 1, n):
            v = abs(A[i, k])
            if v > best:
                best = v
                p = i
        if best == 0.0 or not np.isfinite(best):
            return x, False
        if p != k:
            for j in range(n):
                t = A[k, j]
                A[k, j] = A[p, j]
                A[p, j] = t
            t = x[k]
            x[k] = x[p]
            x[p] = t
        piv = A[k, k]
        for i in range(k + 1, n):
            f = A[i, k] / piv
            if f != 0.0:
                for j in range(k + 1, n):
                    A[i, j] -= f * A[k, j]
                x[i] -= f * x[k]
    for k in range(n - 1, -1, -1):
        acc = x[k]
        for j in range(k + 1, n):
            acc -= A[k, j] * x[j]
        x[k] = acc / A[k, k]
    return x, True


#: unknowns up to which Newton solves by :func:`_small_solve` rather than LAPACK
SMALL_SOLVE = 24


@njit(cache=True)
def _newton_step(J, R):
    """-J^-1 R; where J is singular (a state whose mean value the equations leave free,
    e.g. a node held by a damper and an inerter only) the least-squares step of
    smallest norm, which leaves such a mean where it is."""
    n = R.shape[0]
    if n <= SMALL_SOLVE:
        dX, ok = _small_solve(J, -R)
    else:
        ok = True
        try:
            dX = np.linalg.solve(J, -R)
        except Exception:  # noqa: BLE001 - LAPACK reports a singular matrix
            ok = False
            dX = np.zeros_like(R)
    if ok and np.all(np.isfinite(dX)):
        # reject the solve when it amplifies round-off (near-singular J)
        big = 0.0
        for i in range(n):
            for j in range(n):
                big = max(big, abs(J[i, j]))
        if _norm(dX) * 1e-12 * big <= _norm(R) + 1e-300:
            return dX
    return np.linalg.lstsq(J, -R, rcond=1e-12)[0]


@njit(cache=True, inline="always")
def _norm(v):
    return math.sqrt(np.sum(v * v))


@njit(cache=True)
def fo_newton(
    rhs, jac, terms, mode, itab, ftab, work, lay, Y0, omega, amp, tau, E, E1, E2, F, D1, D2, W,
    scales, rtol, max_iter, scale,
):  # fmt: skip
    """Newton with backtracking on ||R||: Y, converged, iterations, ||R||, code.

    Converged when a full step is below ``rtol * (||Y|| + scale)``. Codes: 0 ok,
    1 iteration limit, 2 singular Jacobian, 3 no descent (line search failed),
    4 non-finite values. With an analytic Jacobian (``mode`` 1, 2) every trial point
    carries its partials (one evaluation per iteration when the full step is taken), and
    the Jacobian is assembled from them only when another iteration needs it (not at
    the converged point); with finite differences the trials evaluate the residual only.
    """
    Y = Y0.copy()
    R, J = fo_residual_jacobian(
        rhs, jac, terms, mode, itab, ftab, work, lay, Y, omega, amp, tau, E, E1, E2, F, D1, D2, W,
        scales,
    )  # fmt: skip
    rn = _norm(R)
    analytic = mode > 0
    for it in range(max_iter):
        if not np.isfinite(rn):
            return Y, False, it, rn, 4
        dY = _newton_step(J, R)
        if not np.all(np.isfinite(dY)):
            return Y, False, it, rn, 2
        step = 1.0
        accepted = False
        Yn = Y
        Rn = R
        Pn = np.empty((1, 1, 1))
        Qn = np.empty((1, 1, 1))
        rnn = rn
        for _ in range(12):
            Yn = Y + step * dY
            if analytic:
                Rn, Pn, Qn = _residual_partials(
                    rhs, jac, terms, mode, itab, ftab, work, lay, Yn, omega, amp, tau, E, E1,
                    E2, F, D1, D2, scales,
                )  # fmt: skip
            else:
                Rn = fo_residual(
                    rhs, jac, terms, mode, itab, ftab, work, lay, Yn, omega, amp, tau, E, E1,
                    E2, F, D1, D2, W,
                )  # fmt: skip
            rnn = _norm(Rn)
            if np.isfinite(rnn) and (rnn <= (1.0 - 1e-4 * step) * rn or rnn < 1e-300):
                accepted = True
                break
            step *= 0.5
        if not accepted:
            # at the round-off floor a full step cannot reduce ||R|| any further
            small = _norm(dY) <= 1e3 * rtol * (_norm(Y) + scale)
            return Y, small, it, rn, 0 if small else 3
        Y = Yn
        R = Rn
        rn = rnn
        if step == 1.0 and _norm(dY) <= rtol * (_norm(Y) + scale):
            return Y, True, it + 1, rn, 0
        if analytic:
            J = _jacobian(Pn, Qn, mode, omega, lay, D1, D2, W)
        else:
            R, J = fo_residual_jacobian(
                rhs, jac, terms, mode, itab, ftab, work, lay, Y, omega, amp, tau, E, E1, E2, F,
                D1, D2, W, scales,
            )  # fmt: skip
            rn = _norm(R)
    return Y, False, max_iter, rn, 1


@njit(cache=True)
def _chord(
    rhs, jac, terms, mode, itab, ftab, work, lay, Y0, omega, amp, tau, E, E1, E2, F, D1, D2, W,
    Jinv, rtol, scale, max_iter,
):  # fmt: skip
    """Quasi-Newton iterations from the inverse Jacobian of a nearby point, improved by
    Broyden's rank-one updates (Jinv is updated in place and carried to the next point).
    Gives up as soon as a step does not shrink the previous one by half. Returns Y,
    converged, iterations, ||R||."""
    Y = Y0.copy()
    prev = np.inf
    R = fo_residual(
        rhs, jac, terms, mode, itab, ftab, work, lay, Y, omega, amp, tau, E, E1, E2, F, D1, D2, W
    )
    rn = _norm(R)
    for it in range(max_iter):
        if not np.isfinite(rn):
            return Y, False, it, rn
        dY = -(Jinv @ R)
        size = _norm(dY)
        if size > 0.5 * prev:
            return Y, False, it, rn
        Y = Y + dY
        prev = size
        if size <= rtol * (_norm(Y) + scale):
            return Y, True, it + 1, rn
        Rn = fo_residual(
            rhs, jac, terms, mode, itab, ftab, work, lay, Y, omega, amp, tau, E, E1, E2, F, D1,
            D2, W,
        )  # fmt: skip
        u = Jinv @ (Rn - R)
        den = dY @ u
        if den != 0.0:
            v = dY @ Jinv
            Jinv += np.outer((dY - u) / den, v)
        R = Rn
        rn = _norm(R)
    return Y, False, max_iter, rn


@njit(cache=True)
def fo_sweep(
    rhs, jac, terms, mode, itab, ftab, work, lay, omegas, Y_start, Y_cold, amp, tau, E, E1, E2,
    F, D1, D2, W, scales, rtol, max_iter, scale, warm, chord,
):  # fmt: skip
    """Solve at each frequency of ``omegas`` in order.

    With ``warm`` each point starts from the last converged solution, extrapolated
    linearly in frequency from the two last ones (the scanning method, (7.23)-(7.32));
    a point that fails is retried through up to 8 intermediate frequencies from the
    last converged point and then from ``Y_cold`` (past a fold the response jumps to
    another branch, which a warm start cannot reach). Without ``warm`` every point starts
    from ``Y_cold``. With ``chord`` (and ``warm``) a point is first tried by chord
    iterations with the inverse Jacobian of an earlier point (a few residual evaluations
    when the frequency step is small: worth it where the Jacobian costs finite
    differences), then by full Newton."""
    n_pts = omegas.shape[0]
    m = Y_start.shape[0]
    out = np.zeros((n_pts, m))
    ok = np.zeros(n_pts, dtype=np.bool_)
    iters = np.zeros(n_pts, dtype=np.int64)
    res = np.zeros(n_pts)
    code = np.zeros(n_pts, dtype=np.int64)
    Y_last = Y_start.copy()
    Y_prev = Y_start.copy()
    w_last = -1.0
    w_prev = -1.0
    Jinv = np.zeros((m, m))
    have_jinv = False
    for i in range(n_pts):
        w = omegas[i]
        if warm:
            guess = Y_last.copy()
            if w_prev > 0.0 and w_last != w_prev:
                guess = Y_last + (Y_last - Y_prev) * ((w - w_last) / (w_last - w_prev))
        else:
            guess = Y_cold.copy()
        conv = False
        it = 0
        c = 0
        rn = np.inf
        Y = guess
        if warm and chord and have_jinv:
            Y, conv, it, rn = _chord(
                rhs, jac, terms, mode, itab, ftab, work, lay, guess, w, amp, tau, E, E1, E2, F,
                D1, D2, W, Jinv, rtol, scale, 12,
            )  # fmt: skip
            if not conv:
                Y = guess
        if not conv:
            Y, conv, its, rn, c = fo_newton(
                rhs, jac, terms, mode, itab, ftab, work, lay, guess, w, amp, tau, E, E1, E2, F,
                D1, D2, W, scales, rtol, max_iter, scale,
            )  # fmt: skip
            it += its
            if conv and warm and chord:
                _, J = fo_residual_jacobian(
                    rhs, jac, terms, mode, itab, ftab, work, lay, Y, w, amp, tau, E, E1, E2, F,
                    D1, D2, W, scales,
                )  # fmt: skip
                Jinv = np.ascontiguousarray(np.linalg.pinv(J, rcond=1e-12))
                have_jinv = np.all(np.isfinite(Jinv))
        if not conv and warm and w_last > 0.0:
            # retry through intermediate frequencies from the last converged point
            Ys = Y_last.copy()
            conv = True
            for s in range(1, 9):
                ws = w_last + (w - w_last) * s / 8
                Ys, cs, its, rn, c = fo_newton(
                    rhs, jac, terms, mode, itab, ftab, work, lay, Ys, ws, amp, tau, E, E1, E2,
                    F, D1, D2, W, scales, rtol, max_iter, scale,
                )  # fmt: skip
                it += its
                if not cs:
                    conv = False
                    break
            Y = Ys
            if not conv:
                # a jump (fold passed): start afresh from the cold start
                Y, conv, its, rn, c = fo_newton(
                    rhs, jac, terms, mode, itab, ftab, work, lay, Y_cold, w, amp, tau, E, E1,
                    E2, F, D1, D2, W, scales, rtol, max_iter, scale,
                )  # fmt: skip
                it += its
            have_jinv = False
        out[i] = Y
        ok[i] = conv
        iters[i] = it
        res[i] = rn
        code[i] = c
        if conv:
            Y_prev = Y_last
            w_prev = w_last
            Y_last = Y
            w_last = w
    return out, ok, iters, res, code


@njit(cache=True)
def fo_relative_residuals(
    rhs, jac, terms, mode, itab, ftab, work, lay, omegas, C, amp, tau, E, E1, E2, F, D1, D2, W
):  # fmt: skip
    """||R(Y_i)|| / ||R(0)|| for each row Y_i of C at frequency omegas[i]."""
    n_pts, m = C.shape
    out = np.empty(n_pts)
    zero = np.zeros(m)
    for i in range(n_pts):
        Y = np.ascontiguousarray(C[i])
        w = omegas[i]
        a = _norm(fo_residual(rhs, jac, terms, mode, itab, ftab, work, lay, Y, w, amp, tau, E,
                              E1, E2, F, D1, D2, W))  # fmt: skip
        b = _norm(fo_residual(rhs, jac, terms, mode, itab, ftab, work, lay, zero, w, amp, tau,
                              E, E1, E2, F, D1, D2, W))  # fmt: skip
        out[i] = a / b if b > 0.0 else a
    return out


@njit(cache=True)
def fo_hill_matrices(
    rhs, jac, terms, mode, itab, ftab, work, lay, omegas, C, ok, amp, tau, E, E1, E2, Es, Fs,
    Ds, scales,
):  # fmt: skip
    """The Hill matrix of every converged point (NaN where not converged), shape
    (P, n ms, n ms) with ms = 2 hs + 1 the harmonics 0..hs of the basis Es, Fs, Ds.

    The states and their derivatives are synthesised at the phases ``tau`` (which may
    be denser than the balance's: the state Jacobian jumps where the flywheel saturates,
    and the quadrature of a jump converges only as 1/N) from the unknown coefficients
    by E, E1, E2. A perturbation e^(lambda t) q(t) of the solution solves
    P q + Q q' = 0 (explicit systems: P = -df/dx, Q = I), so with the blocks
    Jf_ij = Fs diag(P_ij) Es + Fs diag(Q_ij) Es Omega Ds and Qf_ij = Fs diag(Q_ij) Es,
    lambda Qf q = -Jf q: the matrix is -Qf^-1 Jf. Its eigenvalues approximate the
    Floquet exponents and their copies shifted by i k Omega."""
    n = lay[0]
    n_pts = omegas.shape[0]
    K, ms = Es.shape
    nm = n * ms
    out = np.full((n_pts, nm, nm), np.nan)
    G = np.empty((K, ms))
    for p in range(n_pts):
        if not ok[p]:
            continue
        w = omegas[p]
        Y = np.ascontiguousarray(C[p])
        xs, xds = _synth(Y, lay, w, E, E1, E2, mode == 2)
        _, P, Q = _evaluate(
            rhs, jac, terms, mode, itab, ftab, work, lay, xs, xds, w, amp, tau, scales,
            np.bool_(True), np.bool_(False),
        )  # fmt: skip
        Jf = np.zeros((nm, nm))
        Qf = np.zeros((nm, nm))
        for i in range(n):
            for j in range(n):
                for which in range(2 if mode == 2 else 1):
                    A = P if which == 0 else Q
                    if _is_constant(A, i, j):
                        a = A[i, j, 0]
                        if a == 0.0:
                            continue
                        if which == 0:
                            for s in range(ms):
                                Jf[i * ms + s, j * ms + s] += a
                        else:
                            for s in range(ms):
                                Qf[i * ms + s, j * ms + s] += a
                                for u in range(ms):
                                    Jf[i * ms + s, j * ms + u] += a * w * Ds[s, u]
                        continue
                    for kk in range(K):
                        for s in range(ms):
                            G[kk, s] = A[i, j, kk] * Es[kk, s]
                    B = Fs @ G
                    if which == 0:
                        Jf[i * ms : (i + 1) * ms, j * ms : (j + 1) * ms] += B
                    else:
                        Qf[i * ms : (i + 1) * ms, j * ms : (j + 1) * ms] += B
                        Jf[i * ms : (i + 1) * ms, j * ms : (j + 1) * ms] += w * (B @ Ds)
        if mode < 2:
            for i in range(n):
                for s in range(ms):
                    for u in range(ms):
                        Jf[i * ms + s, i * ms + u] += w * Ds[s, u]
            out[p] = -Jf
        else:
            out[p] = -np.linalg.solve(Qf, Jf)
    return out


@njit(cache=True)
def fo_derivative_samples(
    rhs, jac, terms, mode, itab, ftab, work, lay, omegas, C, amp, tau, E, E1, E2
):  # fmt: skip
    """States and their derivatives x' = f at the phases of E for every point:
    (P, n, K) each (``rhs``)."""
    n = lay[0]
    n_pts = omegas.shape[0]
    K = tau.shape[0]
    xs_all = np.empty((n_pts, n, K))
    f_all = np.empty((n_pts, n, K))
    for p in range(n_pts):
        Y = np.ascontiguousarray(C[p])
        xs, _ = _synth(Y, lay, omegas[p], E, E1, E2, False)
        xs_all[p] = xs
        f_all[p] = _rhs_samples(rhs, itab, ftab, work, n, xs, omegas[p], amp, tau)
    return xs_all, f_all


@njit(cache=True)
def _rhs_samples(rhs, itab, ftab, work, n, xs, omega, amp, tau):
    """f(t_k, x(tau_k), u(tau_k)) for every sample, shape (n, K)."""
    K = tau.shape[0]
    x0 = np.zeros(work)
    out0 = np.zeros(work)
    road0 = np.empty(ROAD_LEN)
    x, out, road = _borrow(x0), _borrow(out0), _borrow(road0)
    itab, ftab = _borrow(itab), _borrow(ftab)
    f = np.empty((n, K))
    for k in range(K):
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
def fo_compiled_outputs(outfn, itab, ftab, work, lay, n_out, omegas, C, amp, tau, E, E1, E2):
    """A system's compiled outputs ``outfn(t, x, road, itab, ftab, out) -> bool`` at the
    phases of E for every point: (P, n_out, K) (NaN where it reports a failure)."""
    n = lay[0]
    n_pts = omegas.shape[0]
    K = tau.shape[0]
    res = np.empty((n_pts, n_out, K))
    for p in range(n_pts):
        Y = np.ascontiguousarray(C[p])
        xs, _ = _synth(Y, lay, omegas[p], E, E1, E2, False)
        res[p] = _outputs_at(outfn, itab, ftab, work, n, n_out, xs, omegas[p], amp, tau)
    return res


@njit(cache=True)
def _outputs_at(outfn, itab, ftab, work, n, n_out, xs, omega, amp, tau):
    K = tau.shape[0]
    res = np.empty((n_out, K))
    x0 = np.zeros(work)
    out0 = np.zeros(max(n_out, work))  # the outputs first, then room for their work
    road0 = np.empty(ROAD_LEN)
    x, out, road = _borrow(x0), _borrow(out0), _borrow(road0)
    itab, ftab = _borrow(itab), _borrow(ftab)
    for k in range(K):
        for i in range(n):
            x[i] = xs[i, k]
        _road(amp, omega, tau[k], road)
        good = outfn(tau[k] / omega, x, road, itab, ftab, out)
        for j in range(n_out):
            res[j, k] = out[j] if good else np.nan
    return res


@njit(cache=True)
def fo_outputs_at_states(outfn, itab, ftab, work, n, n_out, xs, omega, amp, tau):
    """Compiled outputs at given states xs (n, K) and phases tau: (n_out, K)."""
    return _outputs_at(outfn, itab, ftab, work, n, n_out, xs, omega, amp, tau)


@njit(cache=True, inline="always")
def _refined_extreme(a0, a, b, t, best, limit, top):
    """The largest (``top``) or smallest value of the trigonometric polynomial
    a0 + sum_h a_h cos(h t) + b_h sin(h t) met by Newton on its derivative from the phase
    t (at most 6 steps, each shorter than ``limit``), or ``best`` if that is beyond."""
    H = a.shape[0]
    for it in range(7):
        c1 = math.cos(t)
        s1 = math.sin(t)
        c = c1
        s = s1
        val = a0
        d1 = 0.0
        d2 = 0.0
        for h in range(H):
            q = h + 1.0
            val += a[h] * c + b[h] * s
            d1 += q * (-a[h] * s + b[h] * c)
            d2 -= q * q * (a[h] * c + b[h] * s)
            c, s = c * c1 - s * s1, s * c1 + c * s1
        if (top and val > best) or (not top and val < best):
            best = val
        if it == 6 or d2 == 0.0:
            break
        dt = -d1 / d2
        if abs(dt) > limit:
            break
        t += dt
    return best


@njit(cache=True)
def half_peak_to_peak(C):
    """Half peak-to-peak [same unit as X] of the signals with coefficients C (rows).

    ``C`` holds for each point the samples' coefficients in the cos/sin basis
    [a0, a1, b1, ..., aH, bH]; the extremes are found on a grid of 16 H + 32 phases
    and refined by Newton on the trigonometric polynomial.
    """
    n_pts, m = C.shape
    H = (m - 1) // 2
    ng = 16 * H + 32
    out = np.empty(n_pts)
    cg = np.empty((ng, H))
    sg = np.empty((ng, H))
    for k in range(ng):
        t = 2.0 * math.pi * k / ng
        for h in range(H):
            cg[k, h] = math.cos((h + 1) * t)
            sg[k, h] = math.sin((h + 1) * t)
    for i in range(n_pts):
        best_hi = -1e300
        best_lo = 1e300
        k_hi = 0
        k_lo = 0
        for k in range(ng):
            val = C[i, 0]
            for h in range(H):
                val += C[i, 2 * h + 1] * cg[k, h] + C[i, 2 * h + 2] * sg[k, h]
            if val > best_hi:
                best_hi = val
                k_hi = k
            if val < best_lo:
                best_lo = val
                k_lo = k
        a = C[i, 1::2]
        b = C[i, 2::2]
        step = 2.0 * math.pi / ng
        hi = _refined_extreme(C[i, 0], a, b, step * k_hi, best_hi, step, True)
        lo = _refined_extreme(C[i, 0], a, b, step * k_lo, best_lo, step, False)
        out[i] = 0.5 * (hi - lo)
    return out


@njit(cache=True)
def interpolant_half_peak_to_peak(samples, a0, a, b):
    """Half peak-to-peak of the trigonometric interpolants of periodic samples.

    ``samples`` (P, K) at phases 2 pi k / K; ``a0`` (P,), ``a``, ``b`` (P, Hd) their
    cos/sin coefficients of harmonics 1..Hd. Each extreme starts at the extreme sample
    and is refined by Newton on the interpolant (exact for a sampled trigonometric
    polynomial of degree <= Hd)."""
    n_pts, K = samples.shape
    out = np.empty(n_pts)
    step = 2.0 * math.pi / K
    for p in range(n_pts):
        k_hi = 0
        k_lo = 0
        for k in range(K):
            if samples[p, k] > samples[p, k_hi]:
                k_hi = k
            if samples[p, k] < samples[p, k_lo]:
                k_lo = k
        hi = _refined_extreme(a0[p], a[p], b[p], step * k_hi, samples[p, k_hi], step, True)
        lo = _refined_extreme(a0[p], a[p], b[p], step * k_lo, samples[p, k_lo], step, False)
        out[p] = 0.5 * (hi - lo)
    return out


# ---------------------------------------------------------------------------------
# brute force on the same right-hand side: fixed-step RK4, period by period


@njit(cache=True)
def _rk4_period(rhs, itab, ftab, work, n, y0, omega, amp, n_steps, xs_out):
    """One forcing period with n_steps RK4 steps from y0; states at the step starts."""
    h = 2.0 * math.pi / omega / n_steps
    own = np.zeros((6, work))
    road0 = np.empty(ROAD_LEN)
    y, yt = _borrow(own[0]), _borrow(own[1])
    k1, k2, k3, k4 = _borrow(own[2]), _borrow(own[3]), _borrow(own[4]), _borrow(own[5])
    road = _borrow(road0)
    itab, ftab = _borrow(itab), _borrow(ftab)
    y[:n] = y0[:n]
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
    return own[0, :n].copy()


@njit(cache=True)
def fo_rk4_period(rhs, itab, ftab, work, n, y0, omega, amp, n_steps):
    """One period from y0: (end state, states at the step starts (n, n_steps))."""
    xs = np.empty((n, n_steps))
    y = _rk4_period(rhs, itab, ftab, work, n, y0, omega, amp, n_steps, xs)
    return y, xs


@njit(cache=True)
def fo_brute_point(
    rhs, itab, ftab, work, n, y0, omega, amp, n_steps, rtol, max_periods, scales, posof, keep
):  # fmt: skip
    """Integrate from y0 until the periodic orbit settles.

    After each period the change of the state at the period start, each state relative
    to its size max(max |x_i| over the period, scale_i), is d_k (a state that is the
    velocity of a position, ``posof[j] = i``, counts as |change| / Omega relative to
    the size of x_i). The contraction per period rho = d_k / d_(k-1) gives the
    remaining distance to the periodic orbit, d_k rho / (1 - rho); the orbit is settled
    when that estimate and d_k are below ``rtol`` for ``keep`` periods running. Returns
    (end state, samples of the last period (n, n_steps), settled, periods, distance,
    largest and smallest value of each state over the settled periods and the one before
    them, period ends included)."""
    y = y0[:n].copy()
    xs = np.empty((n, n_steps))
    size = np.empty(n)
    hi = np.full(n, -1e300)
    lo = np.full(n, 1e300)
    prev = np.inf
    dist = np.inf
    calm = 0
    for k in range(max_periods):
        yn = _rk4_period(rhs, itab, ftab, work, n, y, omega, amp, n_steps, xs)
        for i in range(n):
            size[i] = max(max(np.max(np.abs(xs[i])), abs(yn[i])), scales[i])
        change = 0.0
        for j in range(n):
            i = posof[j]
            if i >= 0:
                change = max(change, abs(yn[j] - y[j]) / omega / size[i])
            else:
                change = max(change, abs(yn[j] - y[j]) / size[j])
        rho = change / prev if prev > 0.0 else 0.0
        prev = change
        dist = change * rho / (1.0 - rho) if rho < 0.999 else np.inf
        dist = max(dist, change)
        y = yn
        if dist < rtol:
            calm += 1
        else:
            calm = 0
            hi[:] = -1e300
            lo[:] = 1e300
        for i in range(n):
            hi[i] = max(hi[i], max(np.max(xs[i]), yn[i]))
            lo[i] = min(lo[i], min(np.min(xs[i]), yn[i]))
        if calm >= keep:
            return y, xs, True, k + 1, dist, hi, lo
    return y, xs, False, max_periods, dist, hi, lo


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

_SYS = (_RHS, _JAC, _TERMS, _i8, _iv, _v, _i8, _iv)  # rhs, jac, terms, mode, itab, ftab, work, lay
_BASIS = (_v, _m, _m, _m, _m, _m, _m, _m)  # tau, E, E1, E2, F, D1, D2, W, W
_RK = (_RHS, _iv, _v, _i8, _i8)  # rhs, itab, ftab, work, n
_ENTRY_TYPES = {
    "fo_residual": (*_SYS, _v, _f8, _f8, *_BASIS),
    "fo_residual_jacobian": (*_SYS, _v, _f8, _f8, *_BASIS, _v),
    "fo_newton": (*_SYS, _v, _f8, _f8, *_BASIS, _v, _f8, _i8, _f8),
    "fo_sweep": (*_SYS, _v, _v, _v, _f8, *_BASIS, _v, _f8, _i8, _f8, _b1, _b1),
    "fo_relative_residuals": (*_SYS, _v, _m, _f8, *_BASIS),
    "fo_hill_matrices": (*_SYS, _v, _m, _a1, _f8, _v, _m, _m, _m, _m, _m, _m, _v),
    "fo_derivative_samples": (*_SYS, _v, _m, _f8, _v, _m, _m, _m),
    "_rhs_samples": (*_RK, _m, _f8, _f8, _v),
    "fo_compiled_outputs": (_RHS, _iv, _v, _i8, _iv, _i8, _v, _m, _f8, _v, _m, _m, _m),
    "fo_outputs_at_states": (_RHS, _iv, _v, _i8, _i8, _i8, _m, _f8, _f8, _v),
    "fo_rk4_period": (*_RK, _v, _f8, _f8, _i8),
    "fo_brute_point": (*_RK, _v, _f8, _f8, _i8, _f8, _i8, _v, _iv, _i8),
    "fo_monodromy": (*_RK, _v, _f8, _f8, _i8, _v),
}
_TYPED: dict = {}


def _placeholder(name: str):
    fn = _TYPED.get(name)
    if fn is None:
        if name == "no_jacobian":
            fn = njit(JACOBIAN_SIGNATURE, cache=True)(_no_jacobian_py)
        else:
            fn = njit(TERMS_SIGNATURE, cache=True)(_no_terms_py)
        _TYPED[name] = fn
    return fn


def kernel(name: str):
    """The compiled entry point ``name`` typed for first-class system functions."""
    fn = _TYPED.get(name)
    if fn is None:
        fn = njit(_ENTRY_TYPES[name], cache=True)(globals()[name].py_func)
        _TYPED[name] = fn
    return fn


# ---------------------------------------------------------------------------------
# systems


@dataclass(frozen=True, kw_only=True, eq=False)
class FirstOrderSystem:
    """A system x' = f(t, x, u(t)) for :func:`inerterlab.frequency.frequency_response`.

    Parameters
    ----------
    n_states : int
        States in the balance.
    rhs : numba dispatcher
        Compiled for :data:`RHS_SIGNATURE`: ``rhs(t, x, road, int_table, float_table,
        out)``, road = [X1, X1', X1'', Omega].
    int_table, float_table : ndarray
        Its parameters (int64, float64).
    work_size : int
        Length of the arrays ``rhs`` is called with (>= n_states; a model-core system
        keeps its evaluation's work array in ``out`` past the derivatives, see
        :func:`inerterlab.frequency.quarter_car.buffered_rhs`).
    state_scales : ndarray
        Typical size of each state (finite-difference steps, settling test).
    rest_state : ndarray, optional
        Cold start of Newton and start of the brute force.
    jacobian : numba dispatcher, optional
        Compiled for :data:`JACOBIAN_SIGNATURE`: df/dx.
    terms : numba dispatcher, optional
        Compiled for :data:`TERMS_SIGNATURE`: the implicit form r(x, x') = 0 and its
        partials, balanced instead of x' - f (see the module docstring).
    velocity_of : sequence of int, optional
        ``velocity_of[i] = j`` where x_i' = x_j identically, else -1 (see the module
        docstring).
    output_samples : callable, optional
        ``output_samples(xs, fs, road) -> {name: samples}`` with xs, fs of shape
        (P, n, K) (states and their derivatives at K phases) and road of shape (P, 3, K).
    compiled_outputs : numba dispatcher, optional
        Instead of ``output_samples``: ``compiled_outputs(t, x, road, int_table,
        float_table, out) -> bool`` (the signature of ``rhs``) filling the first
        ``n_outputs`` values of ``out`` (which has max(n_outputs, work_size) entries, as
        room for its own work), and ``combine_outputs(O) -> {name: samples}`` with O of shape
        (P, n_outputs, K).
    output_units : dict
        Unit of each output.
    response_state : int
        The state whose half peak-to-peak is ``amplitude_m`` when there are no outputs.
    nonlinearity_degree : int
        For the aliasing rule (samples per period).
    label : str
    input_amplitude : float, optional
        The amplitude of the input the system carries itself (the built-in systems);
        None when the caller gives it.
    on_generic : callable, optional
        ``on_generic(seconds)``, called by :func:`inerterlab.frequency.frequency_response`
        with the CPU time of a response computed on the model core's generic code (a
        core system whose structure's own code is not compiled yet): that time counts
        towards compiling it, as an integration's does
        (:func:`inerterlab.systems._compiled.record`).
    """

    n_states: int
    rhs: object
    int_table: np.ndarray
    float_table: np.ndarray
    work_size: int = 0
    state_scales: np.ndarray | None = None
    rest_state: np.ndarray | None = None
    jacobian: object = None
    terms: object = None
    velocity_of: tuple | None = None
    output_samples: object = None
    compiled_outputs: object = None
    n_outputs: int = 0
    combine_outputs: object = None
    output_units: dict = field(default_factory=dict)
    response_state: int = 0
    nonlinearity_degree: int = 3
    label: str = "first-order system"
    input_amplitude: float | None = None
    on_generic: object = None

    def __post_init__(self) -> None:
        if not isinstance(self.n_states, int | np.integer) or self.n_states < 1:
            raise ParameterError("n_states", self.n_states, "an integer >= 1")
        if self.work_size == 0:
            object.__setattr__(self, "work_size", int(self.n_states))
        if self.work_size < self.n_states:
            raise ParameterError("work_size", self.work_size, f">= n_states = {self.n_states}")
        if not 0 <= self.response_state < self.n_states:
            raise ParameterError("response_state", self.response_state, f"0 .. {self.n_states - 1}")
        _layout(self)  # checks velocity_of

    @property
    def displacement_scale(self) -> float:
        return 1.0

    def __repr__(self) -> str:
        return f"<FirstOrderSystem {self.label}: {self.n_states} states>"


def _layout(system) -> tuple[np.ndarray, np.ndarray]:
    """(lay, posof) of a system (see the kernels' comment); checks ``velocity_of``."""
    n = int(system.n_states)
    vel = getattr(system, "velocity_of", None)
    vel = np.full(n, -1, dtype=np.int64) if vel is None else np.asarray(vel, dtype=np.int64)
    if vel.shape != (n,) or np.any(vel < -1) or np.any(vel >= n):
        raise ParameterError("velocity_of", vel.tolist(), f"{n} state indices or -1")
    targets = vel[vel >= 0]
    if (
        len(set(targets.tolist())) != len(targets)
        or np.any(vel[targets] >= 0)
        or np.any(targets == np.flatnonzero(vel >= 0))
    ):
        raise ParameterError(
            "velocity_of", vel.tolist(), "distinct velocities that are not positions themselves"
        )
    posof = np.full(n, -1, dtype=np.int64)
    posof[targets] = np.flatnonzero(vel >= 0)
    free = [j for j in range(n) if posof[j] < 0]
    blk = np.empty(n, dtype=np.int64)
    ordr = np.zeros(n, dtype=np.int64)
    for c, j in enumerate(free):
        blk[j] = c
    for j in range(n):
        if posof[j] >= 0:
            blk[j] = blk[posof[j]]
            ordr[j] = 1
    rows = [i for i in range(n) if vel[i] < 0]
    lay = np.concatenate([[n, len(free)], blk, ordr, rows]).astype(np.int64)
    return lay, posof


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
    return hasattr(system, "rhs") and hasattr(system, "n_states")


def _scales(system, n):
    sc = getattr(system, "state_scales", None)
    return np.ones(n) if sc is None else np.ascontiguousarray(np.asarray(sc, float)[:n])


def _tables(system):
    it, ft = system_tables(system)
    return np.array(it, dtype=np.int64), np.array(ft, dtype=float)  # writable copies


class FirstOrderEngine:
    """Harmonic-balance engine of a system under a sine input of amplitude A.

    Offers ``residual``, ``residual_jacobian``, ``newton``, ``sweep``,
    ``relative_residuals`` on the unknown coefficients (the scanning and continuation
    drivers use them), :meth:`stability`, and the outputs. ``n_dof`` is the number of
    unknown blocks (states less eliminated velocities).
    """

    def __init__(self, system, basis: FourierBasis, amplitude: float):
        n = int(system.n_states)
        if n < 1:
            raise ParameterError("n_states", n, "an integer >= 1")
        self.system = system
        self.basis = basis
        self.n_states = n
        self.amplitude = float(amplitude)
        self.work = int(getattr(system, "work_size", n) or n)
        if self.work < n:
            raise ParameterError("work_size", self.work, f"an integer >= n_states = {n}")
        self.rhs = system.rhs
        jac = getattr(system, "jacobian", None)
        terms = getattr(system, "terms", None)
        self.mode = 2 if terms is not None else (1 if jac is not None else 0)
        self.jac = jac if jac is not None else _placeholder("no_jacobian")
        self.terms = terms if terms is not None else _placeholder("no_terms")
        self.lay, self.posof = _layout(system)
        self.n_dof = int(self.lay[1])
        self.itab, self.ftab = _tables(system)
        self.scales = _scales(system, n)
        # chord iterations pay off where the Jacobian costs finite differences
        self.chord = self.mode == 0
        # Hill matrices: an implicit system (a second-order one) on all harmonics and
        # the balance's samples, an explicit one on denser samples (see stability)
        self.stability_samples = basis.n_samples if self.mode == 2 else 256
        self._set_basis(basis)

    def _set_basis(self, b):
        c = np.ascontiguousarray
        self.tau, self.E, self.E1, self.E2, self.F = c(b.tau), c(b.E), c(b.E1), c(b.E2), c(b.F)
        self.D1 = c(b.F @ b.E1)
        self.D2 = c(b.F @ b.E2)
        self.W = spectral_sums(b)

    def _s(self):
        return (self.rhs, self.jac, self.terms, self.mode, self.itab, self.ftab, self.work,
                self.lay)  # fmt: skip

    def _b(self):
        return (self.tau, self.E, self.E1, self.E2, self.F, self.D1, self.D2, self.W)

    def cold_start(self) -> np.ndarray:
        """The rest state as constant terms (zeros when the system gives none)."""
        m = self.basis.size
        Y = np.zeros(self.n_dof * m)
        rest = rest_state(self.system)
        if rest is not None:
            n = self.n_states
            for j in range(n):
                if self.lay[2 + n + j] == 0:
                    Y[self.lay[2 + j] * m] = float(rest[j])
        return Y

    def residual(self, X, omega):
        return kernel("fo_residual")(
            *self._s(), np.ascontiguousarray(X, dtype=float), float(omega), self.amplitude,
            *self._b(),
        )  # fmt: skip

    def residual_jacobian(self, X, omega):
        return kernel("fo_residual_jacobian")(
            *self._s(), np.ascontiguousarray(X, dtype=float), float(omega), self.amplitude,
            *self._b(), self.scales,
        )  # fmt: skip

    def newton(self, X0, omega, rtol, max_iter, scale):
        return kernel("fo_newton")(
            *self._s(), np.ascontiguousarray(X0, dtype=float), float(omega), self.amplitude,
            *self._b(), self.scales, float(rtol), int(max_iter), float(scale),
        )  # fmt: skip

    def sweep(self, omegas, X_start, rtol, max_iter, scale, warm, X_cold=None):
        cold = self.cold_start() if X_cold is None else X_cold
        return kernel("fo_sweep")(
            *self._s(), np.ascontiguousarray(omegas, dtype=float),
            np.ascontiguousarray(X_start, dtype=float), np.ascontiguousarray(cold, dtype=float),
            self.amplitude, *self._b(), self.scales, float(rtol), int(max_iter), float(scale),
            bool(warm), bool(self.chord),
        )  # fmt: skip

    def relative_residuals(self, omegas, C):
        return kernel("fo_relative_residuals")(
            *self._s(), np.ascontiguousarray(omegas, dtype=float),
            np.ascontiguousarray(C, dtype=float), self.amplitude, *self._b(),
        )  # fmt: skip

    def stability(self, omegas, C, ok, harmonics: int | None = None, samples: int | None = None):
        """Floquet exponents by Hill's method with the harmonics 0..``harmonics``
        (default all) and the partials at ``samples`` phases (default
        ``stability_samples``; at least the balance's N): (max Re lambda [1/s] over the
        n eigenvalues nearest the real axis, NaN where unknown; those eigenvalues,
        (P, n) complex)."""
        hs = self.basis.harmonics if harmonics is None else int(harmonics)
        if not 0 <= hs <= self.basis.harmonics:
            raise ParameterError(
                "stability_harmonics", harmonics, f"0 .. harmonics = {self.basis.harmonics}"
            )
        ns = max(int(self.stability_samples if samples is None else samples),
                 self.basis.n_samples)  # fmt: skip
        bs = fourier_basis(hs, ns)
        bh = self.basis if ns == self.basis.n_samples else fourier_basis(self.basis.harmonics, ns)
        c = np.ascontiguousarray
        omegas = c(omegas, dtype=float)
        ok = c(ok, dtype=np.bool_)
        H = kernel("fo_hill_matrices")(
            *self._s(), omegas, c(C, dtype=float), ok, self.amplitude, c(bs.tau), c(bh.E),
            c(bh.E1), c(bh.E2), c(bs.E), c(bs.F), c(bs.F @ bs.E1), self.scales,
        )  # fmt: skip
        n = self.n_states
        best = np.full(len(omegas), np.nan)
        exps = np.full((len(omegas), n), np.nan + 0j)
        good = ok & np.all(np.isfinite(H), axis=(1, 2))
        if good.any():
            lam = np.linalg.eigvals(H[good])
            # the copy of each exponent nearest the real axis, n of them
            order = np.argsort(np.abs(lam.imag), axis=1, kind="stable")
            near = np.take_along_axis(lam, order[:, :n], axis=1)
            exps[good] = near
            best[good] = np.max(near.real, axis=1)
        return best, exps

    def _dense(self, tau):
        if tau is None:
            return self.tau, self.E, self.E1, self.E2
        b = fourier_basis(self.basis.harmonics, len(tau))
        c = np.ascontiguousarray
        return c(tau, dtype=float), c(b.E), c(b.E1), c(b.E2)

    def compiled_outputs(self, outfn, n_out, omegas, C, tau):
        """A compiled output function at the phases tau of every point, (P, n_out, K)."""
        tau, E, E1, E2 = self._dense(np.asarray(tau, dtype=float))
        return kernel("fo_compiled_outputs")(
            outfn, self.itab, self.ftab, self.work, self.lay, int(n_out),
            np.ascontiguousarray(omegas, dtype=float), np.ascontiguousarray(C, dtype=float),
            self.amplitude, tau, E, E1, E2,
        )  # fmt: skip

    def samples(self, omegas, C, tau=None):
        """States and their derivatives at the phases ``tau`` (default the N samples) of
        every point, (P, n, K) each."""
        tau, E, E1, E2 = self._dense(None if tau is None else np.asarray(tau, dtype=float))
        return kernel("fo_derivative_samples")(
            *self._s(), np.ascontiguousarray(omegas, dtype=float),
            np.ascontiguousarray(C, dtype=float), self.amplitude, tau, E, E1, E2,
        )  # fmt: skip


def make_first_order_engine(
    system, harmonics: int, n_samples: int | None, amplitude: float
) -> FirstOrderEngine:
    """The engine for ``system`` (checks the harmonics, the samples and the memory)."""
    n = checked_samples(system, harmonics, n_samples, int(system.n_states))
    return FirstOrderEngine(system, fourier_basis(int(harmonics), n), amplitude)


def _rk_args(system):
    n = int(system.n_states)
    work = int(getattr(system, "work_size", n) or n)
    itab, ftab = _tables(system)
    return system.rhs, itab, ftab, work, n


def steady_state_point(
    system, omega: float, amplitude: float, y0, *, steps: int, rtol: float,
    max_periods: int, keep_periods: int = 2,
):  # fmt: skip
    """RK4 on the system's own right-hand side, period by period, to the settled orbit:
    (end state, samples of the last period (n, steps), settled, periods, distance,
    largest and smallest value of each state over the settled periods)."""
    args = _rk_args(system)
    n = args[-1]
    _, posof = _layout(system)
    return kernel("fo_brute_point")(
        *args, np.ascontiguousarray(y0, dtype=float), float(omega), float(amplitude),
        int(steps), float(rtol), int(max_periods), _scales(system, n), posof, int(keep_periods),
    )  # fmt: skip


def rk4_period(system, omega: float, amplitude: float, y0, steps: int):
    """One forcing period of RK4 from y0: (end state, states at the step starts)."""
    return kernel("fo_rk4_period")(
        *_rk_args(system), np.ascontiguousarray(y0, dtype=float), float(omega), float(amplitude),
        int(steps),
    )  # fmt: skip


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
    y0 = np.zeros(n) if initial_state is None else np.asarray(initial_state, dtype=float)
    if initial_state is None and rest_state(system) is not None:
        y0 = rest_state(system)[:n].copy()
    y, xs, ok, periods, *_ = steady_state_point(
        system, omega, amplitude, y0, steps=steps_per_period, rtol=rtol, max_periods=max_periods
    )
    return y, xs, bool(ok), int(periods)


def rhs_samples(system, omega, amplitude, xs, tau):
    """f at the states xs (n, K) and phases tau (K,) under the sine input: (n, K)."""
    return kernel("_rhs_samples")(
        *_rk_args(system), np.ascontiguousarray(xs, dtype=float), float(omega), float(amplitude),
        np.ascontiguousarray(tau, dtype=float),
    )  # fmt: skip


def outputs_at_states(system, omega, amplitude, xs, tau):
    """The system's compiled outputs at the states xs (n, K) and phases tau: (n_out, K)."""
    rhs, itab, ftab, work, n = _rk_args(system)
    return kernel("fo_outputs_at_states")(
        system.compiled_outputs, itab, ftab, work, n, int(system.n_outputs),
        np.ascontiguousarray(xs, dtype=float), float(omega), float(amplitude),
        np.ascontiguousarray(tau, dtype=float),
    )  # fmt: skip


def monodromy_multipliers(system, omega, amplitude, state0, *, steps_per_period=4000):
    """Floquet multipliers of the orbit through ``state0`` (RK4 monodromy, central
    differences): independent of the harmonic balance."""
    args = _rk_args(system)
    M = kernel("fo_monodromy")(
        *args, np.ascontiguousarray(state0, dtype=float), float(omega), float(amplitude),
        int(steps_per_period), _scales(system, args[-1]),
    )  # fmt: skip
    return np.linalg.eigvals(M)
