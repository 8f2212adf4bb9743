"""Alternating frequency-time (AFT) harmonic balance: basis, residual, Jacobian, Newton.

Each degree of freedom is a truncated Fourier series in the phase tau = Omega t,

    x(tau) = a0 + sum_{h=1..H} [a_h cos(h tau) + b_h sin(h tau)],          (7.17), (7.23)

stored as X = [a0, a1, b1, ..., aH, bH] per degree of freedom (the thesis writes
B0/2 and puts sine first; only the labels differ). The residual r(t) of the equation of
motion is evaluated at N equally spaced phases and projected back on the same
harmonics, R = F r (7.25)-(7.27); the real FFT does the projection in the numpy path and
an explicit DFT matrix in the compiled path (they are the same linear map). The
Jacobian is exact:

    dR/dX = F [diag(dr/dx) E + Omega diag(dr/dx') E1 + Omega^2 diag(dr/dx'') E2]

with E the synthesis matrix and E1, E2 its phase derivatives.

Aliasing: a polynomial nonlinearity of degree d maps harmonics up to H into harmonics
up to d H; N samples reproduce the first H coefficients exactly when
N >= (d + 1) H + 1. Fewer than 2 H + 1 samples cannot resolve H harmonics at all and
raise; between the two a warning is issued. The default is the smallest power of two
>= 2 d H + 1 (a margin for non-polynomial terms such as the flywheel's kink).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..resources import check_memory

__all__ = [
    "FourierBasis",
    "fourier_basis",
    "default_samples",
    "check_samples",
    "coefficients_by_fft",
]


@dataclass(frozen=True)
class FourierBasis:
    """Synthesis and projection matrices for H harmonics on N phase samples."""

    harmonics: int
    n_samples: int
    tau: np.ndarray
    E: np.ndarray
    E1: np.ndarray
    E2: np.ndarray
    F: np.ndarray

    @property
    def size(self) -> int:
        """2 H + 1, the number of coefficients per degree of freedom."""
        return 2 * self.harmonics + 1


def default_samples(harmonics: int, degree: int = 3) -> int:
    """Smallest power of two >= 2 * degree * harmonics + 1."""
    need = 2 * int(degree) * int(harmonics) + 1
    return 1 << (need - 1).bit_length()  # exact for integers of any size


def check_samples(harmonics: int, n_samples: int, degree: int) -> None:
    """Raise if N < 2H+1; warn if N < (d+1)H+1 (aliasing of a degree-d nonlinearity)."""
    if n_samples < 2 * harmonics + 1:
        raise ParameterError(
            "n_samples", n_samples, f"an integer >= 2*harmonics+1 = {2 * harmonics + 1}"
        )
    if n_samples < (degree + 1) * harmonics + 1:
        warnings.warn(
            f"n_samples={n_samples} < (degree+1)*harmonics+1 = {(degree + 1) * harmonics + 1}: "
            "higher harmonics of the nonlinear terms alias onto the retained ones",
            RuntimeWarning,
            stacklevel=3,
        )


def fourier_basis(harmonics: int, n_samples: int) -> FourierBasis:
    """Matrices E (N x m), E1 = dE/dtau, E2 = d2E/dtau2 and F (m x N), m = 2H+1.

    F @ E is the identity for N > 2 H.

    Examples
    --------
    >>> b = fourier_basis(3, 16)
    >>> bool(np.allclose(b.F @ b.E, np.eye(7)))
    True
    """
    H, N = int(harmonics), int(n_samples)
    tau = 2.0 * np.pi * np.arange(N) / N
    m = 2 * H + 1
    E = np.empty((N, m))
    E1 = np.zeros((N, m))
    E2 = np.zeros((N, m))
    F = np.empty((m, N))
    E[:, 0] = 1.0
    F[0] = 1.0 / N
    for h in range(1, H + 1):
        c, s = np.cos(h * tau), np.sin(h * tau)
        E[:, 2 * h - 1], E[:, 2 * h] = c, s
        E1[:, 2 * h - 1], E1[:, 2 * h] = -h * s, h * c
        E2[:, 2 * h - 1], E2[:, 2 * h] = -h * h * c, -h * h * s
        F[2 * h - 1], F[2 * h] = 2.0 * c / N, 2.0 * s / N
    return FourierBasis(H, N, tau, E, E1, E2, F)


def coefficients_by_fft(signal: np.ndarray, harmonics: int) -> np.ndarray:
    """Cos/sin coefficients [a0, a1, b1, ...] of samples along the last axis (real FFT)."""
    n = signal.shape[-1]
    c = np.fft.rfft(signal, axis=-1) / n
    out = np.empty(signal.shape[:-1] + (2 * harmonics + 1,))
    out[..., 0] = c[..., 0].real
    out[..., 1::2] = 2.0 * c[..., 1 : harmonics + 1].real
    out[..., 2::2] = -2.0 * c[..., 1 : harmonics + 1].imag
    return out


FAILURE_REASONS = {
    0: "ok",
    1: "iteration limit reached",
    2: "singular Jacobian",
    3: "line search found no residual decrease",
    4: "non-finite residual",
}


class NumpyEngine:
    """Engine for any system with ``evaluate`` (n degrees of freedom, numpy and FFT)."""

    def __init__(self, system, basis: FourierBasis):
        self.system = system
        self.basis = basis
        self.n_dof = int(system.n_dof)

    def _samples(self, X, omega):
        b = self.basis
        Xm = X.reshape(self.n_dof, b.size)
        return Xm @ b.E.T, omega * (Xm @ b.E1.T), omega**2 * (Xm @ b.E2.T)

    def relative_residuals(self, omegas, C):
        out = np.empty(len(omegas))
        for i, w in enumerate(omegas):
            r = np.linalg.norm(self.residual(C[i], w))
            r0 = np.linalg.norm(self.residual(np.zeros(C.shape[1]), w))
            out[i] = r / r0 if r0 > 0 else r
        return out

    def residual(self, X, omega):
        x, xd, xdd = self._samples(X, omega)
        r = self.system.evaluate(self.basis.tau, omega, x, xd, xdd)[0]
        return coefficients_by_fft(r, self.basis.harmonics).ravel()

    def _blocks(self, gx, gv, ga, omega, c1, c2):
        b = self.basis
        # G[i, j, unknown, sample] = d r_i(sample) / d X_j(unknown)
        G = (
            gx[:, :, None, :] * b.E.T[None, None]
            + c1 * gv[:, :, None, :] * b.E1.T[None, None]
            + c2 * ga[:, :, None, :] * b.E2.T[None, None]
        )
        C = coefficients_by_fft(G, b.harmonics)  # [i, j, unknown, equation]
        n, m = self.n_dof, b.size
        return C.transpose(0, 3, 1, 2).reshape(n * m, n * m)

    def residual_jacobian(self, X, omega):
        x, xd, xdd = self._samples(X, omega)
        r, gx, gv, ga = self.system.evaluate(self.basis.tau, omega, x, xd, xdd)
        R = coefficients_by_fft(np.asarray(r), self.basis.harmonics).ravel()
        return R, self._blocks(gx, gv, ga, omega, omega, omega**2)

    def hill_matrices(self, X, omega):
        x, xd, xdd = self._samples(X, omega)
        _, gx, gv, ga = self.system.evaluate(self.basis.tau, omega, x, xd, xdd)
        z = np.zeros_like(gx)
        J0 = self._blocks(gx, gv, ga, omega, omega, omega**2)
        # d/d lambda: x' -> x' + lambda y, x'' -> x'' + 2 lambda y' + lambda^2 y
        J1 = self._blocks(gv, ga, z, omega, 2.0 * omega, 0.0)
        J2 = self._blocks(ga, z, z, omega, 0.0, 0.0)
        return J0, J1, J2

    def newton(self, X0, omega, rtol, max_iter, scale):
        X = np.array(X0, dtype=float)
        R, J = self.residual_jacobian(X, omega)
        rn = float(np.linalg.norm(R))
        for it in range(max_iter):
            if not np.isfinite(rn):
                return X, False, it, rn, 4
            try:
                dX = np.linalg.solve(J, -R)
            except np.linalg.LinAlgError:
                return X, False, it, rn, 2
            step, accepted = 1.0, False
            for _ in range(12):
                Xn = X + step * dX
                Rn, Jn = self.residual_jacobian(Xn, omega)
                rnn = float(np.linalg.norm(Rn))
                if np.isfinite(rnn) and (rnn <= (1.0 - 1e-4 * step) * rn or rnn < 1e-300):
                    accepted = True
                    break
                step *= 0.5
            if not accepted:
                small = np.linalg.norm(dX) <= 1e3 * rtol * (np.linalg.norm(X) + scale)
                return X, bool(small), it, rn, 0 if small else 3
            X, R, J, rn = Xn, Rn, Jn, rnn
            if step == 1.0 and np.linalg.norm(dX) <= rtol * (np.linalg.norm(X) + scale):
                return X, True, it + 1, rn, 0
        return X, False, max_iter, rn, 1

    def sweep(self, omegas, X_start, rtol, max_iter, scale, warm, X_cold=None):
        X_cold = np.zeros(len(X_start)) if X_cold is None else X_cold
        n_pts, m = len(omegas), len(X_start)
        out = np.zeros((n_pts, m))
        ok = np.zeros(n_pts, dtype=bool)
        iters = np.zeros(n_pts, dtype=np.int64)
        res = np.zeros(n_pts)
        code = np.zeros(n_pts, dtype=np.int64)
        X_last, X_prev, w_last, w_prev = X_start.copy(), X_start.copy(), -1.0, -1.0
        for i, w in enumerate(omegas):
            guess = X_cold.copy()
            if warm:
                guess = X_last.copy()
                if w_prev > 0 and w_last != w_prev:
                    guess = X_last + (X_last - X_prev) * ((w - w_last) / (w_last - w_prev))
            X, conv, it, rn, c = self.newton(guess, w, rtol, max_iter, scale)
            if not conv and warm and w_last > 0:
                Xs, conv = X_last.copy(), True
                for s in range(1, 9):
                    ws = w_last + (w - w_last) * s / 8
                    Xs, cs, its, rn, c = self.newton(Xs, ws, rtol, max_iter, scale)
                    it += its
                    if not cs:
                        conv = False
                        break
                X = Xs
                if not conv:
                    X, conv, its, rn, c = self.newton(X_cold, w, rtol, max_iter, scale)
                    it += its
            out[i], ok[i], iters[i], res[i], code[i] = X, conv, it, rn, c
            if conv:
                X_prev, w_prev, X_last, w_last = X_last, w_last, X, w
        return out, ok, iters, res, code


def checked_samples(system, harmonics, n_samples: int | None, n_states: int = 1) -> int:
    """The samples per period N of a balance with ``harmonics`` (checked: an integer
    >= 1) on ``n_states`` series: ``n_samples`` or the default for the system's
    nonlinearity degree, checked against aliasing; the basis and the Jacobian and
    stability matrices, which grow with (n (2H+1))^2, must fit in memory."""
    if not isinstance(harmonics, int | np.integer) or isinstance(harmonics, bool) or harmonics < 1:
        raise ParameterError("harmonics", harmonics, "an integer >= 1")
    degree = int(getattr(system, "nonlinearity_degree", 3))
    n = default_samples(int(harmonics), degree) if n_samples is None else int(n_samples)
    check_samples(int(harmonics), n, degree)
    size = (2 * int(harmonics) + 1) * int(n_states)
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
    return n


def make_engine(system, harmonics: int, n_samples: int | None = None):
    """The harmonic-balance engine for ``system``: the one engine of
    :mod:`inerterlab.frequency.first_order` on the system's first-order form (the
    built-in systems, ``system.first_order()``, with their own input amplitude), numpy
    for a :class:`~inerterlab.frequency.UserSystem` given by Python functions."""
    if hasattr(system, "first_order"):
        from .first_order import make_first_order_engine

        form = system.first_order()
        return make_first_order_engine(form, harmonics, n_samples, form.input_amplitude)
    n = checked_samples(system, harmonics, n_samples)
    return NumpyEngine(system, fourier_basis(int(harmonics), n))


def hill_exponents(engine, X, omega):
    """Floquet exponents [1/s] of the HB solution by Hill's method.

    Solves the quadratic eigenproblem (lambda^2 J2 + lambda J1 + J0) q = 0 through its
    companion form and keeps the 2 n eigenvalues with the smallest |Im lambda|, which
    approximate the Floquet exponents best (the others are copies shifted by
    multiples of i Omega). The one engine gives them by its own Hill matrix on every
    harmonic (:meth:`~inerterlab.frequency.first_order.FirstOrderEngine.stability`).
    """
    if hasattr(engine, "stability"):
        X = np.ascontiguousarray(X, dtype=float)[None]
        return engine.stability(np.array([float(omega)]), X, np.array([True]))[1][0]
    J0, J1, J2 = engine.hill_matrices(X, omega)
    m = J0.shape[0]
    try:
        A = np.linalg.solve(J2, np.hstack([J0, J1]))
    except np.linalg.LinAlgError:
        return np.full(2 * engine.n_dof, np.nan + 0j)
    comp = np.zeros((2 * m, 2 * m))
    comp[:m, m:] = np.eye(m)
    comp[m:, :m] = -A[:, :m]
    comp[m:, m:] = -A[:, m:]
    lam = np.linalg.eigvals(comp)
    order = np.argsort(np.abs(lam.imag))
    return lam[order[: 2 * engine.n_dof]]


def is_stable(exponents, omega, tol: float = 1e-7) -> bool:
    """Stable when every Floquet exponent has Re(lambda) < tol * Omega."""
    if not np.all(np.isfinite(exponents)):
        return False
    return bool(np.max(exponents.real) < tol * omega)
