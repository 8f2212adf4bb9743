"""Minimal series-parallel realisation from the enumerated catalogue of layouts, and
the structural catalogue of small networks (series-parallel and bridges).

The catalogue is :func:`inerterlab.networks.enumerate_networks` (every layout ``k | (N)``
of a budget, without the numerical family merge, which only removes duplicates),
tried in order of the number of elements of N. A layout fits when its parameters can
be chosen so that its admittance equals the target's coefficient by coefficient
(nonlinear least squares in the logarithms of the element values from several
starts, on the frequency-normalised target); the first layout that fits to a
relative 1e-10 is minimal within the catalogue. Layouts whose generic degrees or
structural zeros differ from the target's are skipped before fitting.

:func:`structural_catalogue` lists every two-terminal network of at most five elements
with at most a given number of reactive elements (springs and inerters), series-parallel
or bridge, once up to reordering (docs/model.md §13, "Counts"); with the defaults it is
the starting list of Ladenheim's catalogue (148 networks).
"""

from __future__ import annotations

import itertools
from collections import Counter
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..networks import MAX_LAYOUTS, Element, admittance, enumerate_networks, parse_network

__all__ = ["fit_catalogue", "catalogue_layouts", "structural_catalogue", "Bridge", "OnePort"]

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


def _pattern(num, den, rel=1e-9):
    # A coefficient below ``rel`` of the largest is a structural zero: removing the main
    # spring cancels terms of about 1e4 to a remainder of 1e-9 or less, whose size is
    # set by the rounding of the optimiser's products (2e-12 relative under numpy 2.4),
    # not by the admittance.
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
            params = {
                n: vals[n] * scale_of[_KIND[kind]] for n, kind in zip(names, net.kinds, strict=True)
            }
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


# ---------------------------------------------------------------------------------------
# the structural catalogue: every network of at most five elements, SP or bridge

#: the Wheatstone bridge's arms (terminals a, b; inner nodes c, d): a-c, a-d, c-b, d-b,
#: and the bridging arm c-d
BRIDGE_ARMS = (("a", "c"), ("a", "d"), ("c", "b"), ("d", "b"), ("c", "d"))
#: its symmetries that keep the terminal pair (arm permutations): identity, c <-> d,
#: a <-> b, both
_BRIDGE_SYMMETRIES = ((0, 1, 2, 3, 4), (1, 0, 3, 2, 4), (2, 3, 0, 1, 4), (3, 2, 1, 0, 4))
_PREFIX = {"spring": "k", "damper": "c", "inerter": "b"}


@dataclass(frozen=True)
class Bridge:
    """A five-element bridge network (not series-parallel): one element per arm of
    :data:`BRIDGE_ARMS`, ``kinds`` in the network grammar's letters (k, c, b)."""

    kinds: tuple[str, str, str, str, str]

    @property
    def names(self) -> list[str]:
        """Element names k, k1, ..., c, c1, ..., b, b1, ... in arm order."""
        total = Counter(self.kinds)
        seen: Counter = Counter()
        out = []
        for k in self.kinds:
            if k == "k":  # extra springs are k1, k2, ... as in the enumeration
                out.append(f"k{seen[k] + 1}")
            else:
                out.append(k if total[k] == 1 else f"{k}{seen[k] + 1}")
            seen[k] += 1
        return out

    @property
    def text(self) -> str:
        arms = [f"{n}:{x}-{y}" for n, (x, y) in zip(self.names, BRIDGE_ARMS, strict=True)]
        return "bridge(" + ", ".join(arms) + ")"

    def admittance_at(self, values: dict, s) -> np.ndarray:
        """Admittance F/v between the terminals a and b at the points ``s`` (nodal
        analysis: unit velocity at a, b held, forces balanced at c and d)."""
        s = np.atleast_1d(np.asarray(s, complex))
        ys = []
        for name, kind in zip(self.names, self.kinds, strict=True):
            x = float(values[name])
            ys.append({"k": x / s, "c": x + 0 * s, "b": x * s}[kind])
        y_ac, y_ad, y_cb, y_db, y_cd = ys
        # unknown velocities of c and d with v_a = 1, v_b = 0
        a11 = y_ac + y_cb + y_cd
        a22 = y_ad + y_db + y_cd
        a12 = -y_cd
        det = a11 * a22 - a12 * a12
        vc = (y_ac * a22 - a12 * y_ad) / det
        vd = (a11 * y_ad - a12 * y_ac) / det
        return y_ac * (1 - vc) + y_ad * (1 - vd)


@dataclass(frozen=True)
class OnePort:
    """One network of :func:`structural_catalogue`: ``text`` is a network text for a
    series-parallel network, ``bridge`` is set for a bridge."""

    text: str
    springs: int
    dampers: int
    inerters: int
    bridge: Bridge | None = None

    @property
    def elements(self) -> int:
        return self.springs + self.dampers + self.inerters

    @property
    def reactive(self) -> int:
        return self.springs + self.inerters


def structural_catalogue(max_elements: int = 5, max_reactive: int = 2) -> list[OnePort]:
    """Every two-terminal network of springs, dampers and inerters with at most
    ``max_elements`` elements of which at most ``max_reactive`` are springs or inerters.

    Counted once up to reordering: series-parallel networks up to the order of the
    parts of each series or parallel connection (the tool's enumeration,
    :func:`inerterlab.networks.enumerate_networks` without a main spring and without
    the numerical family merge), bridges up to their symmetries. Networks with a part
    made of one kind of element only are left out, since that part is one element: two
    elements of one kind directly in series or in parallel, and a bridge of five
    elements of one kind. Series-parallel networks come first (fewest elements first),
    then the bridges. Under the force-current analogy (spring = inductor, damper =
    resistor, inerter = capacitor; series and parallel keep their meaning) the defaults
    give the 148 networks of Ladenheim's starting list (docs/model.md §13).
    """
    if not (isinstance(max_elements, int) and 1 <= max_elements <= 5):
        raise ParameterError(
            "max_elements", max_elements, "an integer 1-5 (larger needs more bridge graphs)"
        )
    if not (isinstance(max_reactive, int) and 0 <= max_reactive <= max_elements):
        raise ParameterError("max_reactive", max_reactive, f"an integer 0-{max_elements}")
    found: dict[str, OnePort] = {}
    for springs in range(max_reactive + 1):
        for inerters in range(max_reactive + 1 - springs):
            # the enumeration takes at most four of a kind; five dampers in series-parallel
            # are always one damper, which four already list
            dampers = min(4, max_elements - springs - inerters)
            if dampers < 0 or springs > 4 or inerters > 4:
                continue
            for net in enumerate_networks(
                dampers, inerters, springs, main_spring=False, merge_equivalent=False,
                max_layouts=10**6,
            ):  # fmt: skip
                kinds = Counter(net.kinds)
                if len(net.names) <= max_elements and kinds["k"] + kinds["b"] <= max_reactive:
                    found[net.text] = OnePort(net.text, kinds["k"], kinds["c"], kinds["b"])
    out = sorted(found.values(), key=lambda o: (o.elements, o.reactive))
    if max_elements == 5:
        seen = set()
        for kinds in itertools.product("kcb", repeat=5):
            if sum(k != "c" for k in kinds) > max_reactive or len(set(kinds)) == 1:
                continue
            key = min(tuple(kinds[i] for i in perm) for perm in _BRIDGE_SYMMETRIES)
            if key in seen:
                continue
            seen.add(key)
            br = Bridge(key)  # type: ignore[arg-type]
            c = Counter(key)
            out.append(OnePort(br.text, c["k"], c["c"], c["b"], br))
    return out
