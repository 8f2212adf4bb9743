"""H2 norms and Lyapunov equations: the one place every linear analysis solves them.

For a stable x' = A x + B w driven by unit white noise w (two-sided spectral density 1),
the state covariance is the controllability gramian P, the solution of

    A P + P A^T + B B^T = 0,

and the H2 norm of an output y = C x (no feed-through) is ||H||_2^2 = C P C^T
= (1/2 pi) int |H(j w)|^2 dw. Two routes to P, for two sizes of problem:

* :func:`gramian`: any state space, by the Bartels-Stewart method of
  :func:`scipy.linalg.solve_continuous_lyapunov`, checked for a finite solution. The
  quarter cars' H2 norms (:func:`inerterlab.metrics.h2_norms_state_space`), the
  vehicles' (:func:`inerterlab.vehicles.spectral.white_velocity_h2`) and the equivalent
  linearisation of identified cars (:mod:`inerterlab.identify.propagate`) use it.
* the compiled rational route (:func:`h2_rational`, :func:`h2_rational_gradient`): the
  transfers row(s)/Delta(s) of a network quarter car over one denominator, realised in
  controllable canonical form after a frequency scaling s = w0 sigma that puts the roots
  near |sigma| = 1; the Lyapunov equation is solved on the n(n+1)/2 distinct entries of
  the symmetric P (:func:`lyapunov_packed`), stability decided first by the Routh test
  (:func:`hurwitz`). It is the optimiser's inner loop (a few microseconds per candidate
  against about a hundred for the general route, docs/decisions.md "One network grammar
  ..."), and its results agree with the general route to rounding.
* :func:`h2_rational_filtered`: the same transfer followed by a weighting filter given
  as a state space without feed-through (the ISO 2631-1 Wk weighting of
  :func:`wk_realisation`): the cascade's gramian is solved block by block (the car's
  companion block as above, the coupling by a Sylvester equation, the filter's block
  by a Lyapunov equation), so the filter's states stay in their own well-scaled form
  and a feed-through of the car (an inerter with a damped tyre) is allowed: the
  filter's roll-off makes the weighted norm finite.

The frequency responses these norms integrate come from one place too:
:func:`resolvent_solve`, (s I - A)^-1 R at many complex frequencies s, a block of
frequencies per batched LAPACK solve.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .errors import ConvergenceError

__all__ = [
    "gramian",
    "lyapunov_packed",
    "hurwitz",
    "h2_rational",
    "h2_rational_gradient",
    "h2_rational_filtered",
    "h2_rational_filtered_gradient",
    "stable_scaled",
    "wk_realisation",
    "wk_polynomials",
    "variance_gradient",
    "resolvent_solve",
]

#: the largest complex workspace of one block of frequencies in :func:`resolvent_solve`
#: [bytes]
SOLVE_BLOCK_BYTES = 32 * 2**20


def resolvent_solve(A, s, R) -> np.ndarray:
    """X[i] = (s[i] I - A)^-1 R[i] for every complex frequency ``s[i]``.

    ``A`` (n, n) real; ``s`` (nf,) complex; ``R`` (nf, n) or (nf, n, m), the right-hand
    side at each frequency. Each frequency's matrix is factorised on its own (LAPACK's
    ``gesv``, as a loop of :func:`numpy.linalg.solve` would), a block of frequencies per
    call, so the workspace stays under :data:`SOLVE_BLOCK_BYTES`."""
    A = np.asarray(A, dtype=float)
    s = np.atleast_1d(np.asarray(s, dtype=complex))
    R = np.asarray(R)
    vec = R.ndim == 2
    if vec:
        R = R[:, :, None]
    n, m = A.shape[0], R.shape[2]
    X = np.empty((s.size, n, m), complex)
    block = max(1, min(s.size, SOLVE_BLOCK_BYTES // max(1, 16 * n * (n + m))))
    idx = np.arange(n)
    for lo in range(0, s.size, block):
        sb = s[lo : lo + block]
        S = np.broadcast_to(-A, (sb.size, n, n)).astype(complex)
        S[:, idx, idx] += sb[:, None]
        X[lo : lo + block] = np.linalg.solve(S, R[lo : lo + block])
    return X[:, :, 0] if vec else X


def gramian(A, B, *, what: str = "H2 norms") -> np.ndarray:
    """Controllability gramian P of x' = A x + B w: A P + P A^T + B B^T = 0.

    ``B`` is a vector (one input) or a matrix (one column per independent unit white
    input). ConvergenceError naming ``what`` if the equation has no finite solution
    (A singular on the imaginary axis, or scales too far apart).

    Solved on the balanced system D^-1 A D (D diagonal, powers of two:
    :func:`scipy.linalg.matrix_balance`, exact in floating point), P = D P_b D. A quarter
    car with its Wk filter spans tyre hop to the filter's 100 Hz: unbalanced, its
    suspension deflection's variance came out up to 5e-9 off its closed form (a 1-ulp
    change of A moved it that much), balanced below 1e-13 (docs/decisions.md, stop 69)."""
    from scipy.linalg import matrix_balance, solve_continuous_lyapunov

    A = np.asarray(A, dtype=float)
    B = np.asarray(B, dtype=float)
    with np.errstate(all="ignore"):
        try:
            _, (d, _) = matrix_balance(A, permute=False, separate=True)
        except (np.linalg.LinAlgError, ValueError):
            d = np.ones(A.shape[0])
    Ab = (A * d[None, :]) / d[:, None]
    Bb = B / d if B.ndim == 1 else B / d[:, None]
    BB = np.outer(Bb, Bb) if B.ndim == 1 else Bb @ Bb.T
    try:
        with np.errstate(all="ignore"):
            P = solve_continuous_lyapunov(Ab, -BB) * d[:, None] * d[None, :]
    except (np.linalg.LinAlgError, ValueError) as exc:
        P, why = None, f"{type(exc).__name__}: {exc}".splitlines()[0]
    else:
        why = "the solution is not finite"
    if P is None or not np.all(np.isfinite(P)):
        raise ConvergenceError(
            f"{what}: the Lyapunov equation cannot be solved for these parameters ({why}); "
            "masses, stiffnesses, damping and inertance are too far apart in scale"
        )
    return P


# ---------------------------------------------------------------------------------------
# compiled rational route


@nb.njit(cache=True)
def _sym_index(n):
    """Packed index of the entries of a symmetric n x n matrix, and their count."""
    idx = np.empty((n, n), np.int64)
    c = 0
    for i in range(n):
        for j in range(i, n):
            idx[i, j] = c
            idx[j, i] = c
            c += 1
    return idx, c


@nb.njit(cache=True)
def _lyap_system(A, idx, m):
    """Matrix of X -> A X + X A^T on the packed entries of a symmetric X."""
    n = A.shape[0]
    M = np.zeros((m, m))
    for i in range(n):
        for j in range(i, n):
            e = idx[i, j]
            for k in range(n):
                if A[i, k] != 0.0:
                    M[e, idx[k, j]] += A[i, k]
                if A[j, k] != 0.0:
                    M[e, idx[i, k]] += A[j, k]
    return M


@nb.njit(cache=True)
def lyapunov_packed(A, R):
    """Solve A X + X A^T + R = 0 for symmetric X (R symmetric), small n, on the packed
    distinct entries of X; NaN where the equation is singular."""
    n = A.shape[0]
    idx, m = _sym_index(n)
    M = _lyap_system(A, idx, m)
    rhs = np.zeros(m)
    for i in range(n):
        for j in range(i, n):
            rhs[idx[i, j]] = -R[i, j]
    # Gaussian elimination with partial pivoting (in place; for these sizes, m <= a few
    # hundred, it is about twice as fast as a LAPACK call from compiled code)
    for col in range(m):
        piv = col
        best = abs(M[col, col])
        for r in range(col + 1, m):
            if abs(M[r, col]) > best:
                best = abs(M[r, col])
                piv = r
        if best == 0.0:
            return np.full((n, n), np.nan)
        if piv != col:
            for q in range(m):
                M[col, q], M[piv, q] = M[piv, q], M[col, q]
            rhs[col], rhs[piv] = rhs[piv], rhs[col]
        inv = 1.0 / M[col, col]
        for r in range(col + 1, m):
            f = M[r, col] * inv
            if f != 0.0:
                for q in range(col, m):
                    M[r, q] -= f * M[col, q]
                rhs[r] -= f * rhs[col]
    x = np.zeros(m)
    for r in range(m - 1, -1, -1):
        acc = rhs[r]
        for q in range(r + 1, m):
            acc -= M[r, q] * x[q]
        x[r] = acc / M[r, r]
    X = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            X[i, j] = x[idx[i, j]]
    return X


@nb.njit(cache=True)
def _scaled(polys, n):
    """Frequency scale w0 = (Delta_0 / Delta_n)^(1/n), the monic scaled denominator
    coefficients and the factor of each coefficient (s = w0 sigma, divided by Delta_n)."""
    an = polys[0, n]
    w0 = (polys[0, 0] / an) ** (1.0 / n)
    at = np.empty(n + 1)
    scale = np.empty(n + 1)
    for i in range(n + 1):
        scale[i] = 1.0 / (an * w0 ** (n - i))
        at[i] = polys[0, i] * scale[i]
    return w0, at, scale


@nb.njit(cache=True)
def _companion(at, n):
    """The monic companion matrix with coefficients ``at`` and its controllability
    gramian (input on the last state)."""
    A = np.zeros((n, n))
    for i in range(n - 1):
        A[i, i + 1] = 1.0
    for j in range(n):
        A[n - 1, j] = -at[j]
    R = np.zeros((n, n))
    R[n - 1, n - 1] = 1.0
    return A, lyapunov_packed(A, R)


@nb.njit(cache=True)
def hurwitz(a, n):
    """Routh test of the polynomial a[0] + a[1] s + ... + a[n] s^n (a[n] > 0)."""
    w = n // 2 + 2
    r0 = np.zeros(w)
    r1 = np.zeros(w)
    for q in range(w):
        i0 = n - 2 * q
        i1 = n - 1 - 2 * q
        r0[q] = a[i0] if i0 >= 0 else 0.0
        r1[q] = a[i1] if i1 >= 0 else 0.0
    for _ in range(n):
        if not r1[0] > 0.0:
            return False
        r2 = np.zeros(w)
        for q in range(w - 1):
            r2[q] = r0[q + 1] - r0[0] * r1[q + 1] / r1[0]
        r0 = r1
        r1 = r2
    return True


@nb.njit(cache=True)
def stable_scaled(polys, n, which):
    """The checks every norm of row ``which`` over Delta (row 0, degree ``n``) starts
    with, and the scaled coefficients it then needs: (ok, w0, Delta's scaled monic
    coefficients, the row's scaled coefficients). ``ok`` is False (the norm is
    infinite) when Delta's end coefficients are not positive, Delta is not Hurwitz
    (the car is not asymptotically stable) or the row's degree exceeds n."""
    an = polys[0, n]
    if not (polys[0, 0] > 0.0 and an > 0.0):
        return False, 0.0, np.zeros(n + 1), np.zeros(n + 1)
    w0, at, scale = _scaled(polys, n)
    bt = np.empty(n + 1)
    for i in range(n + 1):
        bt[i] = polys[which, i] * scale[i]
    if not hurwitz(at, n):
        return False, w0, at, bt
    for i in range(n + 1, polys.shape[1]):
        if polys[which, i] != 0.0:
            return False, w0, at, bt
    return True, w0, at, bt


@nb.njit(cache=True)
def h2_rational(polys, n, out):
    """Squared H2 norms of the transfers row / Delta, rows 1.. of ``polys`` over Delta
    (row 0; ascending coefficients, degree ``n``), into ``out``; returns w0."""
    an = polys[0, n]
    if not (polys[0, 0] > 0.0 and an > 0.0):
        out[:] = np.inf
        return 0.0
    w0, at, scale = _scaled(polys, n)
    if not hurwitz(at, n):
        out[:] = np.inf
        return w0
    _, P = _companion(at, n)
    for o in range(polys.shape[0] - 1):
        row = polys[o + 1]
        lead = row[n] * scale[n]
        big = 0.0
        for i in range(n):
            big = max(big, abs(row[i] * scale[i]))
        for i in range(n + 1, polys.shape[1]):
            big = max(big, abs(row[i]))
        if abs(lead) > 1e-13 * big:
            out[o] = np.inf
            continue
        acc = 0.0
        for i in range(n):
            ci = row[i] * scale[i]
            if ci == 0.0:
                continue
            for j in range(n):
                acc += ci * P[i, j] * row[j] * scale[j]
        out[o] = w0 * acc
    return w0


@nb.njit(cache=True)
def h2_rational_gradient(polys, n, which, g):
    """||row/Delta||^2 of row ``which`` of ``polys`` and its derivatives in the
    coefficients of Delta and of that row, into g[0], g[1] (adjoint of the Lyapunov
    equation)."""
    an = polys[0, n]
    w0, at, sc = _scaled(polys, n)
    A, P = _companion(at, n)
    c = np.empty(n)
    for i in range(n):
        c[i] = polys[which, i] * sc[i]
    Q = lyapunov_packed(A.T.copy(), np.outer(c, c))
    PQ = P @ Q
    Pc = P @ c
    J = 0.0
    for i in range(n):
        J += c[i] * Pc[i]
    # scaled problem: dJ~/d at_j = -2 (P Q)[j, n-1], dJ~/dc_j = 2 (P c)_j; J = w0 J~
    # (w0 is only the choice of realisation: held fixed while differentiating)
    g[:, :] = 0.0
    for j in range(n):
        g[0, j] = w0 * (-2.0 * PQ[j, n - 1]) * sc[j]
        g[1, j] = w0 * 2.0 * Pc[j] * sc[j]
    # a_n scales every at_j and c_j by 1/a_n
    s = 0.0
    for j in range(n):
        s += -2.0 * PQ[j, n - 1] * at[j] + 2.0 * Pc[j] * c[j]
    g[0, n] = -w0 * s / an
    return w0 * J


# ---------------------------------------------------------------------------------------
# a transfer followed by a weighting filter


def wk_realisation() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C) of the ISO 2631-1 Wk weighting (8 states, no feed-through), the
    cascade of its four sections (:meth:`inerterlab.iso2631.Weighting.state_space`)."""
    from .iso2631 import WEIGHTINGS

    A, B, C, D = WEIGHTINGS["Wk"].state_space()
    if float(np.abs(D).max()) != 0.0:  # pragma: no cover - Wk's low pass has none
        raise ConvergenceError("Wk realisation: expected no feed-through")
    return (
        np.ascontiguousarray(A, dtype=float),
        np.ascontiguousarray(np.ravel(B), dtype=float),
        np.ascontiguousarray(np.ravel(C), dtype=float),
    )


def wk_polynomials() -> tuple[np.ndarray, np.ndarray]:
    """ISO 2631-1 Wk as numerator/denominator polynomials in s, ascending powers: the
    product of its sections' (:meth:`inerterlab.iso2631.Weighting.sections`)."""
    from .iso2631 import WEIGHTINGS

    num, den = np.ones(1), np.ones(1)
    for b, a in WEIGHTINGS["Wk"].sections():
        num = np.convolve(num, b)
        den = np.convolve(den, a)
    return np.trim_zeros(num, "f")[::-1].copy(), den[::-1].copy()


@nb.njit(cache=True)
def _sylvester(M, N, R):
    """X (m x n) of M X + X N + R = 0 (M m x m, N n x n), by its Kronecker form on the
    column-major entries of X (small m n)."""
    m, n = M.shape[0], N.shape[0]
    K = np.zeros((m * n, m * n))
    rhs = np.empty(m * n)
    for j in range(n):
        for i in range(m):
            r = j * m + i
            rhs[r] = -R[i, j]
            for q in range(m):
                K[r, j * m + q] += M[i, q]
            for q in range(n):
                K[r, q * m + i] += N[q, j]
    x = np.linalg.solve(K, rhs)
    X = np.empty((m, n))
    for j in range(n):
        for i in range(m):
            X[i, j] = x[j * m + i]
    return X


@nb.njit(cache=True)
def _cascade(w0, at, bt, n, fA, fB):
    """The car's block of the cascade (physical time) and the gramian blocks P11, P21
    (see :func:`h2_rational_filtered`): (A~, C1, D1, P11, P21)."""
    At, Pt = _companion(at, n)
    D1 = bt[n]
    C1 = np.empty(n)
    for i in range(n):
        C1[i] = w0 * (bt[i] - D1 * at[i])
    P11 = Pt / w0
    m = fA.shape[0]
    # Sylvester fA X + X A1^T = -fB (C1 P11 + D1 e_n^T), X = P21 (m x n)
    g = np.empty(n)
    for j in range(n):
        acc = 0.0
        for i in range(n):
            acc += C1[i] * P11[i, j]
        g[j] = acc
    g[n - 1] += D1
    R = np.empty((m, n))
    for i in range(m):
        for j in range(n):
            R[i, j] = fB[i] * g[j]
    P21 = _sylvester(fA, w0 * At.T, R)
    return At, C1, D1, P11, P21


@nb.njit(cache=True)
def h2_rational_filtered(polys, n, which, fA, fB, fC):
    """Squared H2 norm of W(s) row(s)/Delta(s): row ``which`` of ``polys`` over Delta
    (row 0, degree ``n``) followed by the filter W = fC (sI - fA)^-1 fB; inf if the car
    is not asymptotically stable or the row's degree exceeds n.

    Cascade x1' = A1 x1 + B1 w, y1 = C1 x1 + D1 w (the car's companion form in physical
    time: A1 = w0 A~, B1 = B~, C1 = w0 C~), x2' = fA x2 + fB y1, output fC x2. Its
    gramian [[P11, P12], [P21, P22]]: P11 = P~/w0, then
    fA P21 + P21 A1^T + fB (C1 P11 + D1 B1^T) = 0 (Sylvester, Kronecker form) and
    fA P22 + P22 fA^T + fB C1 P12 + P21 C1^T fB^T + D1^2 fB fB^T = 0; the norm is
    fC P22 fC^T."""
    ok, w0, at, bt = stable_scaled(polys, n, which)
    if not ok:
        return np.inf
    _, C1, D1, _, P21 = _cascade(w0, at, bt, n, fA, fB)
    m = fA.shape[0]
    h = P21 @ C1  # P21 C1^T (m)
    R = np.empty((m, m))
    for i in range(m):
        for j in range(m):
            R[i, j] = fB[i] * h[j] + h[i] * fB[j] + D1 * D1 * fB[i] * fB[j]
    P22 = lyapunov_packed(fA, R)
    acc = 0.0
    for i in range(m):
        for j in range(m):
            acc += fC[i] * P22[i, j] * fC[j]
    if not (acc >= 0.0):
        return np.inf
    return acc


@nb.njit(cache=True)
def h2_rational_filtered_gradient(polys, n, which, fA, fB, fC, g):
    """:func:`h2_rational_filtered` and its derivatives in the coefficients of Delta
    (``g[0, :n+1]``) and of row ``which`` (``g[1, :n+1]``), exact, by the adjoint of the
    cascade's Lyapunov equation; inf (and ``g`` NaN) where the norm is infinite.

    With the cascade A = [[A1, 0], [fB C1, fA]], B = [B1; fB D1], C = [0, fC] and its
    observability gramian L (A^T L + L A + C^T C = 0), solved block by block:
    fA^T L22 + L22 fA + fC^T fC = 0, fA^T L21 + L21 A1 + L22 fB C1 = 0 (Sylvester),
    A1^T L11 + L11 A1 + C1^T fB^T L21 + L21^T fB C1 = 0, the norm is B^T L B and its
    derivatives in A and B are 2 L P and 2 L B. A1's last row is -w0 at, C1 = w0 (bt -
    D1 at), D1 = bt[n]; the scaled coefficients are the polynomials' divided by
    Delta_n w0^(n-i), with w0 held (only the choice of realisation) and Delta_n
    scaling all of them."""
    ok, w0, at, bt = stable_scaled(polys, n, which)
    g[:, :] = np.nan
    if not ok:
        return np.inf
    an = polys[0, n]
    _, _, sc = _scaled(polys, n)
    At, C1, D1, P11, P21 = _cascade(w0, at, bt, n, fA, fB)
    fAT = fA.T.copy()
    L22 = lyapunov_packed(fAT, np.outer(fC, fC))
    G = np.outer(fB, C1)  # m x n
    L21 = _sylvester(fAT, w0 * At, L22 @ G)
    R = G.T @ L21
    L11 = lyapunov_packed(At.T.copy(), (R + R.T) / w0)
    # J = B^T L B, B = [e_n; fB D1]
    Lb = L22 @ fB
    l21 = np.ascontiguousarray(L21[:, n - 1])
    J = L11[n - 1, n - 1] + 2.0 * D1 * (fB @ l21) + D1 * D1 * (fB @ Lb)
    if not (J >= 0.0) or not np.isfinite(J):
        return np.inf
    # 2 L P on the rows that vary: n-1 (A1's last row) and the filter's (fB C1)
    LPlast = 2.0 * (np.ascontiguousarray(L11[n - 1, :]) @ P11 + l21 @ P21)
    LPf = 2.0 * (L21 @ P11 + L22 @ P21)  # m x n
    H = fB @ LPf  # dJ/dC1
    dat = np.empty(n)
    dbt = np.empty(n + 1)
    for j in range(n):
        dat[j] = -w0 * LPlast[j] - w0 * D1 * H[j]
        dbt[j] = w0 * H[j]
    LBf = 2.0 * (l21 + D1 * Lb)  # 2 L B on the filter's rows
    dD1 = fB @ LBf
    for j in range(n):
        dD1 -= w0 * H[j] * at[j]
    dbt[n] = dD1
    g[:, :] = 0.0
    s = 0.0
    for j in range(n):
        g[0, j] = dat[j] * sc[j]
        s += dat[j] * at[j]
    for j in range(n + 1):
        g[1, j] = dbt[j] * sc[j]
        s += dbt[j] * bt[j]
    g[0, n] = -s / an
    return J


# ---------------------------------------------------------------------------------------
# the variance of one output and its adjoint gradient (general state space)


def variance_gradient(A, B, c, *, delay=None, gradient: bool = True, what: str = "H2 norms"):
    """Variance J of y = c x for x' = A x + B w, w unit white noise, and its gradients.

    J = c P c^T with A P + P A^T + B B^T = 0. ``delay`` = (tau, front, rear): the
    columns ``rear`` of B carry the inputs of the columns ``front`` delayed by tau [s]
    (a vehicle's rear wheels on the front wheels' track), which adds
    2 c e^(A tau) X c^T, A X + X A^T + B_front B_rear^T = 0.

    Returns (J, dJ/dA, dJ/dB, dJ/dc) with the gradients as arrays of the shapes of A, B,
    c, so that dJ = <dJ/dA, dA> + <dJ/dB, dB> + <dJ/dc, dc> (elementwise products
    summed) for any change of the matrices; (J, None, None, None) without ``gradient``.
    The gradients come from the adjoint equations: L from A^T L + L A + c^T c = 0 gives
    the first term's 2 L P, 2 L B, 2 c P; the delay term's X is differentiated through
    the adjoint M of A^T M + M A = e^(A^T tau) c^T c and e^(A tau) through its Fréchet
    derivative (one evaluation, transposed: <G, L(A, E)> = <L(A^T, G), E>).
    """
    from scipy.linalg import expm_frechet, solve_continuous_lyapunov
    from scipy.sparse.linalg import expm_multiply

    A = np.asarray(A, dtype=float)
    B = np.asarray(B, dtype=float)
    c = np.asarray(c, dtype=float)
    P = gramian(A, B, what=what)
    J = float(c @ P @ c)
    if delay is not None:
        tau, front, rear = delay
        bf, br = B[:, list(front)], B[:, list(rear)]
        X = solve_continuous_lyapunov(A, -(bf @ br.T))
        if not gradient:  # c e^(A tau) = (e^(A^T tau) c^T)^T, one vector
            J += 2.0 * float(expm_multiply(A.T * tau, c) @ X @ c)
        else:
            E = expm_frechet(A * tau, np.zeros_like(A), compute_expm=True)[0]
            J += 2.0 * float(c @ E @ X @ c)
    if not gradient:
        return J, None, None, None
    cc = np.outer(c, c)
    L = solve_continuous_lyapunov(A.T, -cc)
    gA = 2.0 * L @ P
    gB = 2.0 * L @ B
    gc = 2.0 * c @ P
    if delay is not None:
        EX = E @ X
        gc = gc + 2.0 * (EX @ c + c @ EX)
        # through X: A dX + dX A^T = -(dA X + X dA^T + dB_f B_r^T + B_f dB_r^T)
        M = solve_continuous_lyapunov(A.T, E.T @ cc)
        gA = gA - 2.0 * (M @ X.T + M.T @ X)
        gB = gB.copy()
        gB[:, list(front)] -= 2.0 * M @ br
        gB[:, list(rear)] -= 2.0 * M.T @ bf
        # through e^(A tau): c dE X c^T = <c^T c X^T, L(A tau, tau dA)>
        _, Lt = expm_frechet(A.T * tau, cc @ X.T)
        gA = gA + 2.0 * tau * Lt
    return J, gA, gB, gc
