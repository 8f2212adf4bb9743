"""Linear quarter car with any linear two-terminal network as its suspension.

The network (see :mod:`inerterlab.networks`) sits between the unsprung mass m_u and the
sprung mass m_s; its force is F(s) = Y(s) (v_u - v_s), Y = N/D its admittance. The tyre
is a spring k_t and a damper c_t to the road, whose velocity w is the input. With
P = m_s s D + N the Laplace-domain equations

    m_s s v_s = Y (v_u - v_s),    m_u s v_u = -Y (v_u - v_s) + (k_t/s + c_t)(w - v_u)

give every transfer from w over the one denominator

    Delta = m_u s^2 P + m_s s^2 N + (c_t s + k_t) P

with numerators

    body acceleration                   s (c_t s + k_t) N
    tyre deflection x_u - x_road       -s (m_u P + m_s N)
    suspension deflection x_s - x_u    -m_s (c_t s + k_t) D

Massless internal nodes of the network need no special care: they are inside Y(s).
For generic parameters N/D is coprime (common factors s are cancelled when it is
built), so deg Delta = deg D + 3 is the number of states of a minimal realisation: the
four of the car and one per independent energy store of the network.

H2 norms: the transfers over Delta go to the compiled rational route of
:mod:`inerterlab.h2` (frequency scaling, controllable canonical form, Lyapunov equation
on the distinct entries of the gramian), so

    ||H||_2^2 = (1/2 pi) int |H(j w)|^2 dw.

Stability is decided first by the Routh test on Delta; an unstable or marginally
stable car, or an output with direct feed-through (body acceleration when an inerter
acts at high frequency and the tyre is damped), has an infinite norm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba as nb
import numpy as np

from ..elements import ELEMENTS
from ..errors import check_nonnegative, check_physical, check_positive
from ..h2 import h2_rational, hurwitz
from ..networks import Network, NetworkError, parse_network

#: the kind of quantity of each linear element's parameter (for its physical range), as
#: the element declares it (:attr:`inerterlab.elements.Param.quantity`)
_QUANTITY = {p: ELEMENTS[p].PARAMETERS[0].quantity for p in ("k", "c", "b")}

__all__ = [
    "OUTPUTS",
    "NetworkQuarterCar",
    "network_quarter_car",
    "network_h2",
    "h2_squared_admittance",
]

OUTPUTS = ("body_acc", "tyre_deflection", "suspension_deflection")
MAXC = 32  # polynomial coefficient slots (networks up to ~28 elements)

# ---------------------------------------------------------------------------------------
# compiled kernels; polynomials are ascending coefficient arrays with explicit lengths


@nb.njit(cache=True)
def _pmul(a, la, b, lb, out):
    for i in range(la + lb - 1):
        out[i] = 0.0
    for i in range(la):
        for j in range(lb):
            out[i + j] += a[i] * b[j]
    return la + lb - 1


@nb.njit(cache=True)
def _assemble(prog, theta, num, den):
    """Admittance of the post-order program; returns (len(num), len(den))."""
    m = prog.shape[0]
    sn = np.zeros((m, MAXC))
    sd = np.zeros((m, MAXC))
    ln = np.zeros(m, np.int64)
    ld = np.zeros(m, np.int64)
    t1 = np.zeros(MAXC)
    t2 = np.zeros(MAXC)
    t3 = np.zeros(MAXC)
    top = 0
    for r in range(m):
        op = prog[r, 0]
        if op == 0:
            x = theta[prog[r, 1]]
            kind = prog[r, 2]
            sn[top, :] = 0.0
            sd[top, :] = 0.0
            if kind == 0:  # spring k/s
                sn[top, 0] = x
                ln[top] = 1
                sd[top, 1] = 1.0
                ld[top] = 2
            elif kind == 1:  # damper c
                sn[top, 0] = x
                ln[top] = 1
                sd[top, 0] = 1.0
                ld[top] = 1
            else:  # inerter b s
                sn[top, 1] = x
                ln[top] = 2
                sd[top, 0] = 1.0
                ld[top] = 1
            top += 1
            continue
        i, j = top - 2, top - 1
        if op == 1:  # parallel: (N1 D2 + N2 D1) / (D1 D2)
            l1 = _pmul(sn[i], ln[i], sd[j], ld[j], t1)
            l2 = _pmul(sn[j], ln[j], sd[i], ld[i], t2)
            lnum = max(l1, l2)
            for q in range(lnum):
                sn[i, q] = (t1[q] if q < l1 else 0.0) + (t2[q] if q < l2 else 0.0)
            ldd = _pmul(sd[i], ld[i], sd[j], ld[j], t1)
            for q in range(ldd):
                sd[i, q] = t1[q]
        else:  # series: N1 N2 / (D1 N2 + D2 N1)
            l1 = _pmul(sd[i], ld[i], sn[j], ln[j], t1)
            l2 = _pmul(sd[j], ld[j], sn[i], ln[i], t2)
            ldd = max(l1, l2)
            for q in range(ldd):
                t3[q] = (t1[q] if q < l1 else 0.0) + (t2[q] if q < l2 else 0.0)
            lnum = _pmul(sn[i], ln[i], sn[j], ln[j], t1)
            for q in range(lnum):
                sn[i, q] = t1[q]
            for q in range(ldd):
                sd[i, q] = t3[q]
        # cancel common factors s (exact zeros: products with an exact 0)
        sh = 0
        while sh < lnum - 1 and sh < ldd - 1 and sn[i, sh] == 0.0 and sd[i, sh] == 0.0:
            sh += 1
        if sh:
            for q in range(lnum - sh):
                sn[i, q] = sn[i, q + sh]
            for q in range(ldd - sh):
                sd[i, q] = sd[i, q + sh]
            lnum -= sh
            ldd -= sh
        while lnum > 1 and sn[i, lnum - 1] == 0.0:
            lnum -= 1
        while ldd > 1 and sd[i, ldd - 1] == 0.0:
            ldd -= 1
        ln[i] = lnum
        ld[i] = ldd
        top -= 1
    for q in range(ln[0]):
        num[q] = sn[0, q]
    for q in range(ld[0]):
        den[q] = sd[0, q]
    return ln[0], ld[0]


@nb.njit(cache=True)
def _car_polys(num, lnum, den, lden, ms, mu, kt, ct, polys):
    """Rows of ``polys``: Delta, body_acc, tyre_deflection, suspension_deflection; returns n."""
    polys[:, :] = 0.0
    p = np.zeros(MAXC)
    lp = max(lden + 1, lnum)
    for q in range(lden):
        p[q + 1] += ms * den[q]
    for q in range(lnum):
        p[q] += num[q]
    # Delta = mu s^2 P + ms s^2 N + (ct s + kt) P
    for q in range(lp):
        polys[0, q + 2] += mu * p[q]
        polys[0, q] += kt * p[q]
        polys[0, q + 1] += ct * p[q]
    for q in range(lnum):
        polys[0, q + 2] += ms * num[q]
    # body acceleration s (ct s + kt) N
    for q in range(lnum):
        polys[1, q + 1] += kt * num[q]
        polys[1, q + 2] += ct * num[q]
    # tyre deflection x_u - x_road: -s (mu P + ms N)
    for q in range(lp):
        polys[2, q + 1] -= mu * p[q]
    for q in range(lnum):
        polys[2, q + 1] -= ms * num[q]
    # suspension deflection x_s - x_u: -ms (ct s + kt) D
    for q in range(lden):
        polys[3, q] -= ms * kt * den[q]
        polys[3, q + 1] -= ms * ct * den[q]
    n = MAXC - 1
    while n > 0 and polys[0, n] == 0.0:
        n -= 1
    return n


@nb.njit(cache=True)
def h2_squared(prog, theta, car, out):
    """Squared H2 norms [body_acc, tyre_deflection, suspension_deflection] into ``out``.

    ``car`` = [m_s, m_u, k_t, c_t]; ``theta`` the network parameters in program order.
    """
    num = np.zeros(MAXC)
    den = np.zeros(MAXC)
    lnum, lden = _assemble(prog, theta, num, den)
    h2_squared_admittance(num, lnum, den, lden, car, out)


@nb.njit(cache=True)
def h2_squared_admittance(num, lnum, den, lden, car, out):
    """Squared H2 norms for an admittance given as polynomials N/D (ascending, lengths).

    The one H2 route of the package: :func:`h2_squared` (a network) and the
    positive-real synthesis (an admittance without a network) both end here.
    """
    polys = np.zeros((4, MAXC))
    n = _car_polys(num, lnum, den, lden, car[0], car[1], car[2], car[3], polys)
    h2_rational(polys, n, out)


@nb.njit(cache=True)
def h2_squared_many(prog, thetas, car, out):
    """Rows of ``thetas`` at once (one call from Python for a batch of candidates)."""
    o = np.empty(3)
    for r in range(thetas.shape[0]):
        h2_squared(prog, thetas[r], car, o)
        for q in range(3):
            out[r, q] = o[q]


# ---------------------------------------------------------------------------------------
# Python interface


@dataclass(frozen=True)
class NetworkQuarterCar:
    """A quarter car whose suspension is the linear network ``network``.

    Defaults are those of ``inerterlab h2`` (thesis (4.16)): m_s = 370 kg,
    m_u = 25 kg, k_t = 120 kN/m, c_t = 1300 N s/m.
    """

    network: Network
    sprung_mass: float = 370.0
    unsprung_mass: float = 25.0
    tyre_stiffness: float = 120_000.0
    tyre_damping: float = 1300.0
    _prog: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "network", parse_network(self.network))
        check_positive("sprung_mass", self.sprung_mass, "kg")
        check_positive("unsprung_mass", self.unsprung_mass, "kg")
        check_positive("tyre_stiffness", self.tyre_stiffness, "N/m")
        check_nonnegative("tyre_damping", self.tyre_damping, "N s/m")
        check_physical("sprung_mass", self.sprung_mass, "mass")
        check_physical("unsprung_mass", self.unsprung_mass, "mass")
        check_physical("tyre_stiffness", self.tyre_stiffness, "stiffness")
        check_physical("tyre_damping", self.tyre_damping, "damping", zero=True)
        self.network.require_linear()
        if len(self.network.names) > MAXC - 6:
            raise NetworkError(
                f"network {self.network.text!r}: {len(self.network.names)} elements; "
                f"the compiled evaluator takes at most {MAXC - 6}"
            )
        object.__setattr__(self, "_prog", self.network.program())

    @property
    def car_vector(self) -> np.ndarray:
        return np.array(
            [self.sprung_mass, self.unsprung_mass, self.tyre_stiffness, self.tyre_damping],
            dtype=float,
        )

    @property
    def program(self) -> np.ndarray:
        return self._prog

    def theta(self, params: dict) -> np.ndarray:
        """Parameter values in the order of the network's names, each finite, > 0 and
        within the physical range of its kind (:data:`inerterlab.errors.PHYSICAL_RANGES`)."""
        th = self.network.parameter_vector(params)
        for name, kind, x in zip(self.network.names, self.network.kinds, th, strict=True):
            check_physical(name, float(x), _QUANTITY[kind])
        return th

    def polynomials(self, params: dict) -> dict:
        """Denominator ``den`` and the output numerators, highest power first."""
        th = self.theta(params)
        num, den = np.zeros(MAXC), np.zeros(MAXC)
        ln, ld = _assemble(self._prog, th, num, den)
        polys = np.zeros((4, MAXC))
        n = _car_polys(num, ln, den, ld, *self.car_vector, polys)
        out = {"den": polys[0, : n + 1][::-1].copy()}
        for i, k in enumerate(OUTPUTS):
            out[k] = np.trim_zeros(polys[i + 1, : n + 1][::-1], "f")
        out["admittance"] = (num[:ln][::-1].copy(), den[:ld][::-1].copy())
        return out

    def transfer(self, params: dict, omega) -> dict:
        """H(j omega) from road velocity to each output, omega in rad/s."""
        p = self.polynomials(params)
        s = 1j * np.asarray(omega, dtype=float)
        d = np.polyval(p["den"], s)
        return {k: np.polyval(p[k], s) / d for k in OUTPUTS}

    def state_space(self, params: dict) -> tuple[np.ndarray, np.ndarray, dict, dict]:
        """A minimal realisation x' = A x + B w, y = C[k] x + D[k] w (physical time).

        Controllable canonical form of the frequency-scaled transfers, mapped back:
        A = w0 A~, B = B~, C = w0 C~.
        """
        p = self.polynomials(params)
        den = p["den"][::-1]
        n = len(den) - 1
        an = den[n]
        w0 = (den[0] / an) ** (1.0 / n)
        scale = 1.0 / (an * w0 ** (n - np.arange(n + 1)))
        at = den * scale
        A = np.zeros((n, n))
        A[np.arange(n - 1), np.arange(1, n)] = 1.0
        A[-1, :] = -at[:n]
        B = np.zeros(n)
        B[-1] = 1.0
        C, D = {}, {}
        for k in OUTPUTS:
            row = np.zeros(n + 1)
            coef = p[k][::-1]
            row[: len(coef)] = coef
            bt = row * scale
            D[k] = float(bt[n])
            C[k] = w0 * (bt[:n] - bt[n] * at[:n])
        return w0 * A, B, C, D

    def h2(self, params: dict) -> dict:
        """H2 norms per unit white road velocity; ``math.inf`` where infinite."""
        out = np.empty(3)
        h2_squared(self._prog, self.theta(params), self.car_vector, out)
        return {
            k: (math.sqrt(v) if np.isfinite(v) and v >= 0 else math.inf)
            for k, v in zip(OUTPUTS, out, strict=True)
        }

    def h2_reasons(self, params: dict) -> dict:
        """Why a norm is infinite, for each output whose norm is."""
        norms = self.h2(params)
        p = self.polynomials(params)
        den = p["den"][::-1]
        stable = bool(hurwitz(den / den[-1], len(den) - 1)) if den[0] > 0 else False
        out = {}
        why = _instability(self.network, p["admittance"]) if not stable else ""
        for k, v in norms.items():
            if math.isfinite(v):
                continue
            if not stable:
                out[k] = (
                    f"infinite: the quarter car with this network is not asymptotically stable ({why})"
                )
            else:
                out[k] = (
                    f"infinite: the road velocity feeds straight through to {k} "
                    "(an inerter acting at high frequency with a damped tyre)"
                )
        return out


def _instability(net: Network, adm) -> str:
    """Name the sub-network that makes the car marginally stable, where one stands out."""
    from ..networks import Combination, Element

    num, den = adm
    if den[-1] != 0.0:
        return (
            f"network {net.text!r} has no static stiffness (no path of springs alone "
            "between its terminals): the body drifts"
        )

    found = []

    def walk(node):
        roles = {e.cls.ROLE for e in node.elements()}
        if "dissipative" not in roles and {"elastic", "inertial"} <= roles:
            found.append(node)
            return
        if isinstance(node, Combination):
            for part in node.parts:
                walk(part)

    walk(net.tree)
    if found:
        names = ", ".join(
            repr(f.text() if isinstance(f, Element) else f"({f.text()})") for f in found
        )
        return f"sub-network {names} has springs and inerters but no damper: an undamped resonance"
    return "no damping reaches some mode"


def network_quarter_car(network, **car) -> NetworkQuarterCar:
    """:class:`NetworkQuarterCar` from a network text and car keywords."""
    try:
        return NetworkQuarterCar(parse_network(network), **car)
    except TypeError as e:
        raise NetworkError(str(e)) from None


def network_h2(network, params: dict, **car) -> dict:
    """H2 norms of the quarter car with ``network`` (see :class:`NetworkQuarterCar`).

    Examples
    --------
    >>> n = network_h2("k | c", {"k": 90e3, "c": 5000}, tyre_damping=0.0)
    >>> round(n["suspension_deflection"] ** 2, 9) == round((370 + 25) / (2 * 5000), 9)
    True
    """
    return network_quarter_car(network, **car).h2(params)
