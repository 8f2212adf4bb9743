"""Alternating frequency-time (AFT) harmonic balance: the Fourier basis, the sample
count and its checks, and the driver-level helpers of the one engine
(:mod:`inerterlab.frequency.first_order`).

Each degree of freedom is a truncated Fourier series in the phase tau = Omega t,

    x(tau) = a0 + sum_{h=1..H} [a_h cos(h tau) + b_h sin(h tau)],          (7.17), (7.23)

stored as X = [a0, a1, b1, ..., aH, bH] per degree of freedom (the thesis writes
B0/2 and puts sine first; only the labels differ). The residual r(t) of the equation of
motion is evaluated at N equally spaced phases and projected back on the same
harmonics, R = F r (7.25)-(7.27), F an explicit DFT matrix (the real FFT of
:func:`coefficients_by_fft` is the same linear map, used on brute-force samples). The
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
    """The harmonic-balance engine for ``system`` (a built-in system or a
    :class:`~inerterlab.frequency.UserSystem`): the one engine of
    :mod:`inerterlab.frequency.first_order` on the system's first-order form
    (``system.first_order()``, with its own input amplitude)."""
    from .first_order import make_first_order_engine

    if not hasattr(system, "first_order"):
        raise ParameterError(
            "system", system, "a built-in system, a UserSystem or a first-order system"
        )
    form = system.first_order()
    return make_first_order_engine(form, harmonics, n_samples, form.input_amplitude)


def hill_exponents(engine, X, omega):
    """Floquet exponents [1/s] of the HB solution by Hill's method on every harmonic
    (:meth:`~inerterlab.frequency.first_order.FirstOrderEngine.stability`): the
    eigenvalues nearest the real axis of the Hill matrix, one per state (the others are
    copies shifted by multiples of i Omega)."""
    X = np.ascontiguousarray(X, dtype=float)[None]
    return engine.stability(np.array([float(omega)]), X, np.array([True]))[1][0]


def is_stable(exponents, omega, tol: float = 1e-7) -> bool:
    """Stable when every Floquet exponent has Re(lambda) < tol * Omega."""
    if not np.all(np.isfinite(exponents)):
        return False
    return bool(np.max(exponents.real) < tol * omega)
