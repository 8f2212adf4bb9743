"""Optimal parameters of linear suspension networks and Pareto fronts between norms.

Quantities (:data:`QUANTITIES`), all from road velocity w to an output of the quarter
car of :mod:`inerterlab.suspension.network_linear`:

* H2 norms per unit white road velocity (two-sided density 1 (m/s)^2 per rad/s):
  ``body_acc`` (comfort) [m/s^2], ``tyre_deflection`` (road holding) [m],
  ``suspension_deflection`` (working space) [m], ``body_acc_wk`` (the body acceleration
  weighted by ISO 2631-1 Wk, the filter's eight states cascaded after the car,
  :func:`inerterlab.h2.h2_rational_filtered`) [m/s^2], ``tyre_load`` (the tyre spring's
  force k_t x tyre deflection) [N] and ``tyre_force`` (the whole tyre force, spring and
  damper, (k_t + c_t s) x tyre deflection) [N]. An ISO 8608 road of waviness 2 without
  band limits has a white road velocity of one-sided density (2 pi n0)^2 Gd(n0) V, so
  each norm times pi n0 sqrt(2 Gd(n0) V) is the RMS value on that road (docs/model.md
  §9; ``road_class``, ``speed``).
* ``peak:<quantity>``: the H-infinity norm, the largest gain |H(j w)| over frequency
  (a sine of road velocity amplitude V gives at most that gain times V), found on a
  logarithmic grid of 801 frequencies refined by golden-section search around the
  three highest local maxima, and compared with the limit at infinite frequency.
* ``weighted``: sqrt(sum_i w_i (Q_i / Q_i,ref)^2) over any of the above, Q_i,ref the
  values of the reference ``k | c`` whose damping minimises the body acceleration
  without tyre damping, c = k sqrt((m_s + m_u)/k_t); by default equal weights on the
  three first H2 norms, so the reference scores 1.

A norm is infinite when the car is not asymptotically stable, or when the road
velocity passes straight to the output (direct feed-through): the whole tyre force
with a tyre damper, the body acceleration with an inerter acting at high frequency
and a damped tyre (``k | c | b``). Each such case is named with its reason and the
finite alternative (:func:`infinite_reason`), and with a road the RMS over ISO 8608's
band 0.01-10 cycle/m is computed by quadrature instead (:func:`band_limited_rms`).

Elements. Any element of the registry may stand in the network: springs, dampers and
inerters are one parameter each; any other element (a fluid inerter, friction, an
adaptive flywheel, a device, a user's element) enters through its linearisation about
rest, and its parameters (``fluid.length``) are the variables (:class:`_Design`).
``max_inertance`` bounds every inerter of the network (its parameter, or the inertance
of another element's linearisation, as a constraint).

Search. Parameters are searched in logarithms within bounds (defaults: each
parameter's ``design`` range in the registry; fixed ones, e.g. the main spring, are
held). A scrambled Sobol sample of the box is
evaluated in one compiled batch, the best few distinct points are polished by L-BFGS-B
(unconstrained) or SLSQP (with limits on other quantities), and the best polished point
wins. For the H2 norms of the first three outputs, ``body_acc_wk`` and ``tyre_load``
the gradient is exact up to rounding and costs one compiled call: every polynomial
coefficient of the car is affine in each single network parameter, so the squared
norm is differentiated through the coefficients by the adjoint of the Lyapunov
equation (observability gramian; for ``body_acc_wk`` that of the cascade of the car
and the Wk filter, :func:`inerterlab.h2.h2_rational_filtered_gradient`), see
:func:`gradient`; the others use central differences in the logarithms (one batch).
A peak objective, whose optimum often has two equal peaks (a kink), is polished by
Nelder-Mead instead.

Simpler layouts. An optimum at a bound that stands for a simpler layout (a spring or
damper at the top of its design range: a rigid link; a spring, damper or inerter at
the bottom of its range or at a bound given as 0: absent) is reported as that layout
(:attr:`OptimizationResult.simplified`), optimised on its own and compared with
``k | c`` as such.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field

import numba as nb
import numpy as np

from .errors import PHYSICAL_RANGES, ParameterError, check_physical, check_seed, shorten
from .h2 import (
    h2_rational,
    h2_rational_filtered,
    h2_rational_filtered_gradient,
    h2_rational_gradient,
    stable_scaled,
)
from .networks import MAX_LAYOUTS, NetworkError, enumerate_networks, linearise, parse_network
from .suspension.network_linear import (
    _QUANTITY,
    MAXC,
    OUTPUTS,
    NetworkQuarterCar,
    _assemble,
    _car_polys,
    network_quarter_car,
)

__all__ = [
    "OBJECTIVES",
    "QUANTITIES",
    "TRANSFERS",
    "UNITS",
    "design_parameters",
    "OptimizationResult",
    "optimize_network",
    "check_settings",
    "count_layouts",
    "check_budget",
    "optimize_all",
    "pareto_front",
    "reference_norms",
    "gradient",
    "evaluate",
    "infinite_reason",
    "band_limited_rms",
    "road_scale",
    "unit_of",
    "transfer",
    "network_figure",
    "pareto_figure",
]

#: the transfers from road velocity whose norms the optimiser knows
TRANSFERS = (*OUTPUTS, "body_acc_wk", "tyre_load", "tyre_force")
#: unit of each transfer's output (its H2 norm is per unit white road velocity; its
#: peak gain per m/s of road velocity)
UNITS = {
    "body_acc": "m/s^2",
    "tyre_deflection": "m",
    "suspension_deflection": "m",
    "body_acc_wk": "m/s^2",
    "tyre_load": "N",
    "tyre_force": "N",
}
#: H2 norms, then the peak (H-infinity) gains, in the order of the compiled kernel
QUANTITIES = (*TRANSFERS, *(f"peak:{t}" for t in TRANSFERS))
OBJECTIVES = (*QUANTITIES, "weighted")
_NT = len(TRANSFERS)
_NQ = len(QUANTITIES)
#: row of each transfer among the car's polynomials (body_acc_wk: row 1 through Wk)
_ROW = np.array([1, 2, 3, 1, 4, 5], dtype=np.int64)
_BIG = 1e30

#: most starts of the local polish one optimisation takes
MAX_STARTS = 100


def unit_of(quantity: str) -> str:
    """Unit of a quantity: the output's for an H2 norm (per unit white road velocity),
    output per m/s of road velocity for a peak gain."""
    if quantity.startswith("peak:"):
        u = UNITS[quantity[5:]]
        return f"({u})/(m/s)" if "/" in u else f"{u}/(m/s)"
    return UNITS[quantity]


# ---------------------------------------------------------------------------------------
# compiled evaluation of every quantity


@nb.njit(cache=True)
def _transfer_polys(prog, theta, car, polys):
    """Rows of ``polys``: Delta, body_acc, tyre_deflection, suspension_deflection,
    tyre_load (k_t x tyre deflection), tyre_force ((k_t + c_t s) x tyre deflection);
    returns deg Delta."""
    num = np.zeros(MAXC)
    den = np.zeros(MAXC)
    ln, ld = _assemble(prog, theta, num, den)
    base = np.zeros((4, MAXC))
    n = _car_polys(num, ln, den, ld, car[0], car[1], car[2], car[3], base)
    polys[:, :] = 0.0
    for i in range(4):
        for q in range(MAXC):
            polys[i, q] = base[i, q]
    for q in range(MAXC):
        polys[4, q] = car[2] * base[2, q]
        polys[5, q] += car[2] * base[2, q]
        polys[5, q + 1] += car[3] * base[2, q]
    return n


@nb.njit(cache=True)
def _gain2(bt, at, n, sigma, w0, wsec, use_w):
    """|H|^2 at s = j w0 sigma of bt/at (scaled coefficients), times |W(j w)|^2."""
    s = 1j * sigma
    num = 0.0 + 0.0j
    den = 0.0 + 0.0j
    for i in range(n, -1, -1):
        num = num * s + bt[i]
        den = den * s + at[i]
    h = num / den
    if use_w:
        p = 1j * sigma * w0
        for k in range(wsec.shape[0]):
            h *= (wsec[k, 0] * p * p + wsec[k, 1] * p + wsec[k, 2]) / (
                wsec[k, 3] * p * p + wsec[k, 4] * p + wsec[k, 5]
            )
    return h.real * h.real + h.imag * h.imag


_GRID = 801


@nb.njit(cache=True)
def _peak2(polys, n, which, wsec, use_w):
    """Squared largest gain over frequency of row ``which`` over Delta (through the
    weighting ``wsec`` if ``use_w``); inf if the car is not asymptotically stable."""
    ok, w0, at, bt = stable_scaled(polys, n, which)
    if not ok:
        return np.inf
    ls = np.linspace(-4.0, 4.0, _GRID) * math.log(10.0)
    v = np.empty(_GRID)
    for i in range(_GRID):
        v[i] = _gain2(bt, at, n, math.exp(ls[i]), w0, wsec, use_w)
    # the limit at infinite frequency (the weighting rolls off: 0)
    best = 0.0 if use_w else bt[n] * bt[n]
    # refine the three highest local maxima by golden-section search in log frequency
    g = 0.5 * (math.sqrt(5.0) - 1.0)
    done = np.zeros(_GRID, np.bool_)
    for _ in range(3):
        top = -1
        for i in range(_GRID):
            if done[i]:
                continue
            left = v[i - 1] if i > 0 else -1.0
            right = v[i + 1] if i < _GRID - 1 else -1.0
            if v[i] >= left and v[i] >= right and (top < 0 or v[i] > v[top]):
                top = i
        if top < 0:
            break
        done[top] = True
        best = max(best, v[top])
        if top == 0 or top == _GRID - 1:
            continue
        a, b = ls[top - 1], ls[top + 1]
        c = b - g * (b - a)
        d = a + g * (b - a)
        fc = _gain2(bt, at, n, math.exp(c), w0, wsec, use_w)
        fd = _gain2(bt, at, n, math.exp(d), w0, wsec, use_w)
        for _it in range(70):
            if fc > fd:
                b, d, fd = d, c, fc
                c = b - g * (b - a)
                fc = _gain2(bt, at, n, math.exp(c), w0, wsec, use_w)
            else:
                a, c, fc = c, d, fd
                d = a + g * (b - a)
                fd = _gain2(bt, at, n, math.exp(d), w0, wsec, use_w)
        best = max(best, fc, fd)
    return best


@nb.njit(cache=True)
def _quantities(prog, theta, car, need, fA, fB, fC, wsec, out):
    """Squared values of :data:`QUANTITIES` where ``need``, NaN elsewhere."""
    polys = np.zeros((6, MAXC + 1))
    n = _transfer_polys(prog, theta, car, polys)
    out[:] = np.nan
    if need[0] or need[1] or need[2] or need[4] or need[5]:
        o = np.empty(5)
        h2_rational(polys, n, o)
        out[0], out[1], out[2], out[4], out[5] = o[0], o[1], o[2], o[3], o[4]
    if need[3]:
        out[3] = h2_rational_filtered(polys, n, 1, fA, fB, fC)
    for t in range(6):
        if need[6 + t]:
            out[6 + t] = _peak2(polys, n, _ROW[t], wsec, t == 3)
    for q in range(12):
        if need[q] and not (out[q] >= 0.0):
            out[q] = np.inf


@nb.njit(cache=True)
def _quantities_many(prog, thetas, car, need, fA, fB, fC, wsec, out):
    """Rows of ``thetas`` at once (one call from Python for a batch of candidates)."""
    o = np.empty(12)
    for r in range(thetas.shape[0]):
        if not np.all(np.isfinite(thetas[r])):
            for q in range(12):
                out[r, q] = np.inf if need[q] else np.nan
            continue
        _quantities(prog, thetas[r], car, need, fA, fB, fC, wsec, o)
        out[r, :] = o


_WK: tuple | None = None


def _wk():
    """(A, B, C, sections) of the Wk weighting, built once."""
    global _WK
    if _WK is None:
        from .h2 import wk_realisation
        from .iso2631 import WEIGHTINGS

        A, B, C = wk_realisation()
        sec = np.array([[*b, *a] for b, a in WEIGHTINGS["Wk"].sections()], dtype=float).reshape(
            -1, 6
        )
        _WK = (A, B, C, sec)
    return _WK


def _need(names) -> np.ndarray:
    need = np.zeros(_NQ, dtype=np.bool_)
    for n in names:
        need[QUANTITIES.index(n)] = True
    return need


def _squares(q: NetworkQuarterCar, thetas: np.ndarray, need: np.ndarray) -> np.ndarray:
    T = np.ascontiguousarray(np.atleast_2d(thetas), dtype=float)
    out = np.empty((T.shape[0], _NQ))
    A, B, C, sec = _wk()
    _quantities_many(q.program, T, q.car_vector, need, A, B, C, sec, out)
    return out


def evaluate(network, params: dict, quantities=QUANTITIES, **car) -> dict:
    """Values of ``quantities`` (names of :data:`QUANTITIES`) for the quarter car with
    the linear ``network`` and element values ``params``; ``math.inf`` where infinite
    (:func:`infinite_reason` says why)."""
    q = network_quarter_car(network, **car)
    quantities = list(quantities)
    for n in quantities:
        if n not in QUANTITIES:
            raise NetworkError(f"quantity {n!r}: expected one of {', '.join(QUANTITIES)}")
    sq = _squares(q, q.theta(params), _need(quantities))[0]
    return {n: math.sqrt(sq[QUANTITIES.index(n)]) for n in quantities}


def road_scale(road_class: str, speed: float) -> float:
    """RMS per unit H2 norm on an ISO 8608 road (waviness 2, no band limits):
    pi n0 sqrt(2 Gd(n0) V) [m/s per unit white road velocity] (docs/model.md §9)."""
    from .metrics import H2Norms

    return H2Norms(norms={"x": 1.0}).ride_indices(road_class, speed)["x"]


def infinite_reason(quantity: str, q: NetworkQuarterCar, params: dict, road=None) -> str:
    """One line: why ``quantity`` is infinite for these values, and the finite
    alternative (with ``road`` given, the RMS over the road's band is the one shown)."""
    base = quantity[5:] if quantity.startswith("peak:") else quantity
    stab = q.h2_reasons(params)
    if any("not asymptotically stable" in v for v in stab.values()):
        return (
            f"{quantity} is infinite: "
            + next(iter(stab.values())).removeprefix("infinite: ")
            + "; no road makes it finite"
        )
    if quantity.startswith("peak:"):
        return f"{quantity} is infinite"  # pragma: no cover - only an unstable car
    band = (
        "or the road band-limited to ISO 8608's 0.01-10 cycle/m (its RMS value over that "
        "band is shown)"
        if road is not None
        else "or the road band-limited to ISO 8608's 0.01-10 cycle/m (give a road, "
        "--road-class and --speed, for its RMS value over that band)"
    )
    if base == "tyre_force":
        return (
            "tyre_force is infinite under white road velocity: the tyre damper c_t passes "
            "the road velocity straight to the tyre force (direct feed-through); use "
            f"tyre_load (the tyre-spring force k_t x tyre deflection), {band}"
        )
    if base == "body_acc":
        return (
            "body_acc is infinite under white road velocity: an inerter acting at high "
            "frequency passes the tyre damper's force straight to the body (direct "
            "feed-through); use body_acc_wk (the Wk weighting rolls off above 100 Hz), " + band
        )
    return (
        f"{quantity} is infinite under white road velocity: the road velocity passes "
        f"straight to it (direct feed-through); use {band}"
    )


def band_limited_rms(
    quantity: str, q: NetworkQuarterCar, params: dict, road_class: str, speed: float
) -> float:
    """RMS of an H2 ``quantity`` on an ISO 8608 road band-limited to 0.01-10 cycle/m at
    ``speed``: sqrt(int |H(j 2 pi f)|^2 S_v df) over V n1 < f < V n2, S_v the one-sided
    road-velocity density (2 pi n0)^2 Gd(n0) V, by adaptive quadrature on 40
    logarithmic pieces."""
    import warnings

    from scipy.integrate import quad

    from .excitation import ISO8608_BAND

    scale = road_scale(road_class, speed)  # = sqrt(S_v / 2)
    sv = 2.0 * scale * scale
    h = transfer(quantity, q, params)
    edges = np.geomspace(ISO8608_BAND[0] * speed, ISO8608_BAND[1] * speed, 41)
    total = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for a, b in zip(edges[:-1], edges[1:], strict=True):
            total += quad(lambda f: abs(h(f)) ** 2, a, b, epsabs=0.0, epsrel=1e-10, limit=200)[0]
    return math.sqrt(total * sv)


def transfer(quantity: str, q: NetworkQuarterCar, params: dict):
    """H(j 2 pi f) of an H2 quantity (a name of :data:`TRANSFERS`) as a function of f [Hz]."""
    base = quantity[5:] if quantity.startswith("peak:") else quantity
    p = q.polynomials(params)
    den = p["den"]
    if base in ("body_acc", "body_acc_wk"):
        num = p["body_acc"]
    elif base == "suspension_deflection":
        num = p["suspension_deflection"]
    else:
        num = p["tyre_deflection"]
        if base == "tyre_load":
            num = q.tyre_stiffness * num
        elif base == "tyre_force":
            num = np.polymul([q.tyre_damping, q.tyre_stiffness], num)
    wk = None
    if base == "body_acc_wk":
        from .iso2631 import WEIGHTINGS

        wk = WEIGHTINGS["Wk"]

    def h(f):
        s = 2j * math.pi * np.asarray(f, dtype=float)
        out = np.polyval(num, s) / np.polyval(den, s)
        return out * wk.response(f) if wk is not None else out

    return h


# ---------------------------------------------------------------------------------------
# exact gradient: adjoint of the Lyapunov equation through the polynomial coefficients


@nb.njit(cache=True)
def _grad_batch(prog, theta, car, which, filtered, fA, fB, fC, grad):
    """Squared norm of output ``which`` (1..3; through the filter fA, fB, fC if
    ``filtered``) and its derivatives in log-parameters."""
    num = np.zeros(MAXC)
    den = np.zeros(MAXC)
    ln, ld = _assemble(prog, theta, num, den)
    base = np.zeros((4, MAXC))
    n = _car_polys(num, ln, den, ld, car[0], car[1], car[2], car[3], base)
    g = np.zeros((2, n + 1))
    if filtered:
        val = h2_rational_filtered_gradient(base, n, which, fA, fB, fC, g)
    else:
        sq = np.empty(3)
        h2_rational(base, n, sq)
        val = sq[which - 1]
        if np.isfinite(val):
            h2_rational_gradient(base, n, which, g)
    if not np.isfinite(val):
        grad[:] = np.nan
        return val
    pert = np.zeros((4, MAXC))
    th = theta.copy()
    for k in range(theta.shape[0]):
        # the coefficients are affine in theta_k: doubling it adds theta_k * d/dtheta_k,
        # which is the derivative in log(theta_k)
        th[k] = 2.0 * theta[k]
        ln2, ld2 = _assemble(prog, th, num, den)
        n2 = _car_polys(num, ln2, den, ld2, car[0], car[1], car[2], car[3], pert)
        th[k] = theta[k]
        if n2 != n:
            grad[k] = np.nan
            continue
        acc = 0.0
        for i in range(n + 1):
            acc += g[0, i] * (pert[0, i] - base[0, i])
            acc += g[1, i] * (pert[which, i] - base[which, i])
        grad[k] = acc
    return val


#: the quantities whose gradient is exact (adjoint), by index in :data:`QUANTITIES`:
#: the three H2 norms of :data:`OUTPUTS`, body_acc_wk and tyre_load
_EXACT = (0, 1, 2, 3, 4)


def gradient(car: NetworkQuarterCar, params: dict, output: str) -> tuple[float, dict]:
    """Squared H2 norm of ``output`` (a name of :data:`OUTPUTS`, ``body_acc_wk`` or
    ``tyre_load``) and its exact derivative in the log of each parameter."""
    index = QUANTITIES.index(output) if output in QUANTITIES else -1
    if index not in _EXACT:
        raise NetworkError(
            f"gradient of {output!r}: expected one of {', '.join(QUANTITIES[i] for i in _EXACT)}"
        )
    th = car.theta(params)
    g = np.empty(len(th))
    val = _quantity_gradient(car, th, index, g)
    return float(val), dict(zip(car.network.names, g.tolist(), strict=True))


#: relative step of the central differences in the logarithms of the leaves
_FD_STEP = 2e-5


def _quantity_gradient(q: NetworkQuarterCar, th: np.ndarray, index: int, gfull: np.ndarray):
    """Squared value of quantity ``index`` and its derivatives in the leaves' logs:
    exact (adjoint) for :data:`_EXACT`, central differences in one compiled batch
    otherwise."""
    if index in _EXACT:
        which = {0: 1, 1: 2, 2: 3, 3: 1, 4: 2}[index]
        A, B, C, _ = _wk()
        v = _grad_batch(q.program, th, q.car_vector, which, index == 3, A, B, C, gfull)
        if index == 4:
            f = q.tyre_stiffness**2
            v *= f
            gfull *= f
        return v
    L = len(th)
    T = np.repeat(th[None, :], 2 * L + 1, axis=0)
    for k in range(L):
        T[1 + 2 * k, k] *= math.exp(_FD_STEP)
        T[2 + 2 * k, k] *= math.exp(-_FD_STEP)
    sq = _squares(q, T, _need([QUANTITIES[index]]))[:, index]
    gfull[:] = (sq[1::2] - sq[2::2]) / (2 * _FD_STEP)
    return sq[0]


# ---------------------------------------------------------------------------------------
# problem set-up


def _parse_assignments(items, what: str) -> dict:
    """``["k=50000", ...]`` or a dict -> {name: value}."""
    if items is None:
        return {}
    if isinstance(items, dict):
        return dict(items)
    out = {}
    for it in items:
        for part in str(it).split(","):
            if not part.strip():
                continue
            if "=" not in part:
                raise NetworkError(f"{what} {part!r}: expected name=value")
            name, val = (x.strip() for x in part.split("=", 1))
            if name in out:
                raise NetworkError(
                    f"{what} {shorten(part.strip())!r}: {shorten(name)!r} is given twice; "
                    "give each name once"
                )
            out[name] = val
    return out


def design_parameters(network) -> dict:
    """The numeric parameters of every element of ``network`` that the optimiser can
    vary, from the element registry: {name: Param}. A spring, damper or inerter is one
    number under its own name (``k``, ``c2``); any other element's parameters are
    ``<element>.<parameter>`` (``fluid.length``). Choices (a flywheel preset, a force
    law) are not design parameters."""
    out = {}
    for e in parse_network(network).tree.elements():
        cls = e.cls
        if cls.ADMITTANCE is not None:
            out[e.name] = cls.PARAMETERS[0]
            continue
        for p in cls.PARAMETERS:
            if p.choices is None:
                out[f"{e.name}.{p.name}"] = p
    return out


def _design_name(name: str, params: dict, net) -> str:
    """``name`` as a key of :func:`design_parameters`; an element name alone stands for
    its first parameter (as in the core systems' parameters)."""
    if name in params:
        return name
    if "." not in name and name in net.names:
        first = f"{name}.{parse_network(name).tree.cls.PARAMETERS[0].name}"
        if first in params:
            return first
    known = ", ".join(f"{n} [{p.unit}]" if p.unit else n for n, p in params.items())
    raise NetworkError(f"{name!r} is no parameter of the elements of {net.text!r} ({known})")


class _Design:
    """The optimiser's variables and how they set the springs, dampers and inerters of
    the network written about rest (:func:`inerterlab.networks.linearise`).

    A spring, damper or inerter of the network is one leaf of the linear network and
    its own variable. Any other element contributes the leaves of its linearisation
    about rest, recomputed from its parameters for every candidate (so any law the
    element declares is followed exactly); the derivatives of the leaves' logarithms in
    the variables' logarithms come from central differences."""

    def __init__(self, net, fixed: dict, bounds: dict):
        self.net = net
        params = design_parameters(net)
        fixed = {_design_name(k, params, net): v for k, v in fixed.items()}
        bounds = {_design_name(k, params, net): v for k, v in bounds.items()}
        self.fixed = fixed
        self.free, lo, hi = [], [], []
        #: per free parameter, whether its low / high bound stands for "absent" or
        #: "rigid" (the registry's design range, or a low bound given as 0) rather than
        #: a limit the user set
        self.standin = {}
        for name, p in params.items():
            if name in fixed:
                continue
            ends = (True, True)
            if name in bounds:
                bd = bounds[name]
                if isinstance(bd, str):
                    try:
                        a, b = (float(x) for x in bd.split(":"))
                    except ValueError:
                        raise NetworkError(
                            f"bound {name}={bd!r}: expected low:high in {p.unit}"
                        ) from None
                else:
                    a, b = (float(x) for x in bd)
                if not (0 <= a < b < math.inf):
                    raise NetworkError(f"bound {name}={bd!r}: expected 0 <= low < high")
                q = _QUANTITY.get(net.kinds[net.names.index(name)]) if name in net.names else None
                ends = (a == 0.0, False)
                if a == 0.0:
                    # log search: 0 stands for "negligible", within the physical range
                    a = b * 1e-6 if q is None else max(b * 1e-6, PHYSICAL_RANGES[q][0])
                if q is not None:
                    for x in (a, b):
                        check_physical(f"bound {name}", x, q)
            elif p.design is not None:
                a, b = p.design
            else:
                continue  # held at the element's default (or required: checked below)
            self.free.append(name)
            self.standin[name] = ends
            lo.append(math.log(a))
            hi.append(math.log(b))
        self.lo, self.hi = np.array(lo), np.array(hi)
        self.simple = all(e.linear for e in net.tree.elements())
        if self.simple:
            self.lin = net
            self.free_idx = np.array([net.names.index(n) for n in self.free], dtype=np.int64)
            self.theta0 = np.array([fixed.get(n, 1.0) for n in net.names])
            return
        # the other elements: their parameters by element, and the linear network's
        # structure at the middle of the box
        self.groups = {}
        for e in net.tree.elements():
            if not e.linear:
                self.groups[e.name] = [n for n in params if n.split(".", 1)[0] == e.name]
        self.lin, _ = self._linear(self.values((self.lo + self.hi) / 2))
        self.index = {n: i for i, n in enumerate(self.lin.names)}

    def values(self, u) -> dict:
        """{design name: value} at the log-variables ``u`` (fixed ones included)."""
        out = dict(self.fixed)
        out.update(zip(self.free, np.exp(u).tolist(), strict=True))
        return out

    def _linear(self, values: dict):
        try:
            return linearise(self.net, values)
        except ParameterError as e:
            hint = (
                "; hold it with fixed (--fix name=value) or search it with bounds "
                "(--bound name=low:high)"
                if e.value is None  # a required parameter neither fixed nor bounded
                else ""
            )
            raise NetworkError(f"network {self.net.text!r}: {e}{hint}") from None

    def _leaves(self, u) -> np.ndarray | None:
        """Leaf values of the linear network at ``u``; None if its structure differs."""
        vals = self.values(u)
        th = np.empty(len(self.lin.names))
        seen = 0
        for e in self.net.tree.elements():
            if e.linear:
                th[self.index[e.name]] = vals[e.name]
                seen += 1
                continue
            given = {n.split(".", 1)[1]: vals[n] for n in self.groups[e.name] if n in vals}
            try:
                rest = e.cls.from_value(e.name, given).rest_network()
            except ParameterError:
                return None
            for k, v in ({} if rest is None else rest[1]).items():
                i = self.index.get(f"{k}_{e.name}")
                if i is None:
                    return None
                th[i] = v
                seen += 1
        return th if seen == len(th) else None

    def thetas(self, U) -> np.ndarray:
        U = np.atleast_2d(U)
        if self.simple:
            T = np.repeat(self.theta0[None, :], U.shape[0], axis=0)
            T[:, self.free_idx] = np.exp(U)
            return T
        T = np.empty((U.shape[0], len(self.lin.names)))
        for r, u in enumerate(U):
            th = self._leaves(u)
            T[r] = np.nan if th is None else th
        return T

    def chain(self, u, g_leaf: np.ndarray) -> np.ndarray:
        """Derivatives in the free log-variables from those in the leaves' logarithms."""
        if self.simple:
            return g_leaf[self.free_idx]
        out = np.zeros(len(self.free))
        h = 1e-5
        for j in range(len(self.free)):
            up, dn = u.copy(), u.copy()
            up[j] += h
            dn[j] -= h
            a, b = self._leaves(up), self._leaves(dn)
            if a is None or b is None:
                return np.full(len(self.free), np.nan)
            out[j] = g_leaf @ ((np.log(a) - np.log(b)) / (2 * h))
        return out

    def units(self) -> dict:
        params = design_parameters(self.net)
        return {n: params[n].unit for n in [*self.fixed, *self.free]}


def reference_norms(quantities=None, **car) -> dict:
    """Norms of ``k | c`` with c = k sqrt((m_s + m_u)/k_t), k from ``car['k']`` (50 kN/m):
    the three H2 norms of :data:`OUTPUTS`, or the ``quantities`` named."""
    k = float(car.pop("k", 50e3))
    q = network_quarter_car("k | c", **car)
    c = k * math.sqrt((q.sprung_mass + q.unsprung_mass) / q.tyre_stiffness)
    if quantities is None:
        return q.h2({"k": k, "c": c})
    return evaluate("k | c", {"k": k, "c": c}, quantities, **car)


@dataclass
class OptimizationResult:
    """Best parameters found for one network and objective.

    ``norms``: the H2 norms of :data:`TRANSFERS` per unit white road velocity;
    ``peaks``: the peak gain of every transfer; ``units``: of each
    parameter; ``unit``: of the objective; ``infinite``: why each infinite quantity is
    (one line each, with the finite alternative); ``rms``/``road``: RMS values on the
    ISO 8608 road given (white road velocity; over the band 0.01-10 cycle/m for the
    quantities infinite without it); ``simplified``: the simpler layout the optimum
    stands for, if it sits on such a bound."""

    network: str
    objective_name: str
    objective: float
    parameters: dict
    norms: dict
    converged: bool
    at_bound: list
    improvement_vs: dict = field(default_factory=dict)
    constraints: dict = field(default_factory=dict)
    starts_agree: bool = True
    evaluations: int = 0
    reason: str = ""
    #: unit of each parameter, from the element registry
    units: dict = field(default_factory=dict)
    unit: str = ""
    peaks: dict = field(default_factory=dict)
    infinite: dict = field(default_factory=dict)
    road: dict = field(default_factory=dict)
    rms: dict = field(default_factory=dict)
    simplified: dict = field(default_factory=dict)
    max_inertance: float | None = None

    def to_dict(self) -> dict:
        def fin(d):
            return {k: (v if v is not None and math.isfinite(v) else None) for k, v in d.items()}

        out = {
            "network": self.network,
            "objective_name": self.objective_name,
            "objective": self.objective if math.isfinite(self.objective) else None,
            "unit": self.unit,
            "parameters": self.parameters,
            "units": self.units,
            "norms": fin(self.norms),
            "improvement_vs": self.improvement_vs,
            "converged": self.converged,
            "at_bound": self.at_bound,
        }
        if self.peaks:
            out["peaks"] = fin(self.peaks)
        if self.infinite:
            out["infinite"] = self.infinite
        if self.road:
            out["road"] = self.road
            out["rms"] = fin(self.rms)
        if self.simplified:
            out["simplified"] = self.simplified
        if self.max_inertance is not None:
            out["max_inertance"] = self.max_inertance
        if self.constraints:
            out["constraints"] = self.constraints
        if self.reason:
            out["reason"] = self.reason
        return out


def _quantity_name(name: str, what: str) -> str:
    if name not in QUANTITIES:
        raise NetworkError(f"{what} {name!r}: expected one of {', '.join(QUANTITIES)}")
    return name


class _Problem:
    def __init__(
        self, net, objective, fixed, bounds, constraints, weights, car, max_inertance=None
    ):
        if objective not in OBJECTIVES:
            raise NetworkError(f"objective {objective!r}: expected one of {', '.join(OBJECTIVES)}")
        self.design = _Design(parse_network(net), fixed, bounds)
        self.q = network_quarter_car(self.design.lin, **car)
        self.net = self.design.net
        self.objective = objective
        self.fixed = {k: float(v) for k, v in self.design.fixed.items()}
        if self.fixed and self.design.simple:
            # validates the fixed values (finite, > 0) with the network's own messages
            probe = {n: self.fixed.get(n, 1.0) for n in self.net.names}
            self.net.parameter_vector(probe)
        self.free, self.lo, self.hi = self.design.free, self.design.lo, self.design.hi
        if not self.free:
            raise NetworkError(f"network {self.net.text!r}: every parameter is fixed")
        self.max_inertance = None
        self.bmask = np.array([k == "b" for k in self.q.network.kinds], dtype=bool)
        if max_inertance is not None:
            self._cap_inertance(float(max_inertance))
        self.constraints = {}
        for k, v in constraints.items():
            _quantity_name(k, "constraint on")
            v = float(v)
            if not v > 0:
                raise NetworkError(f"constraint {k} <= {v}: the limit must be > 0")
            self.constraints[k] = v
        ref = None
        if objective == "weighted":
            w = {k: 1.0 for k in OUTPUTS} if not weights else {}
            for k, v in (weights or {}).items():
                _quantity_name(k, "weight on")
                if not float(v) >= 0:
                    raise NetworkError(f"weight {k}={v}: expected w >= 0")
                w[k] = float(v)
            tot = sum(w.values())
            if not tot > 0:
                raise NetworkError("weights: at least one must be > 0")
            ref = reference_norms(list(w), k=self.fixed.get("k", 50e3), **car)
            for k in w:
                if w[k] > 0 and not math.isfinite(ref[k]):
                    raise NetworkError(
                        f"weight on {k}: its value for the reference k | c is infinite, so "
                        f"it cannot be scaled ({infinite_reason(k, network_quarter_car('k | c', **car), {'k': 5e4, 'c': 3e3})})"
                    )
            self.wvec = np.zeros(_NQ)
            for k, v in w.items():
                self.wvec[QUANTITIES.index(k)] = v / tot / ref[k] ** 2
        else:
            self.wvec = np.array([1.0 if k == objective else 0.0 for k in QUANTITIES])
        self.ref = ref
        self.car = self.q.car_vector
        self.prog = self.q.program
        self.neval = 0
        self.cidx = [QUANTITIES.index(k) for k in self.constraints]
        # v * v: a limit beyond 1e154 squares to inf, which is no constraint (not an error)
        self.clim = np.array([self.constraints[k] * self.constraints[k] for k in self.constraints])
        self.need = (self.wvec > 0) | _need(self.constraints)
        self.peak = bool(np.any(self.wvec[_NT:] > 0))

    def _cap_inertance(self, cap: float) -> None:
        """Every inerter at most ``cap`` [kg]: the upper bound of an inerter's own
        parameter, a constraint on the inertance of another element's linearisation."""
        check_physical("max_inertance", cap, "inertance")
        self.max_inertance = cap
        d = self.design
        for name, x in self.fixed.items():
            if name in self.net.names and self.net.kinds[self.net.names.index(name)] == "b":
                if x > cap * (1 + 1e-12):
                    raise NetworkError(
                        f"fixed inerter {name}={x:g} kg exceeds max_inertance={cap:g} kg"
                    )
        for i, name in enumerate(self.free):
            if name in self.net.names and self.net.kinds[self.net.names.index(name)] == "b":
                if math.log(cap) <= d.lo[i]:
                    raise NetworkError(
                        f"max_inertance={cap:g} kg is below the lower bound of {name} "
                        f"({math.exp(d.lo[i]):g} kg)"
                    )
                if math.log(cap) < d.hi[i]:
                    d.hi[i] = math.log(cap)
                    d.standin[name] = (d.standin[name][0], False)
        # inertance from other elements' linearisations: a constraint on their leaves
        self.leaf_cap = None
        if not d.simple:
            own = {n for n in self.net.names if self.net.kinds[self.net.names.index(n)] == "b"}
            mask = np.array(
                [
                    k == "b" and n not in own
                    for n, k in zip(self.q.network.names, self.q.network.kinds, strict=True)
                ]
            )
            if mask.any():
                self.leaf_cap = (mask, cap)

    def thetas(self, U):
        return self.design.thetas(U)

    def squares(self, U):
        T = self.thetas(U)
        out = _squares(self.q, T, self.need)
        self.neval += T.shape[0]
        return out

    def parameters(self, u) -> dict:
        """The design parameters at ``u`` (fixed and free) by name."""
        return self.design.values(u)

    def linear_parameters(self, u) -> dict:
        """The springs, dampers and inerters of the linear network at ``u``."""
        return dict(zip(self.q.network.names, self.thetas(u)[0].tolist(), strict=True))

    def scalar(self, sq):
        with np.errstate(invalid="ignore"):
            used = self.wvec > 0
            v = sq[:, used] @ self.wvec[used]
        return np.where(np.isfinite(v), v, _BIG)

    def _leaf_excess(self, T) -> np.ndarray:
        """Relative excess of the linearised inertances over the cap (0 if none)."""
        if getattr(self, "leaf_cap", None) is None:
            return np.zeros(T.shape[0])
        mask, cap = self.leaf_cap
        with np.errstate(invalid="ignore"):
            r = np.max(T[:, mask], axis=1) / cap - 1.0
        return np.where(np.isfinite(r), np.maximum(r, 0.0), 1e6)

    def violation(self, sq, U=None):
        extra = np.zeros(sq.shape[0]) if U is None else self._leaf_excess(self.thetas(U))
        if not self.cidx:
            return extra
        r = sq[:, self.cidx] / self.clim - 1.0
        r = np.where(np.isfinite(r), r, 1e6)
        return np.maximum(r, 0.0).sum(axis=1) + extra

    def f_and_g(self, u):
        """Scalar objective and its gradient in the free log-parameters."""
        th = self.thetas(u)[0]
        total, grad = 0.0, np.zeros(len(self.free))
        if not np.all(np.isfinite(th)):
            return _BIG, grad
        gfull = np.empty(len(th))
        for o in np.flatnonzero(self.wvec > 0):
            w = self.wvec[o]
            v = _quantity_gradient(self.q, th, int(o), gfull)
            self.neval += 1 if o in _EXACT else 1 + 2 * len(th)
            g = self.design.chain(u, gfull)
            if not np.isfinite(v) or not np.all(np.isfinite(g)):
                return _BIG, np.zeros(len(self.free))
            total += w * v
            grad += w * g
        return total, grad

    def f(self, u):
        """Scalar objective with the constraints as a penalty (derivative-free polish)."""
        u = np.atleast_2d(u)
        sq = self.squares(u)
        v = self.scalar(sq)
        viol = self.violation(sq, u)
        return float(
            np.where(viol > 0, np.minimum(v * (1 + 1e3 * viol) + 1e3 * v * viol, _BIG), v)[0]
        )

    def cons_and_jac(self, u):
        th = self.thetas(u)[0]
        vals, jacs = [], []
        gfull = np.empty(len(th))
        for o, lim in zip(self.cidx, self.clim, strict=True):
            v = _quantity_gradient(self.q, th, o, gfull) if np.all(np.isfinite(th)) else np.nan
            if not np.isfinite(v):
                vals.append(-1e6)
                jacs.append(np.zeros(len(self.free)))
                continue
            vals.append(1.0 - v / lim)
            jacs.append(-self.design.chain(u, gfull) / lim)
        if getattr(self, "leaf_cap", None) is not None:
            mask, cap = self.leaf_cap
            h = 1e-6
            base = 1.0 - float(np.max(th[mask])) / cap
            jac = np.zeros(len(self.free))
            for j in range(len(self.free)):
                up = u.copy()
                up[j] += h
                thu = self.thetas(up)[0]
                jac[j] = ((1.0 - float(np.max(thu[mask])) / cap) - base) / h
            vals.append(base)
            jacs.append(jac)
        return np.array(vals), np.array(jacs)

    @property
    def constrained(self) -> bool:
        return bool(self.cidx) or getattr(self, "leaf_cap", None) is not None

    def value(self, sq_row) -> float:
        v = float(self.scalar(sq_row[None, :])[0])
        return math.sqrt(v) if v < _BIG else math.inf


def _polish(pb: _Problem, u0: np.ndarray, maxiter: int | None = None):
    from scipy.optimize import minimize

    bnds = list(zip(pb.lo, pb.hi, strict=True))
    if pb.peak:
        # the largest gain has a kink where two peaks are equal: derivative-free
        f0 = pb.f(u0)
        return minimize(
            pb.f,
            u0,
            method="Nelder-Mead",
            bounds=bnds,
            options={
                "maxiter": maxiter or 4000,
                "maxfev": maxiter or 8000,
                "xatol": 1e-9,
                "fatol": 1e-13 * f0 if 0 < f0 < _BIG else 0.0,
                "adaptive": len(pb.free) > 2,
            },
        )
    f0 = pb.f_and_g(u0)[0]
    fs = 1.0 / f0 if 0 < f0 < _BIG else 1.0  # SLSQP wants an objective of order one

    def fg(u):
        f, g = pb.f_and_g(u)
        return f * fs, g * fs

    if pb.constrained:
        cons = [
            {
                "type": "ineq",
                "fun": lambda u: pb.cons_and_jac(u)[0],
                "jac": lambda u: pb.cons_and_jac(u)[1],
            }
        ]
        r = minimize(
            fg,
            u0,
            jac=True,
            method="SLSQP",
            bounds=bnds,
            constraints=cons,
            options={"maxiter": maxiter or 300, "ftol": 1e-14},
        )
    else:
        r = minimize(
            lambda u: pb.f_and_g(u),
            u0,
            jac=True,
            method="L-BFGS-B",
            bounds=bnds,
            options={"maxiter": maxiter or 500, "ftol": 1e-15, "gtol": 1e-10},
        )
    return r


def _evolve(pb: _Problem, seed: int) -> np.ndarray:
    """Differential evolution over the log box, one compiled batch per generation."""
    from scipy.optimize import differential_evolution

    def fvec(U):
        sq = pb.squares(U.T)
        v = pb.scalar(sq)
        viol = pb.violation(sq, U.T)
        return np.where(viol > 0, np.minimum(v * (1 + 1e3 * viol) + 1e3 * v * viol, _BIG), v)

    d = len(pb.free)
    r = differential_evolution(
        fvec,
        list(zip(pb.lo, pb.hi, strict=True)),
        popsize=max(15, 8 * d),
        maxiter=200,
        tol=1e-10,
        seed=seed,
        init="sobol",
        polish=False,
        vectorized=True,
        updating="deferred",
    )
    return np.asarray(r.x)


def _kkt(pb: _Problem, u: np.ndarray, val: float) -> bool:
    """First-order optimality without constraints: projected log-gradient ~ 0.

    L-BFGS-B stops with an abnormal line search when the objective can no longer
    decrease in double precision; that point is still an optimum if the gradient,
    projected on the bounds, vanishes relative to the objective. (A peak objective's
    Nelder-Mead polish has no gradient to test: its own convergence stands.)
    """
    if pb.constrained or pb.peak or not math.isfinite(val) or val >= _BIG:
        return False
    _, g = pb.f_and_g(u)
    tol = 1e-4 * (pb.hi - pb.lo)
    g = np.where((u - pb.lo <= tol) & (g > 0), 0.0, g)
    g = np.where((pb.hi - u <= tol) & (g < 0), 0.0, g)
    # exact gradients meet 1e-5; central differences carry about 1e-6 of rounding
    exact = all(i in _EXACT for i in np.flatnonzero(pb.wvec > 0))
    return bool(np.max(np.abs(g)) <= (1e-5 if exact else 1e-4) * val)


_BASELINES: dict = {}


def check_settings(
    objective, *, weights=None, starts=8, samples=256, seed=0, max_inertance=None, road=None
) -> None:
    """Raise if the settings of :func:`optimize_network` (other than the network and
    its parameters) are invalid: the objective, unused weights, starts, samples, seed,
    the inertance limit and the road (class, speed)."""
    if objective not in OBJECTIVES:
        raise NetworkError(f"objective {objective!r}: expected one of {', '.join(OBJECTIVES)}")
    if isinstance(starts, bool) or not isinstance(starts, numbers.Integral):
        raise ParameterError("starts", starts, f"an integer in [1, {MAX_STARTS}]")
    if not 1 <= starts <= MAX_STARTS:
        raise ParameterError("starts", starts, f"an integer in [1, {MAX_STARTS}]")
    if isinstance(samples, bool) or not isinstance(samples, numbers.Integral):
        raise ParameterError("samples", samples, "an integer in [16, 65536]")
    if not 16 <= samples <= 65536:
        raise ParameterError("samples", samples, "an integer in [16, 65536]")
    check_seed("seed", seed)
    if weights and objective != "weighted":
        raise ParameterError(
            "weight",
            weights,
            "no weights unless the objective is 'weighted' (they would be unused)",
        )
    if max_inertance is not None:
        check_physical("max_inertance", max_inertance, "inertance")
        if not max_inertance > 0:
            raise ParameterError("max_inertance", max_inertance, "an inertance > 0 kg")
    if road is not None:
        _check_road(road)


def _check_road(road) -> tuple[str, float]:
    from .errors import check_choice, check_positive
    from .excitation import ISO8608_CLASSES

    try:
        cls, speed = road
    except (TypeError, ValueError):
        raise ParameterError("road", road, "(ISO 8608 class A-H, speed in m/s)") from None
    check_choice("road class", cls, tuple(ISO8608_CLASSES))
    return cls, check_positive("speed", speed, "m/s")


def _simplify(node, repl):
    """``node`` with elements replaced: repl name -> "open" or "short"; returns a node,
    "open" or "short"."""
    from .networks import Element, _combine

    if isinstance(node, Element):
        return repl.get(node.name, node)
    parts = [_simplify(p, repl) for p in node.parts]
    if node.op == "|":
        if any(p == "short" for p in parts):
            return "short"
        parts = [p for p in parts if p != "open"]
        if not parts:
            return "open"
    else:
        if any(p == "open" for p in parts):
            return "open"
        parts = [p for p in parts if p != "short"]
        if not parts:
            return "short"
    return _combine(node.op, parts)


def _standins(pb: _Problem, u: np.ndarray, tol: np.ndarray) -> dict:
    """name -> ("open" | "short", why) for the free springs, dampers and inerters whose
    optimum sits on a bound that stands for a simpler layout."""
    out = {}
    for i, name in enumerate(pb.free):
        if name not in pb.net.names:
            continue
        kind = pb.net.kinds[pb.net.names.index(name)]
        low_ok, high_ok = pb.design.standin.get(name, (False, False))
        if low_ok and u[i] - pb.lo[i] <= tol[i]:
            out[name] = ("open", f"{name} at its lower bound {math.exp(pb.lo[i]):.3g}: absent")
        elif high_ok and pb.hi[i] - u[i] <= tol[i] and kind in ("k", "c"):
            out[name] = (
                "short",
                f"{name} at its upper bound {math.exp(pb.hi[i]):.3g}: a rigid link",
            )
    return out


def optimize_network(
    network,
    objective: str = "body_acc",
    *,
    fixed=None,
    bounds=None,
    constraints=None,
    weights=None,
    starts: int = 8,
    samples: int = 256,
    seed: int = 0,
    compare: bool = True,
    evolve: bool = True,
    max_inertance: float | None = None,
    road: tuple | None = None,
    simplify: bool = True,
    **car,
) -> OptimizationResult:
    """Minimise one objective over the free parameters of ``network``.

    Parameters
    ----------
    network : str or Network
    objective : a name of :data:`OBJECTIVES`: an H2 norm (``body_acc``,
        ``tyre_deflection``, ``suspension_deflection``, ``body_acc_wk``, ``tyre_load``,
        ``tyre_force``), a peak gain ``peak:<that>``, or ``weighted``.
    fixed : dict or list of "name=value", held parameters (e.g. ``{"k": 50e3}``).
    bounds : dict name -> (low, high) or "low:high"; a low of 0 means 1e-6 x high.
        Defaults: each parameter's ``design`` range in the element registry. Names are
        those of :func:`design_parameters`: ``k``, ``c2`` for springs, dampers and
        inerters, ``<element>.<parameter>`` for any other element (its linearisation
        about rest is what the norms see), e.g. ``fluid.length``.
    constraints : dict quantity -> upper limit of its value (a name of
        :data:`QUANTITIES`, e.g. minimise body_acc_wk with limits on the H2 norms of
        tyre and suspension deflection, or on ``peak:suspension_deflection``).
    weights : dict quantity -> weight of the ``weighted`` objective (default equal on
        the three first H2 norms).
    starts, samples, seed : starts (the differential evolution's best point and the
        best distinct Sobol points; each gets a short polish, the two best a full one),
        Sobol sample size, sample seed.
    evolve : with two or more free parameters, run a differential evolution over the
        log box first (one compiled batch per generation) and polish its best point too.
    compare : also optimise ``k | c`` under the same settings and report the
        improvement in percent (positive: this network is better).
    max_inertance : upper limit [kg] of every inerter of the network.
    road : (ISO 8608 class, speed [m/s]): also the RMS values on that road.
    simplify : report an optimum on a bound that stands for a simpler layout as that
        layout (optimised on its own, see the module documentation).
    car : sprung_mass, unsprung_mass, tyre_stiffness, tyre_damping.
    """
    from scipy.stats import qmc

    check_settings(
        objective,
        weights=weights,
        starts=starts,
        samples=samples,
        seed=seed,
        max_inertance=max_inertance,
        road=road,
    )
    fixed = _parse_assignments(fixed, "fixed parameter")
    bounds = _parse_assignments(bounds, "bound")
    constraints = _parse_assignments(constraints, "constraint")
    weights = _parse_assignments(weights, "weight")
    for k, v in list(fixed.items()):
        try:
            fixed[k] = float(v)
        except ValueError:
            raise NetworkError(f"fixed parameter {k}={v!r}: not a number") from None
    pb = _Problem(network, objective, fixed, bounds, constraints, weights, car, max_inertance)
    d = len(pb.free)
    m = max(int(samples), 16 * d)
    sob = qmc.Sobol(d, scramble=True, seed=seed)
    U = pb.lo + (pb.hi - pb.lo) * sob.random(2 ** int(math.ceil(math.log2(m))))
    sq = pb.squares(U)
    score = pb.scalar(sq)
    viol = pb.violation(sq, U)
    order = np.lexsort((score, viol))  # feasible points first, then by objective
    score = np.where(viol > 0, np.minimum(score * (1.0 + viol), _BIG / 2), score)
    picks: list[np.ndarray] = []
    span = pb.hi - pb.lo
    for i in order:
        if score[i] >= _BIG:
            break
        if all(np.max(np.abs(U[i] - p) / span) > 0.05 for p in picks):
            picks.append(U[i])
        if len(picks) >= starts:
            break
    if picks and d > 1 and evolve:
        picks.insert(0, _evolve(pb, seed))
        picks = picks[: max(starts, 1)]
    if len(picks) > 2:
        # short polish of every start, full polish of the two best (distinct) ends
        ends = []
        for u0 in picks:
            r = _polish(pb, u0, maxiter=15 if not pb.peak else 60 * d)
            u = np.clip(r.x, pb.lo, pb.hi)
            s = pb.squares(u)
            ends.append((float(pb.scalar(s)[0] * (1.0 + 1e3 * pb.violation(s, u[None])[0])), u))
        ends.sort(key=lambda e: e[0])
        picks = [ends[0][1]]
        for _, u in ends[1:]:
            if np.max(np.abs(u - picks[0]) / span) > 1e-3:
                picks.append(u)
                break
    best = None
    finals = []
    for u0 in picks:
        r = _polish(pb, u0)
        if pb.peak:  # a restart from the end: Nelder-Mead's simplex may have collapsed
            r = _polish(pb, np.clip(r.x, pb.lo, pb.hi))
        u = np.clip(r.x, pb.lo, pb.hi)
        s = pb.squares(u)
        val = float(pb.scalar(s)[0])
        feas = pb.violation(s, u[None])[0] <= 1e-6
        finals.append((val, feas))
        if feas and (best is None or val < best[0]):
            best = (val, u, s[0], bool(r.success) or _kkt(pb, u, val))
    unit = "-" if objective == "weighted" else unit_of(objective)
    if best is None:
        reason = (
            "no finite objective anywhere in the bounds (see the norms' reasons: "
            "unstable car or direct feed-through)"
            if not picks
            else "no start met the constraints"
        )
        u = (pb.lo + pb.hi) / 2
        params, lin = pb.parameters(u), pb.linear_parameters(u)
        why = ""
        if not picks and objective != "weighted":
            why = "; " + infinite_reason(objective, pb.q, lin)
        res = OptimizationResult(
            network=pb.net.text,
            objective_name=objective,
            objective=math.inf,
            parameters=params,
            units=pb.design.units(),
            unit=unit,
            norms=pb.q.h2(lin),
            converged=False,
            at_bound=[],
            evaluations=pb.neval,
            reason=reason + why,
            max_inertance=pb.max_inertance,
        )
        _describe(res, pb, lin, road)
        stand = {}
    else:
        val, u, srow, ok = best
        params, lin = pb.parameters(u), pb.linear_parameters(u)
        tol = 1e-4 * span
        at_bound = [
            f"{n}={'low' if u[i] - pb.lo[i] <= tol[i] else 'high'}"
            for i, n in enumerate(pb.free)
            if u[i] - pb.lo[i] <= tol[i] or pb.hi[i] - u[i] <= tol[i]
        ]
        good = [v for v, f in finals if f]
        agree = sum(1 for v in good if v <= val * (1 + 1e-6)) >= min(2, len(good))
        res = OptimizationResult(
            network=pb.net.text,
            objective_name=objective,
            objective=math.sqrt(val),
            parameters=params,
            units=pb.design.units(),
            unit=unit,
            norms={},
            converged=ok,
            at_bound=at_bound,
            constraints=dict(pb.constraints),
            starts_agree=agree,
            evaluations=pb.neval,
            max_inertance=pb.max_inertance,
        )
        _describe(res, pb, lin, road)
        stand = _standins(pb, u, tol) if simplify else {}
    common = dict(
        constraints=constraints,
        weights=weights,
        seed=seed,
        max_inertance=max_inertance,
        road=road,
        **car,
    )
    compared = res.objective
    if stand and math.isfinite(res.objective):
        tree = _simplify(pb.net.tree, {n: v[0] for n, v in stand.items()})
        text = tree if isinstance(tree, str) else tree.text()
        res.simplified = {"network": text, "why": [v[1] for v in stand.values()]}
        if isinstance(tree, str):
            res.simplified["reason"] = (
                "the suspension locks (a rigid link between body and wheel)"
                if tree == "short"
                else "no connection between body and wheel"
            )
        else:
            names = parse_network(text).names
            held = {k: v for k, v in fixed.items() if k in names}
            if all(n in held for n in names):
                # nothing left to optimise: the simpler layout's value at the held values
                value = (
                    evaluate(text, held, [objective], **car)[objective]
                    if objective != "weighted"
                    else math.nan
                )
                res.simplified["objective"] = value if math.isfinite(value) else None
                compared = value
            else:
                sub = optimize_network(
                    text,
                    objective,
                    fixed=held,
                    bounds={k: v for k, v in bounds.items() if k in names},
                    starts=starts,
                    compare=compare,
                    **common,
                )
                if math.isfinite(sub.objective):
                    res.simplified.update(
                        objective=sub.objective,
                        parameters=sub.parameters,
                        improvement_vs=sub.improvement_vs,
                    )
                    if sub.simplified:
                        res.simplified["network"] = sub.simplified["network"]
                        res.simplified["why"] += sub.simplified["why"]
                    if compare:
                        res.improvement_vs = dict(sub.improvement_vs)
                    return res
                # the bound does not stand for that layout after all (e.g. a stiff spring
                # and an inerter still resonate inside the band): keep the optimum found
                res.simplified = {}
    if compare and pb.net.text != "k | c":
        # the reference holds only the main spring (same static stiffness); its
        # damper is always optimised, whatever is held in the network compared
        base_fixed = {k: v for k, v in fixed.items() if k == "k"}
        base_bounds = {k: v for k, v in bounds.items() if k == "k"}
        key = repr((objective, base_fixed, base_bounds, sorted(common.items())))
        base = _BASELINES.get(key)
        if base is None:
            base = _BASELINES[key] = optimize_network(
                "k | c",
                objective,
                fixed=base_fixed,
                bounds=base_bounds,
                starts=2,
                samples=64,
                compare=False,
                **common,
            )
        if math.isfinite(base.objective) and math.isfinite(compared):
            res.improvement_vs["k | c"] = 100.0 * (base.objective - compared) / base.objective
        else:
            res.improvement_vs["k | c"] = None
            if not math.isfinite(base.objective):
                note = f"k | c: {base.reason or 'infinite objective'}"
                res.reason = f"{res.reason}; {note}" if res.reason else note
    elif compare:
        res.improvement_vs["k | c"] = 0.0
    return res


def _describe(res: OptimizationResult, pb: _Problem, lin: dict, road) -> None:
    """Fill in the norms, the peaks used, the reasons of infinite values and the RMS
    values on the road of an :class:`OptimizationResult`."""
    peaks = list(QUANTITIES[_NT:])
    vals = evaluate(pb.q.network, lin, QUANTITIES, **_car_of(pb.q))
    res.norms = {k: vals[k] for k in TRANSFERS}
    res.peaks = {k: vals[k] for k in peaks}
    for k, v in vals.items():
        if not math.isfinite(v):
            res.infinite[k] = infinite_reason(k, pb.q, lin, road)
    if road is not None:
        cls, speed = _check_road(road)
        scale = road_scale(cls, speed)
        res.road = {
            "class": cls,
            "speed": speed,
            "units": "m/s",
            "note": "ISO 8608, waviness 2; RMS values under white road velocity (no band "
            "limits); for a quantity infinite there, over the band 0.01-10 cycle/m",
        }
        for k in TRANSFERS:
            v = res.norms[k]
            if math.isfinite(v):
                res.rms[k] = scale * v
            elif "not asymptotically stable" not in res.infinite.get(k, ""):
                res.rms[k + " (band 0.01-10 cycle/m)"] = band_limited_rms(k, pb.q, lin, cls, speed)


def _car_of(q: NetworkQuarterCar) -> dict:
    return dict(
        sprung_mass=q.sprung_mass,
        unsprung_mass=q.unsprung_mass,
        tyre_stiffness=q.tyre_stiffness,
        tyre_damping=q.tyre_damping,
    )


def optimize_all(
    dampers: int = 1,
    inerters: int = 1,
    springs: int = 2,
    objective: str = "body_acc",
    *,
    max_layouts: int = MAX_LAYOUTS,
    **kw,
) -> list[OptimizationResult]:
    """:func:`optimize_network` for every network of :func:`enumerate_networks` (a
    budget of at most ``max_layouts`` candidate layouts)."""
    nets = enumerate_networks(dampers, inerters, springs, max_layouts=max_layouts)
    return [optimize_network(n, objective, **kw) for n in nets]


# ---------------------------------------------------------------------------------------
# Pareto fronts by epsilon-constraint sweeps


def pareto_front(
    networks,
    objectives=("body_acc", "tyre_deflection"),
    *,
    points: int = 12,
    fixed=None,
    bounds=None,
    seed: int = 0,
    **car,
):
    """Pareto fronts of several networks between two or three H2 objectives.

    The first objective is minimised subject to upper limits on the others
    (epsilon-constraint method). For two objectives the limit on the second is swept
    over ``points`` values spaced geometrically between its own optimum (best possible)
    and its value at the first objective's optimum; for three objectives the limits of
    the second and third are swept on a ``points x points`` grid over the same ranges.
    Returns an :class:`xarray.Dataset` with dimensions (network, point): one variable
    per objective, the parameters (``param_<name>``) and the limits imposed
    (``limit_<objective>``); NaN where a sweep point is infeasible. Points of a
    three-objective grid may be dominated by others of the same grid (a limit that is
    not active); filter with the objectives' values where a strict front is needed.
    """
    import xarray as xr

    objectives = tuple(objectives)
    if len(objectives) not in (2, 3) or len(set(objectives)) != len(objectives):
        raise NetworkError("pareto: give two or three different objectives")
    for o in objectives:
        _quantity_name(o, "pareto objective")
    nets = [parse_network(n).text for n in networks]
    first, others = objectives[0], objectives[1:]
    rows = []
    all_names: list[str] = []
    for text in nets:
        # simplify=False: the front reads each optimum's own norms, not those of the
        # simpler layout an optimum on a bound stands for
        kw = dict(fixed=fixed, bounds=bounds, seed=seed, compare=False, simplify=False, **car)
        anchor = optimize_network(text, first, **kw)
        ranges = []
        for o in others:
            lo = _value(optimize_network(text, o, **kw), o)
            hi = _value(anchor, o)
            if not (math.isfinite(lo) and math.isfinite(hi)):
                ranges.append(None)
            else:
                ranges.append(np.geomspace(lo * 1.0001, max(hi, lo * 1.001), points))
        if any(r is None for r in ranges):
            grid = []
        elif len(others) == 1:
            grid = [(x,) for x in ranges[0]]
        else:
            grid = [(x, y) for x in ranges[0] for y in ranges[1]]
        res = []
        for lims in grid:
            r = optimize_network(
                text, first, constraints=dict(zip(others, lims, strict=True)), starts=3, **kw
            )
            res.append((r, lims))
        rows.append(res)
        for r, _ in res:
            for n in r.parameters:
                if n not in all_names:
                    all_names.append(n)
    npts = max((len(r) for r in rows), default=0)
    data = {o: np.full((len(nets), npts), np.nan) for o in objectives}
    pars = {n: np.full((len(nets), npts), np.nan) for n in all_names}
    limits = {o: np.full((len(nets), npts), np.nan) for o in others}
    for i, res in enumerate(rows):
        for j, (r, lims) in enumerate(res):
            for o, lim in zip(others, lims, strict=True):
                limits[o][i, j] = lim
            if not math.isfinite(r.objective):
                continue
            for o in objectives:
                data[o][i, j] = _value(r, o)
            for n, v in r.parameters.items():
                pars[n][i, j] = v
    ds = xr.Dataset(
        {o: (("network", "point"), data[o]) for o in objectives}
        | {f"param_{n}": (("network", "point"), pars[n]) for n in all_names}
        | {f"limit_{o}": (("network", "point"), limits[o]) for o in others},
        coords={"network": nets, "point": np.arange(npts)},
        attrs={
            "objectives": ",".join(objectives),
            "method": "epsilon-constraint: minimise the first objective with limits on the others",
            "units": "H2 norms per unit white road velocity, peak gains per m/s of road "
            "velocity: " + ", ".join(f"{o} [{unit_of(o)}]" for o in objectives),
            "car": str({k: v for k, v in car.items()}),
        },
    )
    for o in objectives:
        ds[o].attrs["long_name"] = (
            f"peak gain of {o[5:]}" if o.startswith("peak:") else f"H2 norm of {o}"
        )
        ds[o].attrs["units"] = unit_of(o)
    return ds


def _value(r: OptimizationResult, quantity: str) -> float:
    """A quantity's value at a result: its H2 norm or its peak gain."""
    if quantity in r.norms:
        return r.norms[quantity]
    return r.peaks.get(quantity, math.nan)


def pareto_figure(ds):
    """Figure of the fronts in a Dataset from :func:`pareto_front` (first two objectives)."""
    from matplotlib.figure import Figure

    objs = ds.attrs["objectives"].split(",")
    fig = Figure(figsize=(6.4, 4.6))
    ax = fig.add_subplot(1, 1, 1)
    for net in ds["network"].values:
        x = ds[objs[1]].sel(network=net).values
        y = ds[objs[0]].sel(network=net).values
        ok = np.isfinite(x) & np.isfinite(y)
        if len(objs) == 3:
            ax.scatter(x[ok], y[ok], s=10, label=str(net))
        else:
            o = np.argsort(x[ok])
            ax.plot(x[ok][o], y[ok][o], marker="o", ms=3, label=str(net))
    ax.set_xlabel(f"{objs[1]} [{unit_of(objs[1])}]")
    ax.set_ylabel(f"{objs[0]} [{unit_of(objs[0])}]")
    ax.set_title("H2 Pareto fronts (epsilon-constraint)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    return fig


# ---------------------------------------------------------------------------------------
# the size of an enumeration, counted before it is built


def _mset_times(poly: dict, part: tuple, count: int, box: tuple) -> dict:
    """``poly`` times (1 - x^part)^-count: multisets of ``count`` kinds of one part."""
    from math import comb

    if count == 0:
        return poly
    out = dict(poly)
    for key, val in poly.items():
        j = 1
        while True:
            k = tuple(a + j * p for a, p in zip(key, part, strict=True))
            if any(a > b for a, b in zip(k, box, strict=True)):
                break
            out[k] = out.get(k, 0) + val * comb(count + j - 1, j)
            j += 1
    return out


def _set_times(poly: dict, part: tuple, box: tuple) -> dict:
    """``poly`` times (1 + x^part): at most one of this part."""
    out = dict(poly)
    for key, val in poly.items():
        k = tuple(a + p for a, p in zip(key, part, strict=True))
        if all(a <= b for a, b in zip(k, box, strict=True)):
            out[k] = out.get(k, 0) + val
    return out


def _coefficient(n: tuple, f: dict, g: dict) -> int:
    """Coefficient of x^n in the product f g."""
    return sum(v * g.get(tuple(a - b for a, b in zip(n, k, strict=True)), 0) for k, v in f.items())


#: bytes of memory per series-parallel tree the enumeration builds (nested tuples)
_TREE_BYTES = 800


def check_budget(
    dampers: int, inerters: int, springs: int, max_layouts: int = MAX_LAYOUTS, *, cli=False
) -> dict:
    """Count the layouts of a budget before building them (:func:`count_layouts`) and
    refuse a budget with more than ``max_layouts`` candidates or whose trees do not fit
    in memory: the one rule of :func:`~inerterlab.networks.enumerate_networks` and of
    the command line (``cli=True`` spells the options as ``--dampers ...``)."""
    from .resources import check_memory

    limit_name = "max-layouts" if cli else "max_layouts"
    if isinstance(max_layouts, bool) or not isinstance(max_layouts, numbers.Integral):
        raise ParameterError(limit_name, max_layouts, "an integer >= 1")
    if max_layouts < 1:
        raise ParameterError(limit_name, max_layouts, "an integer >= 1")
    n = count_layouts(dampers, inerters, springs)
    if cli:
        opts = f"--dampers {dampers} --inerters {inerters} --springs {springs}"
        limit = f"--max-layouts={max_layouts}"
    else:
        opts = f"dampers={dampers}, inerters={inerters}, springs={springs}"
        limit = f"max_layouts={max_layouts}"
    if n["candidates"] > max_layouts:
        raise ParameterError(
            "dampers/inerters/springs",
            opts,
            f"a budget of at most {limit} candidate layouts: this one has "
            f"{n['candidates']:.4g} (before equal families are merged); lower the budget or "
            f"raise {limit.split('=')[0]}",
        )
    check_memory(
        n["trees"] * _TREE_BYTES / 8,
        what=f"enumeration ({n['trees']:.4g} series-parallel trees)",
        parameter="dampers/inerters/springs",
        value=opts,
    )
    return n


def count_layouts(dampers: int = 1, inerters: int = 1, springs: int = 2) -> dict:
    """Sizes of :func:`~inerterlab.networks.enumerate_networks` for a budget, counted
    without building it (generating functions over multisets of sub-networks).

    Returns ``candidates``: the networks k | (N) listed before equal families are
    merged (an upper bound of the listed count; exact without merging), and ``trees``:
    the series-parallel trees the enumeration builds on the way (its memory and time).

    >>> count_layouts(1, 1, 0)["candidates"]
    4
    """
    for nm, v in (("dampers", dampers), ("inerters", inerters), ("springs", springs)):
        if isinstance(v, bool) or not isinstance(v, numbers.Integral) or not 0 <= v <= 4:
            raise NetworkError(f"invalid {nm}={v!r}: expected an integer 0-4")
    box = (int(springs), int(dampers), int(inerters))
    units = {"k": (1, 0, 0), "c": (0, 1, 0), "b": (0, 0, 1)}
    zero = (0, 0, 0)
    # products over the parts of smaller total, updated total by total
    all_non_p = {zero: 1}  # multisets of trees whose root is not parallel (every tree)
    d_s, d_s_ns, d_p, d_p_s = ({zero: 1} for _ in range(4))  # nondegenerate children
    leaves3 = {zero: 1}
    for u in units.values():
        leaves3 = _set_times(leaves3, u, box)
    leaves_ns = _set_times(_set_times({zero: 1}, units["c"], box), units["b"], box)
    leaves_k = _set_times({zero: 1}, units["k"], box)
    comps = sorted(
        (n for n in np.ndindex(*(b + 1 for b in box)) if sum(n) > 0), key=lambda n: sum(n)
    )
    a_tot: dict = {}  # every canonical tree of composition n (what _trees returns)
    cand = 0
    new: dict = {}
    total = 1
    for n in [*comps, None]:
        if n is None or sum(n) > total:
            # fold the parts of the finished total into the products
            for m, (a_s, ds, ds_ns, dp, dp_s) in new.items():
                all_non_p = _mset_times(all_non_p, m, a_s, box)
                d_s = _mset_times(d_s, m, ds, box)
                d_s_ns = _mset_times(d_s_ns, m, ds_ns, box)
                d_p = _mset_times(d_p, m, dp, box)
                d_p_s = _mset_times(d_p_s, m, dp_s, box)
            new = {}
            if n is None:
                break
            total = sum(n)
        if total == 1:
            static = n == units["k"]
            a_tot[n] = 1
            cand += 0 if static else 1
            # a leaf is a child of either kind of node; in nondegenerate nodes the
            # leaves are counted by the set factors (at most one leaf of each type)
            new[n] = (1, 0, 0, 0, 0)
            continue
        a_p = all_non_p.get(n, 0)  # parallel roots; series roots are as many
        a_tot[n] = 2 * a_p
        p_all = _coefficient(n, leaves3, d_s)
        p_ns = _coefficient(n, leaves_ns, d_s_ns)
        s_all = _coefficient(n, leaves3, d_p)
        s_st = _coefficient(n, leaves_k, d_p_s)
        cand += p_ns + (s_all - s_st)
        # children of the next totals: series roots feed parallel nodes and vice versa
        new[n] = (a_p, s_all, s_all - s_st, p_all, p_all - p_ns)
    return {"candidates": int(cand), "trees": int(sum(a_tot.values()))}


# ---------------------------------------------------------------------------------------
# figure: the transfer and the spectra an engineer looks at


def network_figure(network, params, *, reference=None, road=None, title=None, **car):
    """|H(f)| of the body acceleration per road velocity for ``network`` against
    ``k | c`` (``reference`` its k and c; default the reference damper
    c = k sqrt((m_s + m_u)/k_t) of :func:`reference_norms`), with the Wk-weighted
    transfer dashed, and the one-sided PSD of the body acceleration with and without the
    Wk weighting on the road ``road`` = (ISO 8608 class, speed), or per unit white road
    velocity."""
    from matplotlib.figure import Figure

    q = network_quarter_car(network, **car)
    qr = network_quarter_car("k | c", **car)
    if reference is None:
        k = float(params.get("k", 50e3))
        c = k * math.sqrt((q.sprung_mass + q.unsprung_mass) / q.tyre_stiffness)
        reference, rlabel = {"k": k, "c": c}, "k | c (c = k sqrt((m_s+m_u)/k_t))"
    else:
        reference = {"k": float(reference["k"]), "c": float(reference["c"])}
        rlabel = "k | c (optimised)"
    if road is not None:
        cls, speed = _check_road(road)
        sv = 2.0 * road_scale(cls, speed) ** 2
        where = f"ISO 8608 class {cls} at {speed:g} m/s (white road velocity)"
    else:
        sv, where = 2.0, "unit white road velocity (one-sided 2 (m/s)^2/Hz)"
    f = np.geomspace(0.1, 100.0, 800)
    fig = Figure(figsize=(10.5, 4.2), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    for label, qq, p, color in (
        (q.network.text, q, params, "C0"),
        (rlabel, qr, reference, "C1"),
    ):
        h = np.abs(transfer("body_acc", qq, p)(f))
        hw = np.abs(transfer("body_acc_wk", qq, p)(f))
        ax1.loglog(f, h, color=color, label=label)
        ax1.loglog(f, hw, color=color, ls="--", label=f"{label}, Wk-weighted")
        ax2.loglog(f, h**2 * sv, color=color, label=label)
        ax2.loglog(f, hw**2 * sv, color=color, ls="--", label=f"{label}, Wk-weighted")
    ax1.set_xlabel("frequency f [Hz]")
    ax1.set_ylabel("|H(j 2 pi f)| body acceleration / road velocity [1/s]")
    ax1.set_title("transfer from road velocity (linear)", fontsize=9)
    ax2.set_xlabel("frequency f [Hz]")
    ax2.set_ylabel("PSD of body acceleration [(m/s^2)^2/Hz]")
    ax2.set_title(where, fontsize=9)
    for ax in (ax1, ax2):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig
