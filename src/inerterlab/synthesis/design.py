"""The synthesis as one job: PR optimum, its realisations, and the enumerated layouts.

:func:`synthesize_design` runs :func:`~inerterlab.synthesis.optimize.synthesize`,
rounds coefficients of Y0 that are negligible (the optimum sits on the boundary of the
family, e.g. Y0(0) = 0, which the search reaches only to ~1e-9) when this changes the
objective by less than 1e-7 relative and keeps the function PR, realises the result by
every method, and optimises every enumerated layout whose Y0 has McMillan degree <= n
(:func:`inerterlab.network_design.optimize_network`, same car and main spring) to
report the gap: 100 (J_layout - J_PR) / J_layout, never negative up to the searches'
tolerance since every such layout is a member of the PR family (or a limit of it).
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..networks import admittance, enumerate_networks
from .optimize import _y0, objective_value, synthesize
from .positive_real import pr_report
from .realise import RealisationError, brune, realise_all

__all__ = ["synthesize_design", "layout_degree", "compare_layouts"]

_LAYOUT_OBJECTIVE = {
    "body_acc": "body_acc",
    "tyre_deflection": "tyre_deflection",
    "tyre_load": "tyre_deflection",
    "suspension_deflection": "suspension_deflection",
}


def layout_degree(net) -> int:
    """McMillan degree of Y0 = Y - k/s of a layout ``k | (N)`` (generic parameters)."""
    rng = np.random.default_rng(7)
    params = {n: float(np.exp(rng.uniform(-1, 1))) for n in net.names}
    num, den = admittance(net, params)
    return max(len(num), len(den)) - 1 - 1


def compare_layouts(degree, objective, k, budget=(1, 1, 2), seed=0, **car) -> dict:
    """Best enumerated layout (dampers, inerters, springs budget) with deg Y0 <= degree."""
    from ..network_design import optimize_network

    if objective not in _LAYOUT_OBJECTIVE:
        return {"reason": f"the layout optimiser has no {objective} objective"}
    nets = [n for n in enumerate_networks(*budget) if layout_degree(n) <= degree]
    rows = []
    for net in nets:
        r = optimize_network(
            net,
            _LAYOUT_OBJECTIVE[objective],
            fixed={"k": k},
            seed=seed,
            compare=False,
            starts=4,
            **car,
        )
        val = r.objective * (
            car.get("tyre_stiffness", 120_000.0) if objective == "tyre_load" else 1.0
        )
        rows.append(
            {
                "network": r.network,
                "objective": val,
                "parameters": r.parameters,
                "at_bound": r.at_bound,
            }
        )
    rows.sort(key=lambda d: d["objective"])
    return {
        "budget": {"dampers": budget[0], "inerters": budget[1], "springs": budget[2]},
        "layouts": rows,
    }


def _clean(res, objective, car):
    """Zero negligible coefficients of Y0 when that keeps the objective and PR-ness."""
    n0 = np.array(res.y0_numerator, float)
    d0 = np.array(res.y0_denominator, float)
    roots = np.abs(np.concatenate([np.roots(d0), np.roots(n0) if len(n0) > 1 else []]))
    wr = float(np.exp(np.mean(np.log(roots[roots > 0])))) if np.any(roots > 0) else 1.0
    best = None
    for tol in (1e-12, 1e-10, 1e-8, 1e-6):
        nn, dd = n0.copy(), d0.copy()
        for p in (nn, dd):
            sc = p * wr ** np.arange(len(p) - 1, -1, -1)
            p[np.abs(sc) < tol * np.max(np.abs(sc))] = 0.0
        k = res.static_stiffness
        num = np.polyadd(k * dd, np.polymul(nn, [1.0, 0.0]))
        den = np.polymul(dd, [1.0, 0.0])
        val = objective_value(num, den, objective, **car)
        if pr_report(nn, dd)["positive_real"] and abs(val - res.objective) <= 1e-7 * res.objective:
            best = (num, den, nn, dd, val)
    return best


def synthesize_design(
    degree: int = 2,
    objective: str = "body_acc",
    *,
    static_stiffness: float = 90_000.0,
    starts: int | None = None,
    seed: int = 0,
    compare: bool = True,
    budget=(1, 1, 2),
    catalogue_budget=(2, 2, 2),
    **car,
) -> dict:
    """PR optimum, realisations and the gap to the enumerated layouts, as one dict."""
    t0 = time.perf_counter()
    res = synthesize(
        degree, objective, static_stiffness=static_stiffness, starts=starts, seed=seed, **car
    )
    out = res.to_dict()
    num, den = np.array(res.numerator), np.array(res.denominator)
    cleaned = _clean(res, objective, res.car)
    if cleaned is not None and (
        len(np.flatnonzero(cleaned[2])) < len(np.flatnonzero(res.y0_numerator))
        or len(np.flatnonzero(cleaned[3])) < len(np.flatnonzero(res.y0_denominator))
    ):
        num, den = cleaned[0], cleaned[1]
        out["rounded"] = {
            "numerator": num.tolist(),
            "denominator": den.tolist(),
            "objective": cleaned[4],
            "note": "coefficients of Y0 below 1e-6 of their polynomial's largest (frequency-"
            "normalised) set to 0; objective changed by < 1e-7 relative",
        }
    reals = realise_all(num, den, budget=catalogue_budget)
    out["realisations"] = {m: (r if isinstance(r, str) else r.to_dict()) for m, r in reals.items()}
    try:
        b = brune(*_y0_only(num, den, static_stiffness))
        out["brune"] = {
            "sections": [s.__dict__ for s in b["sections"]],
            "note": "Y0 only (the main spring k is in parallel); each section needs a lever "
            "(ideal transformer), which the network text cannot express",
        }
    except RealisationError as e:
        out["brune"] = {"reason": str(e)}
    best_net = None
    for m in ("catalogue", "foster", "cauer", "bott-duffin"):
        r = reals.get(m)
        if not isinstance(r, str) and r is not None:
            if best_net is None or r.elements < best_net.elements:
                best_net = r
    if best_net is not None:
        from ..suspension.network_linear import network_quarter_car

        norms = network_quarter_car(best_net.network, **res.car).h2(best_net.parameters)
        out["network"] = {
            "method": best_net.method,
            "text": best_net.network,
            "parameters": best_net.parameters,
            "elements": best_net.elements,
            "norms": {k: (v if math.isfinite(v) else None) for k, v in norms.items()},
        }
    if compare:
        cmp_ = compare_layouts(
            degree, objective, static_stiffness, budget=budget, seed=seed, **res.car
        )
        if cmp_.get("layouts"):
            bestl = cmp_["layouts"][0]
            cmp_["best"] = bestl["network"]
            cmp_["best_objective"] = bestl["objective"]
            cmp_["gap_percent"] = (
                100.0 * (bestl["objective"] - res.objective) / bestl["objective"]
                if math.isfinite(bestl["objective"])
                else None
            )
        out["comparison"] = cmp_
    out["seconds_total"] = time.perf_counter() - t0
    return out


def _y0_only(num, den, k):
    n0, d0 = _y0(num, den, k)
    return n0, d0
