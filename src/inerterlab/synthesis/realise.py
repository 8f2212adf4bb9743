"""Realisation: from a positive-real admittance to a network of springs, dampers, inerters.

Mechanical admittance Y = F/v with the force-current analogy: a spring k is an
inductor 1/k, a damper c a conductance c, an inerter b a capacitor b; series and
parallel connections keep their meaning, so the classical electrical procedures apply
to Y (admittance) and Z = 1/Y (impedance) unchanged. Methods:

* ``foster``: partial fractions of Y (branches in parallel) or of Z (units in series),
  of the function itself or divided by s; applies when Y is lossless (springs and
  inerters) or has two kinds of element (k-c or c-b networks): Foster 1924, Cauer
  1926; see Guillemin 1957, ch. 2-4.
* ``cauer``: ladder from the continued fraction about s = infinity (Cauer I) or
  s = 0 (Cauer II), same classes.
* ``catalogue``: the series-parallel layouts of :func:`inerterlab.networks.enumerate_networks`
  (fewest elements first) whose parameters can be fitted exactly to the target's
  coefficients; the first that fits is minimal within the catalogue.
* ``bott-duffin``: any PR function: remove imaginary-axis poles and zeros (Foster
  preamble), the minimum real part (a damper), and on a minimum function apply
  Richards' theorem as Bott & Duffin (1949) did: with Z(j w0) = j X, X > 0, pick k > 0
  with Z(k) = k X / w0 and R(s) = (k Z(s) - s Z(k)) / (k Z(k) - s Z(s)), then
  Z = [Z(k) R || k Z(k)/s] + [Z(k)/R || s Z(k)/k], where R has a zero at j w0 that
  the preamble removes; no transformer is needed.
* ``brune``: Brune (1931) cycle on a minimum function: series L1 = X/w0, a shunt L2-C2
  branch and a series L3 with L1 L2 + L2 L3 + L3 L1 = 0 (one of the three negative):
  realisable only with a perfectly coupled transformer, a lever in mechanics, which the
  network grammar lacks; the element values are reported, without network text.

Every realisation is checked: its admittance (:func:`inerterlab.networks.admittance_at`
on the network text; the Brune sections by their own two-port formula) against the
target at points on and off the imaginary axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..networks import NetworkError, admittance_at, parse_network

__all__ = [
    "Realisation",
    "realise",
    "realise_all",
    "METHODS",
    "check_points",
    "brune",
    "bott_duffin",
]

METHODS = ("foster", "cauer", "catalogue", "bott-duffin", "brune")
_EPS = 1e-10  # relative tolerance for "zero" in the numerical steps


class RealisationError(NetworkError):
    """The method does not apply to this function."""


# ---------------------------------------------------------------------------------------
# polynomial helpers (highest power first)


def _trim(p, rel=1e-13):
    p = np.asarray(p, float)
    if p.size == 0:
        return np.zeros(1)
    big = np.max(np.abs(p)) if p.size else 0.0
    if big == 0:
        return np.zeros(1)
    i = 0
    while i < len(p) - 1 and abs(p[i]) <= rel * big:
        i += 1
    return p[i:].copy()


def _deg(p) -> int:
    return len(_trim(p)) - 1


def _is_zero(p, scale) -> bool:
    return bool(np.max(np.abs(p)) <= _EPS * scale)


def _ev(p, q, s):
    return np.polyval(p, s) / np.polyval(q, s)


def _divide_exact(p, f):
    """p / f where f divides p up to rounding (the remainder is dropped)."""
    q, _ = np.polydiv(p, f)
    return _trim(q)


def check_points() -> np.ndarray:
    """Test points: on the imaginary axis and off it (normalised frequency units)."""
    w = np.array([0.0537, 0.317, 1.093, 2.71, 8.93, 37.3])
    return np.concatenate([1j * w, 0.41 + 1j * w, 2.03 - 0.5j * w, [0.71, 3.07]])


# ---------------------------------------------------------------------------------------
# networks as trees: ("e", kind, value) | (op, [parts]) with op "|" or "-"


def _elem(kind: str, value: float):
    if not (math.isfinite(value) and value > 0):
        raise RealisationError(f"negative or zero {kind} ({value:.6g})")
    return ("e", kind, float(value))


def _join(op, parts):
    flat = []
    for p in parts:
        if p is None:
            continue
        if p[0] == op:
            flat.extend(p[1])
        else:
            flat.append(p)
    if not flat:
        return None
    return flat[0] if len(flat) == 1 else (op, flat)


def _count(tree) -> int:
    return 1 if tree[0] == "e" else sum(_count(p) for p in tree[1])


def _to_text(tree, main_spring: float | None = None) -> tuple[str, dict]:
    """Network text and parameters; springs k, k1, ..., dampers c, c1, ..., inerters b, b1."""
    counters = {"spring": 0, "damper": 0, "inerter": 0}
    prefix = {"spring": "k", "damper": "c", "inerter": "b"}
    params: dict = {}

    def name(kind):
        i = counters[kind]
        counters[kind] += 1
        return prefix[kind] + ("" if i == 0 else str(i))

    def walk(node, top=False):
        if node[0] == "e":
            n = name(node[1])
            params[n] = float(node[2])
            return n
        inner = f" {node[0]} ".join(walk(p) for p in node[1])
        return inner if top else f"({inner})"

    if main_spring is not None:
        tree = _join("|", [("e", "spring", main_spring), tree])
    text = walk(tree, top=True)
    return parse_network(text).text, params


# ---------------------------------------------------------------------------------------
# the domain: F is an impedance (imp=True: "+" is series) or an admittance (imp=False)


def _term(kind_of_term: str, a: float, imp: bool):
    """Element whose F-value is a s ('s'), a/s ('1/s') or a ('1') in the domain."""
    if not (math.isfinite(a) and a > 0):
        raise RealisationError(f"a negative or zero term ({a:.6g})")
    if kind_of_term == "1":
        return _elem("damper", 1.0 / a if imp else a)
    if kind_of_term == "s":
        return _elem("spring", 1.0 / a) if imp else _elem("inerter", a)
    return _elem("inerter", 1.0 / a) if imp else _elem("spring", a)


def _resonant(two_a: float, w: float, imp: bool):
    """F-value 2a s/(s^2 + w^2): k | b in an impedance, k - b in an admittance."""
    if not (math.isfinite(two_a) and two_a > 0):
        raise RealisationError(f"an imaginary-axis pole with residue {two_a:.6g}")
    if imp:
        b = 1.0 / two_a
        return ("|", [_elem("spring", b * w * w), _elem("inerter", b)])
    return ("-", [_elem("spring", two_a), _elem("inerter", two_a / (w * w))])


def _add(imp: bool):
    return "-" if imp else "|"


def _par(imp: bool):
    return "|" if imp else "-"


def _imag_pairs(q, tol=1e-9):
    """Frequencies w > 0 of root pairs +-j w of q (relative tolerance ``tol``)."""
    out = []
    for r in np.roots(q):
        if r.imag > 0 and abs(r.real) <= tol * abs(r):
            out.append(float(abs(r)))
    return sorted(out)


def _axis_poles(p, q):
    """Frequencies w of the pole pairs +-j w of p/q on the imaginary axis: roots of q
    within the root finder's tolerance whose residue is real (a PR function's is). A
    pair that only rounds onto the axis (zeros a hair off it, e.g. a minimum function
    whose reactance at its zero of Re is nearly 0) has a complex residue and is left
    to the minimum-function step."""
    out = []
    for w in _imag_pairs(q):
        q1 = _divide_exact(q, np.array([1.0, 0.0, w * w]))
        v = np.polyval(p, 1j * w) / (1j * w * np.polyval(q1, 1j * w))
        if abs(v.imag) <= 1e-8 * abs(v):
            out.append(w)
    return out


def _remove_axis_poles(p, q, imp):
    """Extract poles at infinity, 0 and +-j w of F = p/q; returns (terms, p, q)."""
    terms = []
    scale = max(np.max(np.abs(p)), 1e-300)
    # pole at infinity
    if _deg(p) > _deg(q):
        p, q = _trim(p), _trim(q)
        if _deg(p) != _deg(q) + 1:
            raise RealisationError("pole of order > 1 at infinity: not positive real")
        a = p[0] / q[0]
        terms.append(_term("s", a, imp))
        r = np.polysub(p, a * np.polymul([1.0, 0.0], q))
        r[0] = 0.0
        p = _trim(r)
    # pole at 0
    q = _trim(q)
    if abs(q[-1]) <= _EPS * np.max(np.abs(q)):
        q1 = q[:-1]
        a = np.polyval(p, 0.0) / np.polyval(q1, 0.0)
        terms.append(_term("1/s", a, imp))
        r = np.polysub(p, a * q1)
        r = _trim(r)
        r[-1] = 0.0
        p = _trim(r[:-1]) if len(r) > 1 else np.zeros(1)
        q = q1
    # finite imaginary-axis poles
    for w in _axis_poles(p, q):
        f = np.array([1.0, 0.0, w * w])
        q1 = _divide_exact(q, f)
        two_a = (np.polyval(p, 1j * w) / (1j * w * np.polyval(q1, 1j * w))).real
        terms.append(_resonant(two_a, w, imp))
        r = np.polysub(p, two_a * np.polymul([1.0, 0.0], q1))
        p = _divide_exact(r, f) if _deg(r) >= 2 else np.zeros(1)
        q = q1
    if _is_zero(p, scale):
        p = np.zeros(1)
    return terms, _trim(p), _trim(q)


def _has_axis_zero(p, q) -> bool:
    p, q = _trim(p), _trim(q)
    if _deg(p) < _deg(q):
        return True
    if abs(p[-1]) <= _EPS * np.max(np.abs(p)):
        return True
    return bool(_axis_poles(q, p))


def _min_real(p, q):
    """(min over w >= 0 of Re F(j w), w at the minimum; inf for infinity)."""
    # Re F(j w) = E(w^2)/Q(w^2): E from p(s) q(-s) even part, Q = q(s) q(-s)
    qm = q * (-1.0) ** np.arange(len(q))[::-1]  # q(-s)
    pq = np.polymul(p, qm)
    qq = np.polymul(q, qm)

    def even_in_x(poly):  # even part of poly(s) as a polynomial in x = -s^2 ... at s = j w
        c = poly[::-1]
        ev = np.array([c[i] * (-1.0) ** (i // 2) for i in range(0, len(c), 2)])
        return ev[::-1]  # highest first, in x = w^2

    E, Q = even_in_x(pq), even_in_x(qq)
    dE, dQ = np.polyder(E), np.polyder(Q)
    crit = np.polysub(np.polymul(dE, Q), np.polymul(E, dQ))
    xs = [0.0]
    if _deg(crit) > 0:
        xs += [r.real for r in np.roots(_trim(crit)) if abs(r.imag) <= 1e-9 * abs(r) and r.real > 0]
    best = (np.polyval(E, 0.0) / np.polyval(Q, 0.0), 0.0)
    for x in xs[1:]:
        v = np.polyval(E, x) / np.polyval(Q, x)
        if v < best[0]:
            best = (v, math.sqrt(x))
    if _deg(p) == _deg(q):
        vinf = p[0] / q[0]
        if vinf < best[0]:
            best = (vinf, math.inf)
    return best


def _remove_min_real(p, q, imp):
    m, w = _min_real(p, q)
    scale = np.max(np.abs(p)) / np.max(np.abs(q))
    if m <= _EPS * scale and 0 < w < math.inf:
        return None, p, q, w
    if m <= _EPS * scale:  # rounding: Re F is 0 at w = 0 or infinity; make it exact
        r = np.array(p, float)
        if w == 0.0:
            r[-1] = 0.0
        else:
            r = np.polysub(p, (p[0] / q[0]) * q)
            r[0] = 0.0
        return None, _trim(r), q, w
    r = np.polysub(p, m * np.asarray(q))
    if w == 0.0:
        r[-1] = 0.0
    elif math.isinf(w):
        r = np.polysub(p, m * q)
        r[0] = 0.0
        r = _trim(r)
    return _term("1", m, imp), _trim(r), q, w


def _synth(p, q, imp, method, depth=0):
    """Tree realising F = p/q in the domain ``imp`` by ``method`` (bott-duffin/brune)."""
    if depth > 40:
        raise RealisationError("no termination")
    p, q = _trim(p), _trim(q)
    if _deg(p) == 0 and _deg(q) == 0:
        return _term("1", p[0] / q[0], imp)
    terms, p, q = _remove_axis_poles(p, q, imp)
    if terms:
        if np.all(p == 0):
            return _join(_add(imp), terms)
        return _join(_add(imp), [*terms, _synth(p, q, imp, method, depth + 1)])
    if _has_axis_zero(p, q):
        return _synth(q, p, not imp, method, depth + 1)
    t, p2, q2, w = _remove_min_real(p, q, imp)
    if t is not None:
        if _is_zero(p2, np.max(np.abs(p))):  # F was a constant (common factors)
            return t
        return _join(_add(imp), [t, _synth(p2, q2, imp, method, depth + 1)])
    if not (0 < w < math.inf):
        return _synth(p2, q2, imp, method, depth + 1)
    # minimum function: Re F(j w0) = 0 at a finite w0 > 0
    if not (0 < w < math.inf):
        raise RealisationError("minimum at 0 or infinity left after the preamble")
    x = (np.polyval(p, 1j * w) / np.polyval(q, 1j * w)).imag
    if method == "brune":
        return _brune_section(p, q, imp, w, x, depth)
    if x < 0:
        return _synth(q, p, not imp, method, depth + 1)
    return _bott_duffin_cycle(p, q, imp, w, x, depth)


def _bott_duffin_cycle(p, q, imp, w0, x, depth):
    L = x / w0
    # k > 0 with F(k) = L k: p(k) - L k q(k) = 0
    g = np.polysub(p, L * np.polymul([1.0, 0.0], q))
    ks = [r.real for r in np.roots(_trim(g)) if abs(r.imag) <= 1e-9 * abs(r) and r.real > 0]
    if not ks:
        raise RealisationError("no positive k with F(k) = k X/w0")
    k = min(ks, key=lambda r: abs(np.log(r / w0)))
    fk = L * k
    s = np.array([1.0, 0.0])
    # R = (k F - s F(k)) / (k F(k) - s F) = (k p - fk s q) / (k fk q - s p), common factor (s - k)
    rn = np.polysub(k * p, fk * np.polymul(s, q))
    rd = np.polysub(k * fk * q, np.polymul(s, p))
    rn = _divide_exact(rn, [1.0, -k])
    rd = _divide_exact(rd, [1.0, -k])
    # R's zeros at +-j w0 (exact in theory): make them exact, so the next preamble finds
    # them whatever the rounding of the root finder (a near-double zero of Re F at w0
    # leaves them off the axis by more than its tolerance)
    f0 = np.array([1.0, 0.0, w0 * w0])
    if _deg(rn) >= 2:
        rn = np.polymul(_divide_exact(rn, f0), f0)
    # F = [F(k) R || k F(k)/s] + [F(k)/R || s F(k)/k]
    b1 = _join(
        _par(imp), [_synth(fk * rn, rd, imp, "bott-duffin", depth + 1), _term("1/s", k * fk, imp)]
    )
    b2 = _join(
        _par(imp), [_synth(fk * rd, rn, imp, "bott-duffin", depth + 1), _term("s", fk / k, imp)]
    )
    return _join(_add(imp), [b1, b2])


# ---------------------------------------------------------------------------------------
# Foster and Cauer forms


def _foster_terms(p, q, imp, divided: bool):
    """Partial fractions of F (divided=False) or F/s; each term must be an element/unit."""
    from scipy.signal import residue

    qq = np.polymul(q, [1.0, 0.0]) if divided else q
    r, poles, direct = residue(p, qq, tol=1e-9)
    parts = []
    scale = np.max(np.abs(p)) / np.max(np.abs(q))
    direct = np.atleast_1d(direct)
    # polynomial part: F: c0 + c1 s; F/s: c0 (-> F = c0 s)
    for i, c in enumerate(direct[::-1]):
        power = i + (1 if divided else 0)
        if abs(c) <= _EPS * scale:
            continue
        if power > 1:
            raise RealisationError("pole of order > 1 at infinity")
        parts.append(_term("s" if power == 1 else "1", float(np.real(c)), imp))
    done = np.zeros(len(poles), bool)
    for i, (ri, pi) in enumerate(zip(r, poles, strict=True)):
        if done[i]:
            continue
        done[i] = True
        mag = max(abs(pi), 1e-300)
        if abs(pi) < 1e-9:  # normalised units: a pole at 0
            # pole at 0: F term a/s (F) or F/s term a/s -> F term a (divided)
            parts.append(_term("1" if divided else "1/s", float(ri.real), imp))
            continue
        if abs(pi.imag) <= 1e-9 * mag:  # real pole -sigma
            sig = -pi.real
            a = float(ri.real)
            if sig <= 0 or a <= 0:
                raise RealisationError("real pole with a negative residue or in Re s >= 0")
            if divided:  # F term a s/(s + sig)
                parts.append(_unit_s(a, sig, imp))
            else:  # F term a/(s + sig)
                parts.append(_unit_1(a, sig, imp))
            continue
        if abs(pi.real) <= 1e-9 * mag and not divided:  # +-j w pair
            j = next(
                m
                for m in range(len(poles))
                if not done[m] and abs(poles[m] - np.conj(pi)) <= 1e-7 * mag
            )
            done[j] = True
            two_a = 2.0 * ri.real
            parts.append(_resonant(two_a, abs(pi.imag), imp))
            continue
        raise RealisationError("complex poles off the imaginary axis")
    if not parts:
        raise RealisationError("nothing to realise")
    return _join(_add(imp), parts)


def _unit_1(a, sig, imp):
    """F-value a/(s + sig): k - c in an admittance, b | c in an impedance."""
    if not (a > 0 and sig > 0):
        raise RealisationError("a real pole with a negative residue")
    if imp:
        return ("|", [_elem("inerter", 1.0 / a), _elem("damper", sig / a)])
    return ("-", [_elem("spring", a), _elem("damper", a / sig)])


def _unit_s(a, sig, imp):
    """F-value a s/(s + sig): c - b in an admittance, k | c in an impedance."""
    if not (a > 0 and sig > 0):
        raise RealisationError("a real pole with a negative residue")
    if imp:
        return ("|", [_elem("damper", 1.0 / a), _elem("spring", sig / a)])
    return ("-", [_elem("damper", a), _elem("inerter", a / sig)])


def _cauer(p, q, imp, at_zero: bool):
    """Continued fraction at infinity (Cauer I) or at zero (Cauer II)."""
    chain = []  # list of (imp, element) top-down
    p, q = _trim(p), _trim(q)
    for _ in range(4 * (len(p) + len(q))):
        if at_zero:
            if abs(q[-1]) <= _EPS * np.max(np.abs(q)):  # pole at 0
                q1 = q[:-1]
                a = np.polyval(p, 0.0) / np.polyval(q1, 0.0)
                el = _term("1/s", a, imp)
                r = np.polysub(p, a * q1)
                r[-1] = 0.0
                r = _trim(r)
                rem = (_trim(r[:-1]) if len(r) > 1 else np.zeros(1), q1)
            else:
                a = p[-1] / q[-1]
                el = _term("1", a, imp)
                r = np.polysub(p, a * q)
                r[-1] = 0.0
                rem = (_trim(r), q)
        else:
            if _deg(p) > _deg(q):
                a = p[0] / q[0]
                el = _term("s", a, imp)
                r = np.polysub(p, a * np.polymul([1.0, 0.0], q))
                r[0] = 0.0
                rem = (_trim(r), q)
            else:
                a = p[0] / q[0]
                el = _term("1", a, imp)
                r = np.polysub(p, a * q)
                r[0] = 0.0
                rem = (_trim(r), q)
        chain.append((imp, el))
        rp, rq = rem
        if _is_zero(rp, np.max(np.abs(p))):
            break
        # next: the reciprocal of the remainder, other domain; the remainder at the
        # expansion point must vanish for the ladder to continue
        p, q, imp = _trim(rq), _trim(rp), not imp
    else:
        raise RealisationError("continued fraction does not terminate")
    # build the ladder from the bottom
    tree = None
    for dom, el in reversed(chain):
        tree = el if tree is None else _join(_add(dom), [el, tree])
    return tree


# ---------------------------------------------------------------------------------------
# Brune


@dataclass
class BruneSection:
    """One Brune section in the impedance domain Z (elements in impedance terms).

    Z = L1 s + [(L2 s + 1/(C2 s)) || (L3 s + Z_rest)], L1 L2 + L2 L3 + L3 L1 = 0.
    Mechanical reading (Z = 1/Y): each L is a spring of stiffness 1/L (one negative),
    C2 an inerter; the three coupled springs are a lever (ideal transformer) with springs.
    """

    L1: float
    L2: float
    C2: float
    L3: float
    w0: float
    domain: str  # "impedance" (Z = 1/Y) or "admittance" (the dual: L = inerter, C = spring)

    def value(self, s, rest):
        z = self.L1 * s + 1.0 / (
            1.0 / (self.L2 * s + 1.0 / (self.C2 * s)) + 1.0 / (self.L3 * s + rest)
        )
        return z


def _brune_section(p, q, imp, w, x, depth):
    """Node ("B", imp, section, inner tree, flip) for the minimum function F = p/q."""
    flip = False
    imp2 = imp
    if x < 0:  # the dual function has a positive reactance at w
        p, q, imp2, flip = q, p, not imp, True
        x = (np.polyval(p, 1j * w) / np.polyval(q, 1j * w)).imag
    L1 = x / w
    f = np.array([1.0, 0.0, w * w])
    r1 = _divide_exact(np.polysub(p, L1 * np.polymul([1.0, 0.0], q)), f)
    # 1/(F - L1 s) = q / (f r1): pole at +-j w with residue 2a: the L2-C2 branch
    two_a = (np.polyval(q, 1j * w) / (1j * w * np.polyval(r1, 1j * w))).real
    rest = _divide_exact(np.polysub(q, two_a * np.polymul([1.0, 0.0], r1)), f)
    # F2 = r1 / rest has a pole at infinity: L3
    r1t, restt = _trim(r1), _trim(rest)
    if _deg(r1t) != _deg(restt) + 1:
        raise RealisationError("Brune section without the series L3")
    L3 = r1t[0] / restt[0]
    z3 = np.polysub(r1t, L3 * np.polymul([1.0, 0.0], restt))
    z3[0] = 0.0
    z3 = _trim(z3)
    sec = BruneSection(
        float(L1),
        float(1.0 / two_a),
        float(two_a / (w * w)),
        float(L3),
        float(w),
        "impedance" if imp2 else "admittance",
    )
    inner = (
        None if _is_zero(z3, np.max(np.abs(r1t))) else _synth(z3, restt, imp2, "brune", depth + 1)
    )
    return ("B", imp, sec, inner, flip)


def _sections(tree) -> list:
    if tree is None or tree[0] == "e":
        return []
    if tree[0] == "B":
        return [tree[2], *_sections(tree[3])]
    return [x for t in tree[1] for x in _sections(t)]


def brune(num, den) -> dict:
    """Brune realisation of a PR admittance Y = num/den (highest power first).

    The Foster preamble and the damper removals are those of :func:`realise`; each
    minimum function gets a Brune section (a lever in mechanics: no network text).
    Returns ``sections`` (element values and domain, outermost first) and ``value``
    (a function of s: the realised admittance from the sections' two-port formula and
    the realised elements around them).
    """
    _require_pr(num, den)
    tree = _synth(np.asarray(num, float), np.asarray(den, float), False, "brune")
    return {
        "sections": _sections(tree),
        "value": lambda s: _tree_value(tree, np.asarray(s, complex)),
        "tree": tree,
    }


def _tree_value(tree, s):
    """Admittance of a tree at s (Brune nodes by their two-port formula)."""
    if tree[0] == "B":
        _, imp, sec, inner, flip = tree
        imp2 = imp != flip
        if inner is None:
            rest = 0.0 * s
        else:
            y = _tree_value(inner, s)
            rest = 1.0 / y if imp2 else y
        v = sec.value(s, rest)  # F-value in the section's domain
        if flip:
            v = 1.0 / v  # F-value in the node's domain
        return 1.0 / v if imp else v
    if tree[0] == "e":
        kind, x = tree[1], tree[2]
        return {"spring": x / s, "damper": x + 0 * s, "inerter": x * s}[kind]
    vals = [_tree_value(p, s) for p in tree[1]]
    if tree[0] == "|":
        return sum(vals)
    return 1.0 / sum(1.0 / v for v in vals)


# ---------------------------------------------------------------------------------------
# public interface


@dataclass
class Realisation:
    """A network realising an admittance Y = k/s + Y0 (or only Y0 when k is None)."""

    method: str
    network: str | None
    parameters: dict
    elements: int
    max_relative_error: float
    note: str = ""

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def _require_pr(num, den) -> None:
    from .positive_real import pr_report

    rep = pr_report(num, den)
    if not rep["positive_real"]:
        raise RealisationError(
            "the admittance is not positive real (min Re Y(jw) = "
            f"{rep['min_real_part']:.3g}, right-half-plane roots: {rep['right_half_plane_roots']}); "
            "no passive network realises it"
        )


def _check(text, params, num, den, s) -> float:
    target = _ev(num, den, s)
    got = admittance_at(text, params, s)
    return float(np.max(np.abs(got - target) / np.abs(target)))


def _scaled(num, den):
    """Frequency scale w_r (s = w_r sigma) so the poles and zeros sit near |sigma| = 1."""
    roots = np.concatenate([np.roots(_trim(num)), np.roots(_trim(den))])
    mags = np.abs(roots[np.abs(roots) > 1e-12 * max(1.0, np.max(np.abs(roots), initial=1.0))])
    return float(np.exp(np.mean(np.log(mags)))) if mags.size else 1.0


def _finish(method, tree, k, num_y, den_y, note="") -> Realisation:
    text, params = _to_text(tree, k)
    wr = _scaled(num_y, den_y)
    err = _check(text, params, num_y, den_y, wr * check_points())
    if not err < 1e-8:
        raise RealisationError(
            f"{method}: the realised admittance misses the target by {err:.2g} (relative)"
        )
    return Realisation(method, text, params, len(params), err, note)


def _split_main_spring(num, den):
    """(k, num0, den0): Y = k/s + Y0, k = 0 when Y has no pole at 0."""
    num, den = _trim(num), _trim(den)
    if abs(den[-1]) > _EPS * np.max(np.abs(den)):
        return None, num, den
    d = den[:-1]
    k = np.polyval(num, 0.0) / np.polyval(d, 0.0)
    r = np.polysub(num, k * d)
    r = _trim(r)
    r[-1] = 0.0
    return float(k), (_trim(r[:-1]) if len(r) > 1 else np.zeros(1)), d


def realise(num, den, method: str = "bott-duffin", **catalogue) -> Realisation:
    """Realise the PR admittance Y = num/den (highest power first) by ``method``.

    A pole of Y at s = 0 becomes the main spring k in parallel with the rest (the
    convention of the enumerated layouts); the method realises the remainder Y0.
    Raises :class:`RealisationError` when the method does not apply.
    """
    if method not in METHODS:
        raise ParameterError("method", method, "one of " + ", ".join(METHODS))
    num = np.asarray(num, float)
    den = np.asarray(den, float)
    _require_pr(num, den)
    k, n0, d0 = _split_main_spring(num, den)
    if np.all(n0 == 0):
        if k is None:
            raise RealisationError("Y = 0: nothing to realise")
        return _finish(method, ("e", "spring", k), None, num, den)
    wr = _scaled(n0, d0)
    # work in sigma = s / wr with unit-size coefficients, map the element values back
    p, q = _to_sigma(n0, wr), _to_sigma(d0, wr)
    g = np.max(np.abs(p)) / np.max(np.abs(q))
    tree = _realise_normalised(p / g, q, method, catalogue, (k, num, den, wr, g))
    if isinstance(tree, Realisation):
        return tree
    tree = _unscale(tree, wr, g)
    return _finish(method, tree, k, num, den)


def _to_sigma(p, wr):
    """Coefficients of p(wr sigma), highest first."""
    p = np.asarray(p, float)
    n = len(p) - 1
    return p * wr ** np.arange(n, -1, -1)


def _unscale(tree, wr, g):
    """Element values for Y(s) = g Ytilde(s/wr)."""
    if tree[0] == "e":
        kind, x = tree[1], tree[2]
        # admittance terms: spring a/sigma -> g a wr / s; damper a -> g a; inerter a sigma -> g a s / wr
        f = {"spring": g * wr, "damper": g, "inerter": g / wr}[kind]
        return ("e", kind, x * f)
    return (tree[0], [_unscale(t, wr, g) for t in tree[1]])


def _realise_normalised(p, q, method, catalogue, ctx):
    if method == "bott-duffin":
        return _synth(p, q, False, "bott-duffin")
    if method == "foster":
        errs = []
        for imp in (False, True):
            for divided in (False, True):
                try:
                    a, b = (p, q) if not imp else (q, p)
                    t = _foster_terms(a, b, imp, divided)
                    k, num, den, wr, g = ctx
                    text, params = _to_text(_unscale(t, wr, g), k)
                    if _check(text, params, num, den, wr * check_points()) < 1e-8:
                        return t
                except (RealisationError, StopIteration, ValueError) as e:
                    errs.append(str(e))
        raise RealisationError(
            "Foster forms do not apply (the admittance has three kinds of element or complex poles off the axis)"
        )
    if method == "cauer":
        for at_zero in (False, True):
            for imp in (False, True):
                try:
                    a, b = (p, q) if not imp else (q, p)
                    t = _cauer(a, b, imp, at_zero)
                    k, num, den, wr, g = ctx
                    text, params = _to_text(_unscale(t, wr, g), k)
                    if _check(text, params, num, den, wr * check_points()) < 1e-8:
                        return t
                except (RealisationError, ValueError, ZeroDivisionError, FloatingPointError):
                    continue
        raise RealisationError(
            "Cauer forms do not apply (a continued fraction step gives a negative or non-element term)"
        )
    if method == "catalogue":
        from .catalogue import fit_catalogue

        k, num, den, wr, g = ctx
        return fit_catalogue(num, den, **catalogue)
    if method == "brune":
        raise RealisationError("use brune() for the Brune realisation: it needs a lever")
    raise ParameterError("method", method, "one of " + ", ".join(METHODS))


def realise_all(
    num, den, methods=("foster", "cauer", "catalogue", "bott-duffin"), **catalogue
) -> dict:
    """Every method that applies: method -> Realisation or the reason it does not."""
    out: dict = {}
    for m in methods:
        try:
            out[m] = realise(num, den, m, **catalogue)
        except RealisationError as e:
            out[m] = str(e)
    return out


def bott_duffin(num, den) -> Realisation:
    """Bott-Duffin realisation of Y = num/den (highest power first)."""
    return realise(num, den, "bott-duffin")
