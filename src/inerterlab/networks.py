"""Two-terminal mechanical networks written as text: parsing, admittance, enumeration.

Grammar (whitespace is ignored)::

    network := series ("|" series)*        parallel connection
    series  := factor ("-" factor)*         series connection
    factor  := NAME | "(" network ")"

so ``-`` binds tighter than ``|``: ``k | c - b`` is ``k | (c - b)``. Printed networks
always carry the parentheses, so nobody has to remember this.

Element names are a type prefix and an optional suffix of digits or ``_word``:

=========  =====================  ==============  ===============
prefix     element                parameter       admittance Y(s)
=========  =====================  ==============  ===============
``k``      linear spring          stiffness N/m   k / s
``c``      linear damper          damping N s/m   c
``b``      ideal inerter          inertance kg    b s
=========  =====================  ==============  ===============

The prefixes ``afw``, ``hyd``, ``screw``, ``rect`` and ``fluid`` name nonlinear devices
(adaptive flywheel, hydraulic, screw, rectifier, fluid inerters). They parse into the
tree so a layout can be written down, but any linear analysis refuses them: it needs a
linearisation first.

The admittance (force per unit relative velocity, Laplace domain) of a tree is a ratio
of polynomials, built exactly: parallel branches add admittances, series branches add
impedances 1/Y. Common factors of s (two springs in parallel, two inerters in series)
are cancelled, so for generic parameters the degree of the denominator is the number of
independent energy stores of the network (its McMillan degree). Coefficients are
returned highest power first, as :func:`numpy.polyval` takes them.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from .errors import InerterlabError

__all__ = [
    "NetworkError",
    "Element",
    "Combination",
    "Network",
    "parse_network",
    "admittance",
    "enumerate_networks",
    "same_family",
    "LINEAR_KINDS",
    "NONLINEAR_PREFIXES",
]

LINEAR_KINDS = {"k": "spring", "c": "damper", "b": "inerter"}
UNITS = {"spring": "N/m", "damper": "N s/m", "inerter": "kg"}
NONLINEAR_PREFIXES = {
    "afw": "adaptive-flywheel inerter",
    "hyd": "hydraulic inerter",
    "screw": "ball-screw inerter",
    "rect": "rectifying inerter",
    "fluid": "fluid inerter",
}
_SUFFIX = r"(?:\d*|_[A-Za-z0-9_]+)"
_NONLINEAR_RE = re.compile(rf"^({'|'.join(NONLINEAR_PREFIXES)}){_SUFFIX}$")
_LINEAR_RE = re.compile(rf"^([kcb]){_SUFFIX}$")
_TOKEN_RE = re.compile(r"\s*(?:([A-Za-z][A-Za-z0-9_]*)|(\|)|(-)|(\()|(\)))")


class NetworkError(InerterlabError, ValueError):
    """A network text, or the parameters given for it, cannot be used."""


# ---------------------------------------------------------------------------------------
# tree


@dataclass(frozen=True)
class Element:
    """One element: ``name`` as written, ``kind`` spring/damper/inerter or a device."""

    name: str
    kind: str

    @property
    def linear(self) -> bool:
        return self.kind in UNITS

    def text(self) -> str:
        return self.name

    def elements(self) -> list[Element]:
        return [self]


@dataclass(frozen=True)
class Combination:
    """Series (``op == "-"``) or parallel (``op == "|"``) connection of two or more parts."""

    op: str
    parts: tuple

    def text(self) -> str:
        inner = f" {self.op} ".join(
            p.text() if isinstance(p, Element) else f"({p.text()})" for p in self.parts
        )
        return inner

    def elements(self) -> list[Element]:
        return [e for p in self.parts for e in p.elements()]


def _element(name: str) -> Element:
    m = _NONLINEAR_RE.match(name)
    if m:
        return Element(name, NONLINEAR_PREFIXES[m.group(1)])
    m = _LINEAR_RE.match(name)
    if m:
        return Element(name, LINEAR_KINDS[m.group(1)])
    raise NetworkError(
        f"unknown element name {name!r}: expected k..., c..., b... (spring, damper, "
        f"inerter; e.g. k2, c_front) or a nonlinear device {', '.join(NONLINEAR_PREFIXES)}"
    )


def _combine(op: str, parts: list) -> Any:
    flat: list = []
    for p in parts:  # associativity: (a - b) - c is a - b - c
        if isinstance(p, Combination) and p.op == op:
            flat.extend(p.parts)
        else:
            flat.append(p)
    return flat[0] if len(flat) == 1 else Combination(op, tuple(flat))


def _tokens(text: str) -> list[tuple[str, str, int]]:
    out, pos = [], 0
    text = text.rstrip()
    while pos < len(text):
        m = _TOKEN_RE.match(text, pos)
        if not m or m.end() == pos:
            raise NetworkError(
                f"network {text!r}: unexpected character {text[pos:].lstrip()[:1]!r} at "
                f"position {pos + 1}; use names, '|' (parallel), '-' (series) and parentheses"
            )
        kinds = ("name", "|", "-", "(", ")")
        for kind, g in zip(kinds, m.groups(), strict=True):
            if g is not None:
                out.append((kind, g, m.start(m.lastindex)))
        pos = m.end()
    return out


class _Parser:
    def __init__(self, text: str):
        self.text = text
        self.toks = _tokens(text)
        self.i = 0

    def peek(self) -> str | None:
        return self.toks[self.i][0] if self.i < len(self.toks) else None

    def fail(self, what: str) -> NetworkError:
        if self.i < len(self.toks):
            _, val, pos = self.toks[self.i]
            where = f"{val!r} at position {pos + 1}"
        else:
            where = "the end"
        return NetworkError(f"network {self.text!r}: expected {what}, found {where}")

    def network(self) -> Any:
        parts = [self.series()]
        while self.peek() == "|":
            self.i += 1
            parts.append(self.series())
        return _combine("|", parts)

    def series(self) -> Any:
        parts = [self.factor()]
        while self.peek() == "-":
            self.i += 1
            parts.append(self.factor())
        return _combine("-", parts)

    def factor(self) -> Any:
        kind = self.peek()
        if kind == "name":
            name = self.toks[self.i][1]
            self.i += 1
            return _element(name)
        if kind == "(":
            self.i += 1
            node = self.network()
            if self.peek() != ")":
                raise self.fail("')'")
            self.i += 1
            return node
        raise self.fail("an element name or '('")


@dataclass(frozen=True)
class Network:
    """A parsed network: the tree and its parameter names in order of appearance."""

    tree: Any
    names: tuple[str, ...]
    kinds: tuple[str, ...]

    @property
    def text(self) -> str:
        return self.tree.text()

    def __str__(self) -> str:
        return self.text

    @property
    def is_linear(self) -> bool:
        return all(k in UNITS for k in self.kinds)

    def require_linear(self) -> None:
        """Raise :class:`NetworkError` naming the first nonlinear element."""
        for n, k in zip(self.names, self.kinds, strict=True):
            if k not in UNITS:
                raise NetworkError(
                    f"network {self.text!r}: {n!r} is a nonlinear element ({k}); "
                    "linear analysis needs a linearisation (replace it by an equivalent "
                    "spring, damper and inerter, e.g. b for its inertance)"
                )

    def parameter_vector(self, params: dict) -> np.ndarray:
        """Values of ``params`` in the order of :attr:`names`; each must be finite > 0."""
        self.require_linear()
        missing = [n for n in self.names if n not in params]
        if missing:
            raise NetworkError(
                f"network {self.text!r}: missing parameter(s) "
                + ", ".join(f"{n} [{UNITS[self.kinds[self.names.index(n)]]}]" for n in missing)
            )
        extra = sorted(set(params) - set(self.names))
        if extra:
            raise NetworkError(
                f"network {self.text!r}: parameter(s) {', '.join(extra)} name no element "
                f"(elements: {', '.join(self.names)})"
            )
        out = np.empty(len(self.names))
        for i, (n, k) in enumerate(zip(self.names, self.kinds, strict=True)):
            try:
                x = float(params[n])
            except (TypeError, ValueError):
                raise NetworkError(f"parameter {n}={params[n]!r}: not a number") from None
            if not np.isfinite(x) or x <= 0:
                raise NetworkError(
                    f"parameter {n}={params[n]!r} ({k}): expected a finite number > 0 "
                    f"{UNITS[k]} (drop the element from the network instead of setting 0)"
                )
            out[i] = x
        return out

    def admittance(self, params: dict) -> tuple[np.ndarray, np.ndarray]:
        """Y(s) = num(s)/den(s), coefficients highest power first."""
        return admittance(self, params)

    def program(self) -> np.ndarray:
        """Post-order program of the tree for the compiled evaluator, rows (op, a, b).

        op 0: push element ``a`` (index into :attr:`names`) of kind ``b`` (0 spring,
        1 damper, 2 inerter); op 1: replace the top two entries by their parallel
        connection; op 2: by their series connection.
        """
        self.require_linear()
        rows: list[tuple[int, int, int]] = []
        code = {"spring": 0, "damper": 1, "inerter": 2}

        def walk(node):
            if isinstance(node, Element):
                rows.append((0, self.names.index(node.name), code[node.kind]))
                return
            walk(node.parts[0])
            for p in node.parts[1:]:
                walk(p)
                rows.append((1 if node.op == "|" else 2, 0, 0))

        walk(self.tree)
        return np.array(rows, dtype=np.int64)


def parse_network(text: str | Network) -> Network:
    """Parse a network text.

    Examples
    --------
    >>> n = parse_network("k | (c - b) | k2")
    >>> n.names, n.kinds
    (('k', 'c', 'b', 'k2'), ('spring', 'damper', 'inerter', 'spring'))
    >>> parse_network("k | c - b").text
    'k | (c - b)'
    """
    if isinstance(text, Network):
        return text
    if not isinstance(text, str) or not text.strip():
        raise NetworkError(f"network {text!r}: empty; write e.g. 'k | c'")
    p = _Parser(text)
    tree = p.network()
    if p.i != len(p.toks):
        raise p.fail("'|', '-' or the end")
    elems = tree.elements()
    counts = Counter(e.name for e in elems)
    dup = [n for n, c in counts.items() if c > 1]
    if dup:
        raise NetworkError(
            f"network {text!r}: element {dup[0]!r} appears {counts[dup[0]]} times; "
            "give every element its own name (k, k2, ...)"
        )
    return Network(tree, tuple(e.name for e in elems), tuple(e.kind for e in elems))


# ---------------------------------------------------------------------------------------
# admittance (reference implementation in numpy; the compiled one is in
# suspension/network_linear.py and is tested against this one)


def _strip_s(num: np.ndarray, den: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    # ascending coefficients: cancel common factors s (exact zeros from products by 0)
    while len(num) > 1 and len(den) > 1 and num[0] == 0.0 and den[0] == 0.0:
        num, den = num[1:], den[1:]
    return num, den


def _padd(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    n = max(len(a), len(b))
    out = np.zeros(n)
    out[: len(a)] += a
    out[: len(b)] += b
    return out


def _adm_asc(node, values: dict) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(node, Element):
        x = values[node.name]
        if node.kind == "spring":
            return np.array([x]), np.array([0.0, 1.0])
        if node.kind == "damper":
            return np.array([x]), np.array([1.0])
        return np.array([0.0, x]), np.array([1.0])
    num, den = _adm_asc(node.parts[0], values)
    for part in node.parts[1:]:
        n2, d2 = _adm_asc(part, values)
        if node.op == "|":  # N1/D1 + N2/D2
            num, den = _padd(np.convolve(num, d2), np.convolve(n2, den)), np.convolve(den, d2)
        else:  # 1 / (D1/N1 + D2/N2)
            num, den = np.convolve(num, n2), _padd(np.convolve(den, n2), np.convolve(d2, num))
        num, den = _strip_s(num, den)
    return num, den


def admittance(network: str | Network, params: dict) -> tuple[np.ndarray, np.ndarray]:
    """Admittance Y(s) = num(s)/den(s) of a linear network, highest power first.

    Examples
    --------
    >>> num, den = admittance("k | c", {"k": 4.0, "c": 3.0})
    >>> num.tolist(), den.tolist()  # (3 s + 4) / s
    ([3.0, 4.0], [1.0, 0.0])
    >>> num, den = admittance("k - c", {"k": 4.0, "c": 2.0})
    >>> num.tolist(), den.tolist()  # 8 / (2 s + 4)
    ([8.0], [2.0, 4.0])
    """
    net = parse_network(network)
    vec = net.parameter_vector(params)
    num, den = _adm_asc(net.tree, dict(zip(net.names, vec, strict=True)))
    num = np.trim_zeros(num, "b") if np.any(num) else np.zeros(1)
    den = np.trim_zeros(den, "b")
    return num[::-1].copy(), den[::-1].copy()


def admittance_at(network: str | Network, params: dict, s: Any) -> np.ndarray:
    """Y(s) evaluated directly on the tree with complex arithmetic (no polynomials)."""
    net = parse_network(network)
    vals = dict(zip(net.names, net.parameter_vector(params), strict=True))
    s = np.asarray(s, dtype=complex)

    def ev(node):
        if isinstance(node, Element):
            x = vals[node.name]
            return {"spring": x / s, "damper": x + 0 * s, "inerter": x * s}[node.kind]
        ys = [ev(p) for p in node.parts]
        if node.op == "|":
            return sum(ys)
        return 1.0 / sum(1.0 / y for y in ys)

    return ev(net.tree)


# ---------------------------------------------------------------------------------------
# enumeration


def _canon(node) -> tuple:
    """Canonical key: type letters only, children sorted, associativity flattened."""
    if isinstance(node, str):
        return ("e", node)
    op, parts = node
    keys = []
    for p in parts:
        kp = _canon(p)
        if kp[0] == op:
            keys.extend(kp[1])
        else:
            keys.append(kp)
    return (op, tuple(sorted(keys, key=_sort_key)))


def _sort_key(key: tuple) -> tuple:
    order = {"k": 0, "c": 1, "b": 2}
    if key[0] == "e":
        return (0, order[key[1]], "")
    return (1, 0, repr(key))


@cache
def _trees(nk: int, nc: int, nb: int) -> frozenset:
    """Canonical keys of every series-parallel tree with exactly these element counts."""
    total = nk + nc + nb
    if total == 1:
        return frozenset([("e", "k" if nk else "c" if nc else "b")])
    out = set()
    for k1 in range(nk + 1):
        for c1 in range(nc + 1):
            for b1 in range(nb + 1):
                n1 = k1 + c1 + b1
                if n1 == 0 or n1 == total:
                    continue
                for t1 in _trees(k1, c1, b1):
                    for t2 in _trees(nk - k1, nc - c1, nb - b1):
                        for op in ("|", "-"):
                            out.add(_canon((op, (_untag(t1), _untag(t2)))))
    return frozenset(out)


def _untag(key: tuple):
    return key[1] if key[0] == "e" else (key[0], tuple(_untag(k) for k in key[1]))


def _static_path(key: tuple) -> bool:
    """True if springs alone connect the two terminals (Y(s) has a pole at s = 0)."""
    if key[0] == "e":
        return key[1] == "k"
    paths = [_static_path(k) for k in key[1]]
    return any(paths) if key[0] == "|" else all(paths)


def _degenerate(key: tuple, top: bool) -> bool:
    """Two elements of one type side by side, or (top) a static stiffness of its own."""
    if top and _static_path(key):
        return True
    if key[0] == "e":
        return False
    leaves = Counter(k[1] for k in key[1] if k[0] == "e")
    if any(c > 1 for c in leaves.values()):
        return True
    return any(_degenerate(k, False) for k in key[1])


def _key_text(key: tuple, counter: dict, totals: dict) -> str:
    if key[0] == "e":
        t = key[1]
        counter[t] += 1
        if t == "k":
            return f"k{counter[t]}"
        return t if totals[t] == 1 else f"{t}{counter[t]}"
    parts = [_key_text(k, counter, totals) for k in key[1]]
    parts = [p if k[0] == "e" else f"({p})" for p, k in zip(parts, key[1], strict=True)]
    return f" {key[0]} ".join(parts)


def _count(key: tuple) -> Counter:
    if key[0] == "e":
        return Counter(key[1])
    c: Counter = Counter()
    for k in key[1]:
        c += _count(k)
    return c


def enumerate_networks(
    dampers: int = 1,
    inerters: int = 1,
    springs: int = 2,
    *,
    main_spring: bool = True,
    merge_equivalent: bool = True,
) -> list[Network]:
    """Every distinct series-parallel network within a budget of elements.

    Convention: the budget counts the elements of a sub-network N with at most
    ``springs`` springs, ``dampers`` dampers and ``inerters`` inerters (at least one
    element), and the listed network is ``k | (N)``: a main spring ``k`` in parallel
    with the whole, as in the suspension layouts of Smith and Wang (2004). Extra
    springs are named k1, k2, ...; dampers and inerters c, b (c1, c2, ... if more).

    The main spring alone sets the static stiffness: N must not join the terminals by
    springs alone (no pole of its admittance at s = 0), so every listed network has the
    static stiffness k, which the optimiser holds fixed. This also removes a spring
    directly in parallel with ``k``.

    Networks are kept once up to commutativity and associativity (children sorted,
    nested connections of the same kind flattened) and degenerate ones are removed:
    two springs, two dampers or two inerters connected directly in series or in
    parallel (they act as one element of the same kind). With ``main_spring=False``
    the sub-networks N themselves are listed (then without the static rule).

    With ``merge_equivalent`` (default) sub-networks N that realise the same family of
    admittances in different structures are kept once (the first in the listed order),
    by the numerical test of :func:`same_family`; e.g. ``b - (k1 | (k2 - c))`` and
    ``k1 - b - (k2 | c)`` are one family, because ``k1 | (k2 - c)`` and
    ``k1 - (k2 | c)`` are (the two forms of the standard linear solid). Since the main
    spring is common to all, equal families of N give equal families of k | (N).

    Examples
    --------
    >>> [n.text for n in enumerate_networks(1, 1, 0)]
    ['k | c', 'k | b', 'k | (c - b)', 'k | c | b']
    """
    for nm, v in (("dampers", dampers), ("inerters", inerters), ("springs", springs)):
        if not isinstance(v, int | np.integer) or v < 0 or v > 4:
            raise NetworkError(f"invalid {nm}={v!r}: expected an integer 0-4")
    keys: list[tuple] = []
    for total in range(1, springs + dampers + inerters + 1):
        level = []
        for nk in range(springs + 1):
            for nc in range(dampers + 1):
                nb = total - nk - nc
                if 0 <= nb <= inerters:
                    level.extend(k for k in _trees(nk, nc, nb) if not _degenerate(k, main_spring))
        keys.extend(sorted(level, key=_sort_key))
    subs = [parse_network(_key_text(key, Counter(), _count(key))) for key in keys]
    if merge_equivalent:
        subs = _merge_families(subs)
    out = []
    for sub in subs:
        text = sub.text
        if main_spring:
            op = sub.tree.op if isinstance(sub.tree, Combination) else ""
            text = "k | " + (f"({text})" if op == "-" else text)
        out.append(parse_network(text))
    return out


# ---------------------------------------------------------------------------------------
# equal admittance families


_PROGRAMS: dict[str, np.ndarray] = {}


def _normalised(net: Network, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ascending coefficients of Y with a monic denominator (compiled assembly)."""
    from .suspension.network_linear import MAXC, _assemble

    prog = _PROGRAMS.get(net.text)
    if prog is None:
        prog = _PROGRAMS[net.text] = net.program()
    num, den = np.zeros(MAXC), np.zeros(MAXC)
    ln, ld = _assemble(prog, np.asarray(theta, dtype=float), num, den)
    lead = den[ld - 1]
    return num[:ln] / lead, den[:ld] / lead


def _signature(net: Network) -> tuple:
    """Degrees, structural zeros and dimension of the family (rank of its Jacobian)."""
    rng = np.random.default_rng(7)
    u = rng.uniform(-1, 1, len(net.names))
    num, den = _normalised(net, np.exp(u))
    base = np.concatenate([num, den])
    jac = np.empty((len(base), len(u)))
    for i in range(len(u)):
        up = u.copy()
        up[i] += 1e-6
        jac[:, i] = (np.concatenate(_normalised(net, np.exp(up))) - base) / 1e-6
    sv = np.linalg.svd(jac, compute_uv=False)
    rank = int(np.sum(sv > 1e-6 * sv[0])) if len(sv) else 0
    counts = tuple(sorted(Counter(net.kinds).items()))
    return (counts, len(num), len(den), tuple(num == 0), tuple(den == 0), rank)


def _covers(a: Network, b: Network, rng, samples: int = 2, tries: int = 4) -> bool:
    """True if every sampled admittance of ``a`` is matched by some parameters of ``b``."""
    from scipy.optimize import least_squares

    for _ in range(samples):
        na, da = _normalised(a, np.exp(rng.uniform(-1.0, 1.0, len(a.names))))
        target = np.concatenate([na, da])
        mask = target != 0.0
        scale = np.abs(target[mask])

        def res(u, mask=mask, target=target, scale=scale):
            with np.errstate(all="ignore"):
                nb_, db_ = _normalised(b, np.exp(np.clip(u, -40.0, 40.0)))
                got = np.concatenate([nb_, db_])
            if got.shape != target.shape or not np.all(np.isfinite(got)):
                return np.full(int(mask.sum()), 1e6)
            return (got[mask] - target[mask]) / scale

        ok = False
        for _t in range(tries):
            r = least_squares(
                res,
                rng.uniform(-2.0, 2.0, len(b.names)),
                xtol=1e-15,
                ftol=1e-15,
                gtol=1e-15,
                max_nfev=200,
            )
            if np.max(np.abs(r.fun)) < 1e-8:
                ok = True
                break
        if not ok:
            return False
    return True


def same_family(a: str | Network, b: str | Network, seed: int = 0) -> bool:
    """True if two linear networks realise the same set of admittances.

    Numerical test: the two networks must have the same numbers of springs, dampers
    and inerters (a limitation: equal families with different element counts are not
    sought), their admittances the same degrees, structural zero
    coefficients and family dimension (rank of the Jacobian of the normalised
    coefficients in the log-parameters), and random admittances of each (parameters log-uniform over a factor
    e^2) must be matched exactly (to 1e-8 in every normalised coefficient) by some
    parameters of the other, found by least squares from several starts. A failed fit
    reads as "different", so the test can keep two equal families apart but does not
    merge different ones unless a fit succeeds.

    Examples
    --------
    >>> same_family("k1 - (k2 | c)", "k1 | (k2 - c)")  # the two standard-solid forms
    True
    >>> same_family("k1 - c", "k1 | c")
    False
    """
    a, b = parse_network(a), parse_network(b)
    a.require_linear()
    b.require_linear()
    if _signature(a) != _signature(b):
        return False
    rng = np.random.default_rng(seed)
    return _covers(a, b, rng) and _covers(b, a, rng)


def _merge_families(nets: list[Network]) -> list[Network]:
    reps: dict[tuple, list[Network]] = {}
    out = []
    for n in nets:
        group = reps.setdefault(_signature(n), [])
        if any(same_family(r, n) for r in group):
            continue
        group.append(n)
        out.append(n)
    return out
