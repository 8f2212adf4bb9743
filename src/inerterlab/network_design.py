"""H2-optimal parameters of linear suspension networks and Pareto fronts between norms.

Objectives are the H2 norms of :mod:`inerterlab.suspension.network_linear` per unit
white road velocity: ``body_acc`` (comfort), ``tyre_deflection`` (road holding; times
k_t it is the elastic tyre load), ``suspension_deflection`` (working space), or
``weighted``: sqrt(sum_i w_i (H_i / H_i,ref)^2) with H_i,ref the norms of the reference
``k | c`` whose damping minimises the body acceleration without tyre damping,
c = k sqrt((m_s + m_u)/k_t); equal weights by default, so the reference scores 1.

Elements. Any element of the registry may stand in the network: springs, dampers and
inerters are one parameter each; any other element (a fluid inerter, friction, an
adaptive flywheel, a device, a user's element) enters through its linearisation about
rest, and its parameters (``fluid.length``) are the variables (:class:`_Design`).

Search. Parameters are searched in logarithms within bounds (defaults: each
parameter's ``design`` range in the registry; fixed ones, e.g. the main spring, are
held). A scrambled Sobol sample of the box is
evaluated in one compiled batch, the best few distinct points are polished by L-BFGS-B
(unconstrained) or SLSQP (with limits on other norms), and the best polished point wins.
The gradient for the polish is exact up to rounding and costs one batch call: every
polynomial coefficient of the car is affine in each single network parameter, so the
squared norm is differentiated through the coefficients by the adjoint of the Lyapunov
equation (observability gramian), see :func:`gradient`.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field

import numba as nb
import numpy as np

from .errors import PHYSICAL_RANGES, ParameterError, check_physical, check_seed, shorten
from .h2 import h2_rational, h2_rational_gradient
from .networks import MAX_LAYOUTS, NetworkError, enumerate_networks, linearise, parse_network
from .suspension.network_linear import (
    _QUANTITY,
    MAXC,
    OUTPUTS,
    NetworkQuarterCar,
    _assemble,
    _car_polys,
    h2_squared_many,
    network_quarter_car,
)

__all__ = [
    "OBJECTIVES",
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
]

OBJECTIVES = (*OUTPUTS, "weighted")
_BIG = 1e30

#: most starts of the local polish one optimisation takes
MAX_STARTS = 100


# ---------------------------------------------------------------------------------------
# exact gradient: adjoint of the Lyapunov equation through the polynomial coefficients


@nb.njit(cache=True)
def _grad_batch(prog, theta, car, which, grad):
    """Squared norm of output ``which`` (1..3) and its derivatives in log-parameters."""
    num = np.zeros(MAXC)
    den = np.zeros(MAXC)
    ln, ld = _assemble(prog, theta, num, den)
    base = np.zeros((4, MAXC))
    n = _car_polys(num, ln, den, ld, car[0], car[1], car[2], car[3], base)
    sq = np.empty(3)
    h2_rational(base, n, sq)
    if not np.isfinite(sq[which - 1]):
        grad[:] = np.nan
        return sq[which - 1]
    g = np.zeros((2, n + 1))
    h2_rational_gradient(base, n, which, g)
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
    return sq[which - 1]


def gradient(car: NetworkQuarterCar, params: dict, output: str) -> tuple[float, dict]:
    """Squared H2 norm of ``output`` and its derivative in the log of each parameter."""
    th = car.theta(params)
    g = np.empty(len(th))
    val = _grad_batch(car.program, th, car.car_vector, OUTPUTS.index(output) + 1, g)
    return float(val), dict(zip(car.network.names, g.tolist(), strict=True))


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
        for name, p in params.items():
            if name in fixed:
                continue
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


def reference_norms(**car) -> dict:
    """Norms of ``k | c`` with c = k sqrt((m_s + m_u)/k_t), k from ``car['k']`` (50 kN/m)."""
    k = float(car.pop("k", 50e3))
    q = network_quarter_car("k | c", **car)
    c = k * math.sqrt((q.sprung_mass + q.unsprung_mass) / q.tyre_stiffness)
    return q.h2({"k": k, "c": c})


@dataclass
class OptimizationResult:
    """Best parameters found for one network and objective."""

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

    def to_dict(self) -> dict:
        out = {
            "network": self.network,
            "objective_name": self.objective_name,
            "objective": self.objective if math.isfinite(self.objective) else None,
            "parameters": self.parameters,
            "units": self.units,
            "norms": {k: (v if math.isfinite(v) else None) for k, v in self.norms.items()},
            "improvement_vs": self.improvement_vs,
            "converged": self.converged,
            "at_bound": self.at_bound,
        }
        if self.constraints:
            out["constraints"] = self.constraints
        if self.reason:
            out["reason"] = self.reason
        return out


class _Problem:
    def __init__(self, net, objective, fixed, bounds, constraints, weights, car):
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
        self.constraints = {}
        for k, v in constraints.items():
            if k not in OUTPUTS:
                raise NetworkError(f"constraint on {k!r}: expected one of {', '.join(OUTPUTS)}")
            v = float(v)
            if not v > 0:
                raise NetworkError(f"constraint {k} <= {v}: the limit must be > 0")
            self.constraints[k] = v
        ref = None
        if objective == "weighted":
            ref = reference_norms(k=self.fixed.get("k", 50e3), **car)
            w = {k: 1.0 for k in OUTPUTS} if not weights else {k: 0.0 for k in OUTPUTS}
            for k, v in (weights or {}).items():
                if k not in OUTPUTS or float(v) < 0:
                    raise NetworkError(f"weight {k}={v}: expected an output name and w >= 0")
                w[k] = float(v)
            tot = sum(w.values())
            if not tot > 0:
                raise NetworkError("weights: at least one must be > 0")
            self.wvec = np.array([w[k] / tot / ref[k] ** 2 for k in OUTPUTS])
        else:
            self.wvec = np.array([1.0 if k == objective else 0.0 for k in OUTPUTS])
        self.ref = ref
        self.car = self.q.car_vector
        self.prog = self.q.program
        self.neval = 0
        self.cidx = [OUTPUTS.index(k) for k in self.constraints]
        # v * v: a limit beyond 1e154 squares to inf, which is no constraint (not an error)
        self.clim = np.array([self.constraints[k] * self.constraints[k] for k in self.constraints])

    def thetas(self, U):
        return self.design.thetas(U)

    def squares(self, U):
        T = self.thetas(U)
        out = np.empty((T.shape[0], 3))
        ok = np.all(np.isfinite(T), axis=1)
        out[~ok] = np.inf
        if ok.all():
            h2_squared_many(self.prog, T, self.car, out)
        elif ok.any():
            part = np.empty((int(ok.sum()), 3))
            h2_squared_many(self.prog, T[ok], self.car, part)
            out[ok] = part
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

    def violation(self, sq):
        if not self.cidx:
            return np.zeros(sq.shape[0])
        r = sq[:, self.cidx] / self.clim - 1.0
        r = np.where(np.isfinite(r), r, 1e6)
        return np.maximum(r, 0.0).sum(axis=1)

    def f_and_g(self, u):
        """Scalar objective and its gradient in the free log-parameters."""
        th = self.thetas(u)[0]
        total, grad = 0.0, np.zeros(len(self.free))
        if not np.all(np.isfinite(th)):
            return _BIG, grad
        gfull = np.empty(len(th))
        for o in range(3):
            w = self.wvec[o]
            if w == 0.0:
                continue
            v = _grad_batch(self.prog, th, self.car, o + 1, gfull)
            self.neval += 1 + len(th)
            g = self.design.chain(u, gfull)
            if not np.isfinite(v) or not np.all(np.isfinite(g)):
                return _BIG, np.zeros(len(self.free))
            total += w * v
            grad += w * g
        return total, grad

    def cons_and_jac(self, u):
        th = self.thetas(u)[0]
        vals, jacs = [], []
        gfull = np.empty(len(th))
        for o, lim in zip(self.cidx, self.clim, strict=True):
            v = _grad_batch(self.prog, th, self.car, o + 1, gfull) if np.all(np.isfinite(th)) else np.nan
            if not np.isfinite(v):
                vals.append(-1e6)
                jacs.append(np.zeros(len(self.free)))
                continue
            vals.append(1.0 - v / lim)
            jacs.append(-self.design.chain(u, gfull) / lim)
        return np.array(vals), np.array(jacs)

    def value(self, sq_row) -> float:
        v = float(self.scalar(sq_row[None, :])[0])
        return math.sqrt(v) if v < _BIG else math.inf


def _polish(pb: _Problem, u0: np.ndarray, maxiter: int | None = None):
    from scipy.optimize import minimize

    bnds = list(zip(pb.lo, pb.hi, strict=True))
    f0 = pb.f_and_g(u0)[0]
    fs = 1.0 / f0 if 0 < f0 < _BIG else 1.0  # SLSQP wants an objective of order one

    def fg(u):
        f, g = pb.f_and_g(u)
        return f * fs, g * fs

    if pb.cidx:
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
        viol = pb.violation(sq)
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
    projected on the bounds, vanishes relative to the objective.
    """
    if pb.cidx or not math.isfinite(val) or val >= _BIG:
        return False
    _, g = pb.f_and_g(u)
    tol = 1e-4 * (pb.hi - pb.lo)
    g = np.where((u - pb.lo <= tol) & (g > 0), 0.0, g)
    g = np.where((pb.hi - u <= tol) & (g < 0), 0.0, g)
    return bool(np.max(np.abs(g)) <= 1e-5 * val)


_BASELINES: dict = {}


def check_settings(objective, *, weights=None, starts=8, samples=256, seed=0) -> None:
    """Raise if the settings of :func:`optimize_network` (other than the network and
    its parameters) are invalid: the objective, unused weights, starts, samples, seed."""
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
    **car,
) -> OptimizationResult:
    """Minimise one H2 objective over the free parameters of ``network``.

    Parameters
    ----------
    network : str or Network
    objective : {"body_acc", "tyre_deflection", "suspension_deflection", "weighted"}
    fixed : dict or list of "name=value", held parameters (e.g. ``{"k": 50e3}``).
    bounds : dict name -> (low, high) or "low:high"; a low of 0 means 1e-6 x high.
        Defaults: each parameter's ``design`` range in the element registry. Names are
        those of :func:`design_parameters`: ``k``, ``c2`` for springs, dampers and
        inerters, ``<element>.<parameter>`` for any other element (its linearisation
        about rest is what the H2 norms see), e.g. ``fluid.length``.
    constraints : dict output -> upper limit of its H2 norm (constraint form, e.g.
        minimise body_acc with tyre and suspension deflection limits).
    weights : dict output -> weight of the ``weighted`` objective (default equal).
    starts, samples, seed : starts (the differential evolution's best point and the
        best distinct Sobol points; each gets a short polish, the two best a full one),
        Sobol sample size, sample seed.
    evolve : with two or more free parameters, run a differential evolution over the
        log box first (one compiled batch per generation) and polish its best point too.
    compare : also optimise ``k | c`` under the same settings and report the
        improvement in percent (positive: this network is better).
    car : sprung_mass, unsprung_mass, tyre_stiffness, tyre_damping.
    """
    from scipy.stats import qmc

    check_settings(objective, weights=weights, starts=starts, samples=samples, seed=seed)
    fixed = _parse_assignments(fixed, "fixed parameter")
    bounds = _parse_assignments(bounds, "bound")
    constraints = _parse_assignments(constraints, "constraint")
    weights = _parse_assignments(weights, "weight")
    for k, v in list(fixed.items()):
        try:
            fixed[k] = float(v)
        except ValueError:
            raise NetworkError(f"fixed parameter {k}={v!r}: not a number") from None
    pb = _Problem(network, objective, fixed, bounds, constraints, weights, car)
    d = len(pb.free)
    m = max(int(samples), 16 * d)
    sob = qmc.Sobol(d, scramble=True, seed=seed)
    U = pb.lo + (pb.hi - pb.lo) * sob.random(2 ** int(math.ceil(math.log2(m))))
    sq = pb.squares(U)
    score = pb.scalar(sq)
    viol = pb.violation(sq)
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
            r = _polish(pb, u0, maxiter=15)
            u = np.clip(r.x, pb.lo, pb.hi)
            s = pb.squares(u)
            ends.append((float(pb.scalar(s)[0] * (1.0 + 1e3 * pb.violation(s)[0])), u))
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
        u = np.clip(r.x, pb.lo, pb.hi)
        s = pb.squares(u)
        val = float(pb.scalar(s)[0])
        feas = pb.violation(s)[0] <= 1e-6
        finals.append((val, feas))
        if feas and (best is None or val < best[0]):
            best = (val, u, s[0], bool(r.success) or _kkt(pb, u, val))
    if best is None:
        reason = (
            "no finite objective anywhere in the bounds (see the norms' reasons: "
            "unstable car or direct feed-through)"
            if not picks
            else "no start met the constraints"
        )
        u = (pb.lo + pb.hi) / 2
        params, lin = pb.parameters(u), pb.linear_parameters(u)
        res = OptimizationResult(
            network=pb.net.text,
            objective_name=objective,
            objective=math.inf,
            parameters=params,
            units=pb.design.units(),
            norms=pb.q.h2(lin),
            converged=False,
            at_bound=[],
            evaluations=pb.neval,
            reason=reason
            + ("; " + "; ".join(pb.q.h2_reasons(lin).values()) if picks == [] else ""),
        )
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
            norms=pb.q.h2(lin),
            converged=ok,
            at_bound=at_bound,
            constraints=dict(pb.constraints),
            starts_agree=agree,
            evaluations=pb.neval,
        )
    if compare and pb.net.text != "k | c":
        # the reference holds only the main spring (same static stiffness); its
        # damper is always optimised, whatever is held in the network compared
        base_fixed = {k: v for k, v in fixed.items() if k == "k"}
        base_bounds = {k: v for k, v in bounds.items() if k == "k"}
        key = repr((objective, base_fixed, base_bounds, constraints, weights, seed, car))
        base = _BASELINES.get(key)
        if base is None:
            base = _BASELINES[key] = optimize_network(
                "k | c",
                objective,
                fixed=base_fixed,
                bounds=base_bounds,
                constraints=constraints,
                weights=weights,
                starts=2,
                samples=64,
                seed=seed,
                compare=False,
                **car,
            )
        if math.isfinite(base.objective) and math.isfinite(res.objective):
            res.improvement_vs["k | c"] = 100.0 * (base.objective - res.objective) / base.objective
        else:
            res.improvement_vs["k | c"] = None
            if not math.isfinite(base.objective):
                note = f"k | c: {base.reason or 'infinite objective'}"
                res.reason = f"{res.reason}; {note}" if res.reason else note
    elif compare:
        res.improvement_vs["k | c"] = 0.0
    return res


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
        if o not in OUTPUTS:
            raise NetworkError(f"pareto objective {o!r}: expected one of {', '.join(OUTPUTS)}")
    nets = [parse_network(n).text for n in networks]
    first, others = objectives[0], objectives[1:]
    rows = []
    all_names: list[str] = []
    for text in nets:
        kw = dict(fixed=fixed, bounds=bounds, seed=seed, compare=False, **car)
        anchor = optimize_network(text, first, **kw)
        ranges = []
        for o in others:
            lo = optimize_network(text, o, **kw).norms[o]
            hi = anchor.norms[o]
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
                data[o][i, j] = r.norms[o]
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
            "units": "H2 norms per unit white road velocity (body_acc m/s^2, deflections m)",
            "car": str({k: v for k, v in car.items()}),
        },
    )
    for o in objectives:
        ds[o].attrs["long_name"] = f"H2 norm of {o}"
    return ds


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
    ax.set_xlabel(f"{objs[1]} H2 norm")
    ax.set_ylabel(f"{objs[0]} H2 norm")
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
