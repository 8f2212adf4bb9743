"""Catalogue counts against the published ones (docs/model.md §13, "Counts").

Ladenheim's catalogue (Ladenheim 1948, as derived again in Morelli & Smith 2019,
*Passive Network Synthesis: An Approach to Classification*, SIAM, ch. 3) starts from the
148 networks with at most five elements of which at most two are reactive, counted once
up to reordering (2-isomorphism), leaving out those with two elements of one kind
directly in series or in parallel (and so any part of one kind only); eight of them
have four resistors and one reactive element. Under the force-current analogy
(spring = inductor, damper = resistor, inerter = capacitor, series and parallel kept)
the mechanical count is the same.
"""

import itertools
from collections import Counter
from functools import lru_cache

import numpy as np
import pytest

from inerterlab.errors import ParameterError
from inerterlab.networks import admittance_at
from inerterlab.synthesis.catalogue import structural_catalogue
from inerterlab.synthesis.positive_real import is_regular


def test_ladenheim_starting_list_has_148_networks():
    cat = structural_catalogue(5, 2)
    assert len(cat) == 148
    # eight with four resistors (dampers) and one reactive element: four ladders
    # c - (c | (c - (c | X))) and duals, four bridges
    four = [o for o in cat if o.dampers == 4]
    assert len(four) == 8 and all(o.reactive == 1 and o.elements == 5 for o in four)
    assert sum(o.bridge is not None for o in four) == 4
    # every listed network respects the scope; the same-kind rule holds
    assert all(o.elements <= 5 and o.reactive <= 2 for o in cat)
    assert len({o.text for o in cat}) == 148
    # the Ladenheim catalogue proper (108) keeps at most three resistors: 140 remain
    # here before the electrical reductions that take it to 108 (not reproduced)
    assert sum(o.dampers <= 3 for o in cat) == 140


# an independent enumeration of the series-parallel part: canonical trees with sorted
# children and alternating operations, leaves R, L, C; no two equal leaves under one node


@lru_cache(None)
def _trees(n: int, op: str) -> frozenset:
    if n == 1:
        return frozenset("RLC")
    other = "P" if op == "S" else "S"

    def parts(m, largest):
        if m == 0:
            yield ()
            return
        for p in range(min(m, largest), 0, -1):
            for rest in parts(m - p, p):
                yield (p, *rest)

    out = set()
    for part in parts(n, n - 1):
        pools = [sorted(frozenset("RLC") if m == 1 else _trees(m, other), key=repr) for m in part]
        for combo in itertools.product(*pools):
            out.add((op, tuple(sorted(combo, key=repr))))
    return frozenset(out)


def _leaves(t) -> Counter:
    return Counter(t) if isinstance(t, str) else sum((_leaves(x) for x in t[1]), Counter())


def _primitive(t) -> bool:
    if isinstance(t, str):
        return True
    leaves = [x for x in t[1] if isinstance(x, str)]
    return len(leaves) == len(set(leaves)) and all(_primitive(x) for x in t[1])


def test_series_parallel_part_agrees_with_an_independent_enumeration():
    ref = Counter()
    for n in range(1, 6):
        pool = frozenset("RLC") if n == 1 else _trees(n, "S") | _trees(n, "P")
        for t in pool:
            c = _leaves(t)
            if _primitive(t) and c["L"] + c["C"] <= 2:
                ref[(c["R"], c["L"], c["C"])] += 1
    got = Counter(
        (o.dampers, o.springs, o.inerters) for o in structural_catalogue(5, 2) if o.bridge is None
    )
    assert got == ref
    assert sum(ref.values()) == 131  # and 17 bridges: 148


def test_bridges_are_counted_up_to_their_symmetries():
    br = [o.bridge for o in structural_catalogue(5, 2) if o.bridge is not None]
    assert len(br) == 17  # 13 with two reactive elements, 4 with one
    # Burnside over the four symmetries, colourings with <= 2 reactive arms of 3 kinds,
    # minus the bridge of five dampers (one kind: one damper)
    sym = [(0, 1, 2, 3, 4), (1, 0, 3, 2, 4), (2, 3, 0, 1, 4), (3, 2, 1, 0, 4)]
    fixed = 0
    for perm in sym:
        for col in itertools.product("kcb", repeat=5):
            if sum(k != "c" for k in col) <= 2 and all(col[perm[i]] == col[i] for i in range(5)):
                fixed += 1
    assert fixed % 4 == 0 and fixed // 4 - 1 == 17


def test_bridge_admittance_limits():
    """The bridge's nodal solution against series-parallel networks: with a zero
    bridging damper it is (a-c - c-b) | (a-d - d-b); balanced (equal arm ratios), the
    bridging element carries nothing, whatever it is."""
    cat = structural_catalogue(5, 2)
    bridge = next(
        o.bridge
        for o in cat
        if o.bridge is not None and o.bridge.kinds == ("c", "c", "k", "k", "c")
    )
    n = bridge.names  # arms a-c, a-d, c-b, d-b, c-d
    s = np.array([0.3j, 2.1j, 0.5 + 1.2j, 4.0 - 0.7j])
    vals = {n[0]: 3.0, n[1]: 7.0, n[2]: 5.0, n[3]: 11.0, n[4]: 0.0}
    ref = admittance_at(
        f"({n[0]} - {n[2]}) | ({n[1]} - {n[3]})", {k: v for k, v in vals.items() if v}, s
    )
    assert np.allclose(bridge.admittance_at(vals, s), ref, rtol=1e-13)
    # balanced: y_ac / y_cb == y_ad / y_db at every s (c1/k1 = c2/k2)
    vals = {n[0]: 3.0, n[1]: 6.0, n[2]: 5.0, n[3]: 10.0, n[4]: 17.0}
    ref = admittance_at(f"({n[0]} - {n[2]}) | ({n[1]} - {n[3]})", {k: vals[k] for k in n[:4]}, s)
    assert np.allclose(bridge.admittance_at(vals, s), ref, rtol=1e-13)


def _biquadratic(bridge, vals, s):
    """(num, den) of a bridge's admittance by the null vector of Y D - N = 0."""
    y = bridge.admittance_at(vals, s)
    a = np.column_stack([y * s**2, y * s, y, -(s**2), -s, -np.ones_like(s)])
    _, sv, vt = np.linalg.svd(np.vstack([a.real, a.imag]))
    if sv[-1] > 1e-9 * sv[0] or sv[-2] < 1e-6 * sv[0]:
        return None  # not a biquadratic of full degree with these values
    v = vt[-1] / np.max(np.abs(vt[-1]))
    if min(abs(v[0]), abs(v[2]), abs(v[3]), abs(v[5])) < 1e-8:
        return None  # a pole or zero at 0 or infinity: not a full biquadratic
    v = v / v[0]
    return v[3:], v[:3]


def test_two_bridges_realise_non_regular_biquadratics():
    """Published count: Jiang & Smith (2011, IEEE TAC 56(6), 1275-1290, abstract): a
    biquadratic is realised by a series-parallel network with two reactive elements iff
    it is regular (checked in test_synthesis_regular.py), and the only five-element
    networks that realise non-regular biquadratics form three quartets, the first of
    them "two bridge networks with two reactive elements". Of the 13 two-reactive
    bridges of the catalogue, exactly two give non-regular biquadratics (60 random draws
    each; the other eleven gave only regular ones): the published two. They form one
    quartet reduced to two networks: frequency inversion (s -> 1/s, spring <-> inerter)
    maps the one to the other up to the bridge's symmetries (checked below)."""
    rng = np.random.default_rng(3)
    s = np.exp(rng.uniform(-2, 2, 24)) * np.exp(1j * rng.uniform(-1.5, 1.5, 24))
    bridges = [
        o.bridge for o in structural_catalogue(5, 2) if o.bridge is not None and o.reactive == 2
    ]
    assert len(bridges) == 13
    non_regular = set()
    for br in bridges:
        for _ in range(60):
            vals = {name: float(np.exp(rng.uniform(-2, 2))) for name in br.names}
            f = _biquadratic(br, vals, s)
            if f is not None and not is_regular(*f):
                non_regular.add(br.kinds)
                break
    assert non_regular == {("c", "c", "c", "k", "b"), ("b", "c", "c", "c", "k")}
    # frequency inversion of the first, then the symmetry swapping both terminal pairs
    inverted = tuple({"k": "b", "b": "k"}.get(x, x) for x in ("c", "c", "c", "k", "b"))
    assert tuple(inverted[i] for i in (3, 2, 1, 0, 4)) == ("b", "c", "c", "c", "k")


def test_structural_catalogue_bounds():
    assert len(structural_catalogue(1, 1)) == 3  # k, c, b
    assert len(structural_catalogue(2, 2)) == 9  # + the six pairs of different kinds
    with pytest.raises(ParameterError, match="max_elements"):
        structural_catalogue(6, 2)
    with pytest.raises(ParameterError, match="max_reactive"):
        structural_catalogue(5, 6)
