"""Minimal series-parallel realisation from the enumerated catalogue of layouts.

The catalogue is :func:`inerterlab.networks.enumerate_networks` (every layout ``k | (N)``
of a budget, without the numerical family merge, which only removes duplicates),
tried in order of the number of elements of N. A layout fits when its parameters can
be chosen so that its admittance equals the target's coefficient by coefficient
(nonlinear least squares in the logarithms of the element values from several
starts, on the frequency-normalised target); the first layout that fits to a
relative 1e-10 is minimal within the catalogue. Layouts whose generic degrees or
structural zeros differ from the target's are skipped before fitting.
"""

from __future__ import annotations

import numpy as np

from ..networks import MAX_LAYOUTS, Element, admittance, enumerate_networks, parse_network

__all__ = ["fit_catalogue", "catalogue_layouts"]

_DEFAULT_BUDGET = (2, 2, 2)  # dampers, inerters, springs besides k


#: the realisation trees' element kinds by the network grammar's prefixes
_KIND = {"k": "spring", "c": "damper", "b": "inerter"}

def catalogue_layouts(dampers: int = 2, inerters: int = 2, springs: int = 2) -> list[str]:
    """Sub-network texts N of the layouts ``k | (N)``, fewest elements first."""
    subs = []
    # without merging, listing is fast: the default budget's 556 candidates take well
    # under a second, so the catalogue allows ten times the default limit
    nets = enumerate_networks(
        dampers, inerters, springs, merge_equivalent=False, max_layouts=10 * MAX_LAYOUTS
    )
    for net in nets:
        tree = net.tree
        parts = [p for p in tree.parts if not (isinstance(p, Element) and p.name == "k")]
        if len(parts) == 1:
            text = parts[0].text()
        else:
            text = " | ".join(
                p.text() if isinstance(p, Element) else f"({p.text()})" for p in parts
            )
        subs.append(parse_network(text))
    subs.sort(key=lambda n: len(n.names))
    return [n.text for n in subs]


def _norm(num, den):
    num = np.asarray(num, float)
    den = np.asarray(den, float)
    return num / den[0], den / den[0]


def _pattern(num, den, rel=1e-12):
    big = max(np.max(np.abs(num)), np.max(np.abs(den)))
    return (len(num), len(den), tuple(np.abs(num) > rel * big), tuple(np.abs(den) > rel * big))


def fit_catalogue(num, den, budget=_DEFAULT_BUDGET, starts: int = 6, seed: int = 0):
    """Realisation of Y = num/den from the smallest catalogue layout that fits."""
    from scipy.optimize import least_squares

    from .realise import (
        RealisationError,
        _check,
        _scaled,
        _split_main_spring,
        _to_sigma,
        check_points,
    )

    k, n0, d0 = _split_main_spring(num, den)
    wr = _scaled(n0, d0)
    p, q = _to_sigma(n0, wr), _to_sigma(d0, wr)
    g = np.max(np.abs(p)) / np.max(np.abs(q))
    tn, td = _norm(p / g, q)
    target_pattern = _pattern(tn, td)
    rng = np.random.default_rng(seed)
    mask_n = np.abs(tn) > 0
    mask_d = np.abs(td) > 0
    scale_of = {"spring": g * wr, "damper": g, "inerter": g / wr}
    for text in catalogue_layouts(*budget):
        net = parse_network(text)
        names = net.names
        x0 = rng.uniform(-0.5, 0.5, len(names))
        an, ad = _norm(*admittance(net, dict(zip(names, np.exp(x0), strict=True))))
        if _pattern(an, ad) != target_pattern:
            continue

        def res(x, net=net, names=names):
            bad = np.full(int(mask_n.sum() + mask_d.sum()), 1e3)
            try:  # far from the target the values over- or underflow
                a, b = _norm(*admittance(net, dict(zip(names, np.exp(x), strict=True))))
            except (IndexError, ValueError, ZeroDivisionError, FloatingPointError):
                return bad
            if len(a) != len(tn) or len(b) != len(td) or not np.all(np.isfinite(a)):
                return bad
            return np.concatenate([(a - tn)[mask_n], (b - td)[mask_d]])

        for i in range(starts):
            x0 = rng.uniform(-3.0, 3.0, len(names)) if i else np.zeros(len(names))
            try:
                with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                    r = least_squares(
                        res, x0, xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=400 * len(names)
                    )
            except (ValueError, FloatingPointError):
                continue
            if np.max(np.abs(r.fun)) > 1e-10:
                continue
            vals = {n: float(np.exp(v)) for n, v in zip(names, r.x, strict=True)}
            # back to physical units
            params = {n: vals[n] * scale_of[_KIND[kind]] for n, kind in zip(names, net.kinds, strict=True)}
            full, fparams = _with_main_spring(net, params, k)
            from .realise import Realisation

            err = _check(full, fparams, num, den, wr * check_points())
            if err < 1e-8:
                return Realisation(
                    "catalogue",
                    full,
                    fparams,
                    len(fparams),
                    err,
                    f"layout k | ({text})" if k else text,
                )
    raise RealisationError(
        f"no layout of the catalogue (<= {budget[0]} dampers, {budget[1]} inerters, "
        f"{budget[2]} springs besides k) fits" + _regularity_note(n0, d0)
    )


def _regularity_note(n0, d0) -> str:
    """Why no small layout can fit, when Y0 is a non-regular biquadratic."""
    from .positive_real import is_regular

    n0, d0 = np.trim_zeros(np.asarray(n0, float), "f"), np.trim_zeros(np.asarray(d0, float), "f")
    if len(n0) == 3 and len(d0) == 3 and not is_regular(n0, d0):
        return (
            "; Y0 is a biquadratic that is not regular, so no series-parallel network "
            "with two reactive elements realises it (Jiang & Smith 2011)"
        )
    return ""


def _with_main_spring(net, params, k):
    """Rename N's elements after adding the main spring k (names k, k1, ...)."""
    from .realise import _to_text

    def tree_of(node):
        if isinstance(node, Element):
            return ("e", _KIND[node.kind], params[node.name])
        return (node.op, [tree_of(p) for p in node.parts])

    return _to_text(tree_of(net.tree), k)
