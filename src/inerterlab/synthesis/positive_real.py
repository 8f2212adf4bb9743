"""Positive-real functions: a parametrisation that is PR by construction, and checks.

A rational function Y = N/D with real coefficients is positive real (PR) when it is
analytic in Re s > 0 and Re Y(s) >= 0 there; for D strictly Hurwitz (every root in
Re s < 0) this is equivalent to Re Y(j w) >= 0 for every real w (Brune 1931).
Writing Re Y(j w) = E(w^2) / |D(j w)|^2, the even polynomial E is

    E(-s^2) = (N(s) D(-s) + N(-s) D(s)) / 2,

so every PR function with a strictly Hurwitz denominator of degree n is fixed by D
and a polynomial E of degree <= n that is >= 0 on [0, inf); given D and E the
numerator follows from a linear system of n + 1 equations (Gewertz's method: a
function from its real part; Gewertz 1933, see Guillemin 1957, ch. 9). Hence the
parametrisation used for the synthesis, PR by construction and with exactly 2n + 1
free numbers (D monic):

* D from the Routh/Stieltjes continued fraction: a real polynomial of degree n with
  positive leading coefficient is strictly Hurwitz iff the ratio of its even and odd
  parts expands as  a_1 s + 1/(a_2 s + 1/(... + 1/(a_n s)))  with every a_i > 0
  (Wall 1945; the Routh test). Any positive a_1..a_n gives a Hurwitz D.
* E from the Markov-Lukacs theorem: a polynomial of degree n that is >= 0 on
  [0, inf) is p(x)^2 + x q(x)^2 (n = 2m; deg p <= m, deg q <= m - 1) or
  x p(x)^2 + q(x)^2 (n = 2m + 1; deg p, deg q <= m) (Powers & Reznick 2000, Thm 2.2).

Poles on the imaginary axis (lossless parts) are limits of this family, reached as
some a_i -> 0 or infinity.
"""

from __future__ import annotations

import numba as nb
import numpy as np

__all__ = [
    "hurwitz_from_fraction",
    "even_part_from_squares",
    "numerator_from_even_part",
    "pr_from_parameters",
    "pr_report",
    "is_positive_real",
    "biquadratic_pr_condition",
    "real_part_polynomials",
    "is_regular",
    "minimum_at_the_ends",
]


@nb.njit(cache=True)
def hurwitz_from_fraction(alpha):
    """Monic strictly Hurwitz polynomial (ascending) from positive a_1..a_n."""
    n = alpha.shape[0]
    # F = p/q built from the bottom: F_n = a_n s; F_i = a_i s + 1/F_{i+1} = (a_i s p + q)/p
    p = np.zeros(n + 1)
    q = np.zeros(n + 1)
    p[1] = alpha[n - 1]
    q[0] = 1.0
    for i in range(n - 2, -1, -1):
        newp = np.zeros(n + 1)
        for j in range(n):
            newp[j + 1] += alpha[i] * p[j]
        for j in range(n + 1):
            newp[j] += q[j]
        q = p.copy()
        p = newp
    d = p + q
    return d / d[n]


@nb.njit(cache=True)
def even_part_from_squares(u, n):
    """Coefficients (in x = w^2, ascending) of a polynomial >= 0 on [0, inf), degree n.

    ``u`` holds n + 1 numbers: the coefficients of p, then of q (Markov-Lukacs form).
    """
    e = np.zeros(n + 1)
    if n % 2 == 0:
        m = n // 2
        p = u[: m + 1]
        q = u[m + 1 :]
        for i in range(m + 1):
            for j in range(m + 1):
                e[i + j] += p[i] * p[j]
        for i in range(m):
            for j in range(m):
                e[i + j + 1] += q[i] * q[j]
    else:
        m = (n - 1) // 2
        p = u[: m + 1]
        q = u[m + 1 :]
        for i in range(m + 1):
            for j in range(m + 1):
                e[i + j + 1] += p[i] * p[j]
                e[i + j] += q[i] * q[j]
    return e


@nb.njit(cache=True)
def numerator_from_even_part(d, e):
    """N (ascending) with (N(s) D(-s) + N(-s) D(s))/2 = E(-s^2) (Gewertz).

    Row j (power s^(2j)): sum_a N_a D_(2j-a) (-1)^a = (-1)^j E_j.
    """
    n = d.shape[0] - 1
    M = np.zeros((n + 1, n + 1))
    r = np.zeros(n + 1)
    for j in range(n + 1):
        r[j] = e[j] * (-1.0) ** j
        for a in range(n + 1):
            b = 2 * j - a
            if 0 <= b <= n:
                M[j, a] = d[b] * (-1.0) ** a
    return np.linalg.solve(M, r)


@nb.njit(cache=True)
def pr_from_parameters(x, n):
    """PR function N/D of degree <= n (ascending, D monic) from 2n + 1 numbers.

    x[:n]: log10 of the continued-fraction coefficients of D; x[n:]: the squares'
    coefficients of E through sinh (fine near 0, wide range).
    """
    alpha = 10.0 ** x[:n]
    d = hurwitz_from_fraction(alpha)
    u = np.sinh(x[n:])
    e = even_part_from_squares(u, n)
    return numerator_from_even_part(d, e), d


def is_positive_real(num, den, grid: int = 4001, tol: float = 1e-9) -> bool:
    """Numerical PR test of N/D (highest power first); see :func:`pr_report`."""
    return pr_report(num, den, grid=grid, tol=tol)["positive_real"]


def pr_report(num, den, grid: int = 4001, tol: float = 1e-9) -> dict:
    """Numerical PR check: poles and zeros in Re s <= 0, Re Y(j w) >= 0 on a dense grid.

    The grid is logarithmic over the span of the pole and zero magnitudes (four
    decades beyond each end) plus w = 0; ``tol`` is relative to max |Y(j w)|. A root
    with a real part within ``tol`` of its magnitude counts as on the imaginary axis;
    the simplicity and the sign of the residues of such poles are not examined.
    """
    num = np.trim_zeros(np.asarray(num, float), "f")
    den = np.trim_zeros(np.asarray(den, float), "f")
    roots = np.concatenate([np.roots(num), np.roots(den)])
    mags = np.abs(roots[np.abs(roots) > 0])
    lo = np.log10(mags.min()) - 4 if mags.size else -4
    hi = np.log10(mags.max()) + 4 if mags.size else 4
    w = np.concatenate([[0.0], np.logspace(lo, hi, grid)])
    with np.errstate(divide="ignore", invalid="ignore"):
        y = np.polyval(num, 1j * w) / np.polyval(den, 1j * w)
    fin = np.isfinite(y)
    scale = np.max(np.abs(y[fin])) if fin.any() else 1.0
    min_re = float(np.min(y.real[fin])) if fin.any() else 0.0
    rmax = max(float(np.max(np.abs(roots))) if roots.size else 1.0, 1.0)
    right = [
        complex(r) for r in roots if r.real > tol * max(abs(r), 1e-300) and r.real > 1e-12 * rmax
    ]
    ok = min_re >= -tol * scale and not right
    return {
        "positive_real": bool(ok),
        "min_real_part": min_re,
        "max_magnitude": float(scale),
        "right_half_plane_roots": right,
        "max_root_real_part": float(np.max(roots.real)) if roots.size else 0.0,
    }


def biquadratic_pr_condition(num, den) -> bool:
    """Closed-form PR test of a biquadratic (a2 s^2 + a1 s + a0)/(d2 s^2 + d1 s + d0).

    With every coefficient >= 0 (and the denominator and numerator not identically 0),
    the function is PR iff  a1 d1 >= (sqrt(a2 d0) - sqrt(a0 d2))^2
    (e.g. Chen & Smith 2009, Lemma 4; Foster & Ladenheim 1963).
    """
    a2, a1, a0 = (list(np.zeros(3 - len(num))) + list(num))[-3:]
    d2, d1, d0 = (list(np.zeros(3 - len(den))) + list(den))[-3:]
    if min(a2, a1, a0, d2, d1, d0) < 0:
        return False
    return bool(a1 * d1 >= (np.sqrt(a2 * d0) - np.sqrt(a0 * d2)) ** 2)


def real_part_polynomials(num, den):
    """(E, F) in x = w^2 (highest power first) with Re Y(j w) = E(w^2) / F(w^2).

    E(-s^2) = (N(s) D(-s) + N(-s) D(s)) / 2 and F(-s^2) = D(s) D(-s), both even in s.
    """
    num = np.trim_zeros(np.asarray(num, float), "f")
    den = np.trim_zeros(np.asarray(den, float), "f")

    def minus(p):  # p(-s), highest first
        n = len(p) - 1
        return p * (-1.0) ** np.arange(n, -1, -1)

    def in_x(even):  # even polynomial in s (highest first) -> polynomial in x = -s^2
        asc = even[::-1]
        c = np.array([asc[2 * j] * (-1.0) ** j for j in range((len(asc) + 1) // 2)])
        return np.trim_zeros(c[::-1], "f") if np.any(c) else np.zeros(1)

    e = np.polyadd(np.polymul(num, minus(den)), np.polymul(minus(num), den)) / 2.0
    f = np.polymul(den, minus(den))
    return in_x(e), in_x(f)


def is_regular(num, den, tol: float = 1e-9) -> bool:
    """Is the PR function Y = N/D (highest power first) *regular*?

    Jiang & Smith (2011, IEEE TAC 56(6), the definition of a regular PR function): the
    smallest value of Re Y(j w) or of Re (1/Y)(j w) over 0 <= w <= inf is attained at
    w = 0 or w = inf. The "or" makes the class closed under Y -> 1/Y (as the networks
    it characterises are under duality). See :func:`minimum_at_the_ends`.
    """
    return minimum_at_the_ends(num, den, tol) or minimum_at_the_ends(den, num, tol)


def minimum_at_the_ends(num, den, tol: float = 1e-9) -> bool:
    """Does Re Y(j w) (Y = N/D) attain its smallest value over [0, inf] at w = 0 or inf?

    Computed exactly rather than on a grid: with Re Y(j w) = E(x)/F(x), x = w^2
    (:func:`real_part_polynomials`), the interior extrema are the positive roots of
    E'F - EF'; the answer is yes when none of them lies below min(value at x = 0,
    value at infinity) by more than ``tol`` times the largest value compared. Roots of
    F on x > 0 (imaginary-axis poles) are skipped.
    """
    e, f = real_part_polynomials(num, den)
    r0 = np.polyval(e, 0.0) / np.polyval(f, 0.0) if np.polyval(f, 0.0) != 0 else np.inf
    de, df = len(e) - 1, len(f) - 1
    if de < df:
        rinf = 0.0
    elif de == df:
        rinf = e[0] / f[0]
    else:
        rinf = np.inf
    ends = min(r0, rinf)
    crit = np.polysub(np.polymul(np.polyder(e), f), np.polymul(e, np.polyder(f)))
    crit = np.trim_zeros(crit, "f")
    vals = []
    if len(crit) > 1:
        for x in np.roots(crit):
            if abs(x.imag) > 1e-9 * max(1.0, abs(x)) or x.real <= 0:
                continue
            fx = np.polyval(f, x.real)
            if abs(fx) <= 1e-12 * np.max(np.abs(f)) * max(1.0, x.real) ** (len(f) - 1):
                continue
            vals.append(np.polyval(e, x.real) / fx)
    if not vals:
        return True
    finite = [abs(v) for v in (*vals, r0, rinf) if np.isfinite(v)]
    scale = max(finite) if finite else 1.0
    return bool(min(vals) >= ends - tol * scale)
