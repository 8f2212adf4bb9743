"""Two-terminal mechanical networks written as text: parsing, admittance, enumeration.

Grammar (whitespace is ignored)::

    network := series ("|" series)*        parallel connection
    series  := factor ("-" factor)*         series connection
    factor  := NAME | "(" network ")"

so ``-`` binds tighter than ``|``: ``k | c - b`` is ``k | (c - b)``. Printed networks
always carry the parentheses, so nobody has to remember this.

Element names are a prefix of the element registry (:data:`inerterlab.elements.ELEMENTS`,
the only list of element names) and an optional suffix of digits or ``_word``: ``k``,
``c``, ``b`` (linear spring N/m, damper N s/m, inerter kg; admittances k/s, c, b s),
``fric``, ``afw``, ``gap``, ``hyd``, ``screw``, ``rect``, ``fluid`` and whatever is
registered later. Each element class declares its parameters with units and its
linearisation about rest (:meth:`~inerterlab.elements.ElementBase.rest_network`);
:func:`linearise` writes any network about rest with springs, dampers and inerters only,
which is what the admittance and the H2 analyses take.

Nesting is limited to :data:`MAX_NESTING` levels of parentheses, and messages quote at
most a short excerpt of a long text, with the position.

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

from .errors import NetworkError

__all__ = [
    "NetworkError",
    "Element",
    "Combination",
    "Network",
    "parse_network",
    "admittance",
    "admittance_coefficients",
    "enumerate_networks",
    "MAX_LAYOUTS",
    "same_family",
    "substitute",
    "linearise",
    "MAX_NESTING",
]

#: deepest nesting of parentheses a network text may have
MAX_NESTING = 100
_TOKEN_RE = re.compile(r"\s*(?:([A-Za-z][A-Za-z0-9_]*)|(\|)|(-)|(\()|(\)))")


def _short(text: str, pos: int | None = None, width: int = 60) -> str:
    """``text`` quoted, or an excerpt of about ``width`` characters around ``pos``."""
    if len(text) <= width:
        return repr(text)
    pos = 0 if pos is None else max(0, min(pos, len(text)))
    lo = max(0, pos - width // 2)
    hi = min(len(text), lo + width)
    lo = max(0, hi - width)
    return (
        ("..." if lo > 0 else "")
        + repr(text[lo:hi])
        + ("..." if hi < len(text) else "")
        + f" ({len(text)} characters)"
    )


# ---------------------------------------------------------------------------------------
# tree


@dataclass(frozen=True)
class Element:
    """One element: ``name`` as written, ``kind`` its registry prefix (``k``, ``fluid``)."""

    name: str
    kind: str

    @property
    def cls(self):
        """The element class of the registry."""
        from .elements import ELEMENTS

        return ELEMENTS[self.kind]

    @property
    def linear(self) -> bool:
        """A one-parameter linear element (spring, damper, inerter)."""
        return self.cls.ADMITTANCE is not None

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
    from .elements import element_class

    return Element(name, element_class(name).prefix)


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
            at = len(text) - len(text[pos:].lstrip())
            raise NetworkError(
                f"network {_short(text, at)}: unexpected character {text[at]!r} at "
                f"position {at + 1}; use names, '|' (parallel), '-' (series) and parentheses"
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
        self.depth = 0

    def peek(self) -> str | None:
        return self.toks[self.i][0] if self.i < len(self.toks) else None

    def fail(self, what: str) -> NetworkError:
        pos = len(self.text)
        if self.i < len(self.toks):
            _, val, pos = self.toks[self.i]
            shown = val if len(val) <= 40 else val[:37] + "..."
            where = f"{shown!r} at position {pos + 1}"
        else:
            where = "the end"
        return NetworkError(f"network {_short(self.text, pos)}: expected {what}, found {where}")

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
            self.depth += 1
            if self.depth > MAX_NESTING:
                pos = self.toks[self.i][2]
                raise NetworkError(
                    f"network {_short(self.text, pos)}: parentheses nested deeper than "
                    f"{MAX_NESTING} levels at position {pos + 1} (the nesting limit)"
                )
            self.i += 1
            node = self.network()
            self.depth -= 1
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
        """Springs, dampers and inerters only (one number each)."""
        return all(e.linear for e in self.tree.elements())

    def _units(self, name: str) -> str:
        return _element(name).cls.PARAMETERS[0].unit

    def require_linear(self) -> None:
        """Raise :class:`NetworkError` naming the first element that is not a spring,
        damper or inerter."""
        for e in self.tree.elements():
            if not e.linear:
                raise NetworkError(
                    f"network {_short(self.text)}: {e.name!r} ({e.cls.description}) is not a "
                    "spring, damper or inerter; this analysis needs its linearisation "
                    "about rest (inerterlab.networks.linearise)"
                )

    def parameter_vector(self, params: dict) -> np.ndarray:
        """Values of ``params`` in the order of :attr:`names`; each must be finite > 0."""
        self.require_linear()
        missing = [n for n in self.names if n not in params]
        if missing:
            raise NetworkError(
                f"network {_short(self.text)}: missing parameter(s) "
                + ", ".join(f"{n} [{self._units(n)}]" for n in missing)
            )
        extra = sorted(set(params) - set(self.names))
        if extra:
            raise NetworkError(
                f"network {_short(self.text)}: parameter(s) {', '.join(extra)} name no element "
                f"(elements: {', '.join(self.names)})"
            )
        out = np.empty(len(self.names))
        for i, n in enumerate(self.names):
            try:
                x = float(params[n])
            except (TypeError, ValueError):
                raise NetworkError(f"parameter {n}={params[n]!r}: not a number") from None
            if not np.isfinite(x) or x <= 0:
                cls = _element(n).cls
                raise NetworkError(
                    f"parameter {n}={params[n]!r} ({cls.description}): expected a finite "
                    f"number > 0 {self._units(n)} (drop the element from the network "
                    "instead of setting 0)"
                )
            out[i] = x
        return out

    def admittance(self, params: dict) -> tuple[np.ndarray, np.ndarray]:
        """Y(s) = num(s)/den(s), coefficients highest power first."""
        return admittance(self, params)

    def program(self) -> np.ndarray:
        """Post-order program of the tree for the compiled evaluator, rows (op, a, b).

        op 0: push element ``a`` (index into :attr:`names`) whose admittance is
        value * s**(b - 1) (b = 0 spring, 1 damper, 2 inerter); op 1: replace the top two
        entries by their parallel connection; op 2: by their series connection.
        """
        self.require_linear()
        rows: list[tuple[int, int, int]] = []

        def walk(node):
            if isinstance(node, Element):
                rows.append((0, self.names.index(node.name), node.cls.ADMITTANCE + 1))
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
    (('k', 'c', 'b', 'k2'), ('k', 'c', 'b', 'k'))
    >>> parse_network("k | c - b").text
    'k | (c - b)'
    """
    if isinstance(text, Network):
        return text
    if not isinstance(text, str) or not text.strip():
        shown = _short(text) if isinstance(text, str) else type(text).__name__
        raise NetworkError(f"network {shown}: empty; write e.g. 'k | c'")
    p = _Parser(text)
    tree = p.network()
    if p.i != len(p.toks):
        raise p.fail("'|', '-' or the end")
    elems = tree.elements()
    counts = Counter(e.name for e in elems)
    dup = [n for n, c in counts.items() if c > 1]
    if dup:
        shown = dup[0] if len(dup[0]) <= 40 else dup[0][:37] + "..."
        raise NetworkError(
            f"network {_short(text)}: element {shown!r} appears {counts[dup[0]]} times; "
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
    out = np.zeros(n, dtype=np.result_type(a, b))
    out[: len(a)] += a
    out[: len(b)] += b
    return out


def _adm_asc(node, values: dict) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(node, Element):  # value * s**p
        p = node.cls.ADMITTANCE
        lead = np.zeros(abs(p) + 1)
        lead[-1] = 1.0
        if p >= 0:
            return values[node.name] * lead, np.array([1.0])
        return np.array([values[node.name]]), lead
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
    return admittance_coefficients(net, dict(zip(net.names, vec, strict=True)))


def admittance_coefficients(network: str | Network, values: dict):
    """The polynomials of :func:`admittance` for element ``values`` taken as given (no
    check): any numeric type, so a complex value k + i h gives, in the imaginary parts
    over h, the derivatives of the coefficients in k (the complex step; the
    coefficients are polynomials in the values, so the step is exact to rounding)."""
    net = parse_network(network)
    num, den = _adm_asc(net.tree, values)
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
            return vals[node.name] * s ** node.cls.ADMITTANCE
        ys = [ev(p) for p in node.parts]
        if node.op == "|":
            return sum(ys)
        return 1.0 / sum(1.0 / y for y in ys)

    return ev(net.tree)


# ---------------------------------------------------------------------------------------
# elements from parameters; linearisation about rest


def elements_of(text: str | Network, params: dict | None) -> tuple[Any, dict]:
    """Parse ``text`` and build each element from ``params``.

    ``params`` maps an element name to a number (its first parameter), a dict of
    parameters or an element object; ``"name.parameter"`` keys set one parameter.
    Unknown names are an error naming them; missing values name the element.
    """
    from .elements import ElementBase
    from .errors import ParameterError

    net = parse_network(text)
    tree, names = net.tree, net.names
    grouped: dict[str, Any] = {}
    for key, value in dict(params or {}).items():
        base, _, sub = str(key).partition(".")
        if base not in names:
            raise ParameterError(
                str(key), value, f"a parameter of an element of {_short(net.text)} "
                f"({', '.join(names)})"
            )
        cur = grouped.get(base)
        first = _element(base).cls.PARAMETERS[0].name
        if sub:
            cur = {} if cur is None else dict(cur) if isinstance(cur, dict) else {first: cur}
            cur[sub] = value
            grouped[base] = cur
        elif isinstance(cur, dict) and not isinstance(value, dict | ElementBase):
            grouped[base] = {first: value, **cur}
        else:
            grouped[base] = value
    elements = {n: _element(n).cls.from_value(n, grouped.get(n)) for n in names}
    return tree, elements


_NAME_RE = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def substitute(tree, repl: dict) -> tuple[str, dict[str, float]] | None:
    """Replace every element of ``tree`` by a network of springs, dampers and inerters.

    ``repl`` maps an element name to (text over local names, {local name: value}) or
    ``None``, an open circuit (no force). A local name becomes ``<local>_<element>``,
    unless the replacement is one element of the element's own kind (a spring ``k2``
    stays ``k2``). An open circuit drops out of a parallel connection and opens a series
    one. Returns (text, values), or None if the whole network is open."""
    if isinstance(tree, Element):
        r = repl[tree.name]
        if r is None:
            return None
        text, vals = r
        if len(vals) == 1 and text.strip() in vals and _element(text.strip()).kind == tree.kind:
            return tree.name, {tree.name: next(iter(vals.values()))}
        ren = {k: f"{k}_{tree.name}" for k in vals}
        return (
            "(" + _NAME_RE.sub(lambda m: ren.get(m.group(0), m.group(0)), text) + ")",
            {ren[k]: v for k, v in vals.items()},
        )
    subs = [substitute(p, repl) for p in tree.parts]
    if tree.op == "-" and any(r is None for r in subs):
        return None
    subs = [r for r in subs if r is not None]
    if not subs:
        return None
    values: dict[str, float] = {}
    for _, v in subs:
        values.update(v)
    return "(" + f" {tree.op} ".join(t for t, _ in subs) + ")", values


def linearise(
    network: str | Network, params: dict | None = None, *, exact: bool = False
) -> tuple[Network, dict[str, float]]:
    """``network`` with ``params`` (as :func:`elements_of` takes them) written about rest
    with springs, dampers and inerters only: (Network, {name: value}).

    Every element contributes its :meth:`~inerterlab.elements.ElementBase.rest_network`
    (a composite, its parts'). With ``exact`` an element that is not linear for every
    motion is refused (NetworkError naming it) instead of being linearised.

    Examples
    --------
    >>> net, values = linearise("k | fric", {"k": 5e4, "fric": 20.0})
    >>> net.text, values
    ('k | c_fric', {'k': 50000.0, 'c_fric': 20000.0})
    """
    tree, els = elements_of(network, params)
    text = tree.text()
    if exact:
        for name, el in els.items():
            if not el.is_linear:
                raise NetworkError(
                    f"network {_short(text)}: {name!r} ({el.description}) is not linear with "
                    "these parameters; this analysis needs springs, linear dampers and ideal "
                    "inerters (or the linearisation about rest)"
                )
    r = substitute(tree, {n: el.rest_network() for n, el in els.items()})
    if r is None:
        raise NetworkError(
            f"network {_short(text)}: carries no force for small motions about rest (every "
            "path between its terminals holds an open element, such as a gap with free play)"
        )
    return parse_network(r[0]), r[1]


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


#: default limit of candidate layouts of one budget (``max_layouts``, the command line's
#: --max-layouts): the default budget has 19 candidates, (2, 1, 2) has 93
MAX_LAYOUTS = 100


def enumerate_networks(
    dampers: int = 1,
    inerters: int = 1,
    springs: int = 2,
    *,
    main_spring: bool = True,
    merge_equivalent: bool = True,
    max_layouts: int = MAX_LAYOUTS,
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
    The work is bounded before it starts: a budget with more than ``max_layouts``
    candidate layouts (:func:`inerterlab.network_design.count_layouts`, counted without
    building them; :data:`MAX_LAYOUTS` by default) or
    whose trees would not fit in memory is refused with a :class:`ParameterError`;
    raise ``max_layouts`` to run a larger budget on purpose.

    >>> [n.text for n in enumerate_networks(1, 1, 0)]
    ['k | c', 'k | b', 'k | (c - b)', 'k | c | b']
    """
    from .network_design import check_budget

    check_budget(dampers, inerters, springs, max_layouts)
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
