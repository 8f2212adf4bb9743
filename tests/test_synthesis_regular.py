"""Regular positive-real biquadratics and the series-parallel networks that realise them.

Jiang & Smith (2011, IEEE TAC 56(6)) show that a biquadratic is realised by a
series-parallel network with two reactive elements if and only if it is *regular*
(the smallest value of Re Y(j w) or of Re (1/Y)(j w) is attained at w = 0 or w = inf).
The tests check our computation of regularity against the networks themselves, in both
directions: every such network of the catalogue gives a regular function (random
element values), and random regular biquadratics are fitted exactly by a catalogue
layout with two reactive elements.
"""

import numpy as np
import pytest

from inerterlab.networks import admittance, parse_network
from inerterlab.synthesis.catalogue import catalogue_layouts, fit_catalogue
from inerterlab.synthesis.positive_real import (
    is_regular,
    minimum_at_the_ends,
    pr_from_parameters,
    pr_report,
)
from inerterlab.synthesis.realise import RealisationError, realise

# dampers, inerters, springs: every layout with at most two reactive elements and at
# most three dampers (five elements), the class of Jiang & Smith's theorem
TWO_REACTIVE = [(3, 1, 1), (3, 2, 0), (3, 0, 2)]


def _two_reactive_layouts():
    return sorted({t for b in TWO_REACTIVE for t in catalogue_layouts(*b)})


def test_regularity_on_known_functions():
    # the minimum function (s^2 + s + 1)/(s^2 + s + 4): Re Z(j w) = 0 at w = sqrt(2),
    # above 0 at both ends; Re(1/Z) likewise: not regular
    assert not minimum_at_the_ends([1, 1, 1], [1, 1, 4])
    assert not minimum_at_the_ends([1, 1, 4], [1, 1, 1])
    assert not is_regular([1, 1, 1], [1, 1, 4])
    # a bilinear function (one damper and one spring and one damper) is always regular:
    # Re Y(j w) is monotone in w
    assert is_regular([2.0, 1.0], [1.0, 3.0]) and is_regular([1.0, 3.0], [2.0, 1.0])
    # Re Y(j w) = E/F by hand for Y = (s + 2)/(s + 1): E = x + 2, F = x + 1; minimum
    # at infinity (1 < 2)
    assert minimum_at_the_ends([1.0, 2.0], [1.0, 1.0])
    # a lightly damped resonance in the real part: (s^2 + 0.1 s + 1)/(s^2 + s + 1)
    # has Re Y(j w) dipping to 0.1 at w = 1 below the ends (1 and 1): not at the ends;
    # its inverse has a peak there instead, so the function is regular
    assert not minimum_at_the_ends([1, 0.1, 1], [1, 1, 1])
    assert minimum_at_the_ends([1, 1, 1], [1, 0.1, 1])
    assert is_regular([1, 0.1, 1], [1, 1, 1])


def test_series_parallel_two_reactive_networks_are_regular():
    """The 'only if' of Jiang & Smith (2011) against the networks: random element
    values (three decades) on every catalogue layout with at most two reactive elements
    and three dampers give regular functions, as admittance and as impedance; and the
    "or 1/Y" of the definition matters (many of them fail the one-sided test)."""
    rng = np.random.default_rng(11)
    layouts = _two_reactive_layouts()
    # 66 + 34 + 23 layouts per budget; those with at most one reactive element appear
    # in more than one budget, 109 distinct
    assert len(layouts) == 109
    biquadratic = one_sided_fails = 0
    for text in layouts:
        net = parse_network(text)
        for _ in range(12):
            vals = dict(zip(net.names, 10 ** rng.uniform(-1.5, 1.5, len(net.names)), strict=True))
            n, d = admittance(net, vals)
            n = np.trim_zeros(np.asarray(n, float), "f")
            d = np.trim_zeros(np.asarray(d, float), "f")
            assert is_regular(n, d), (text, vals)
            assert is_regular(d, n), (text, vals)
            if len(n) == 3 and len(d) == 3:
                biquadratic += 1
                one_sided_fails += not minimum_at_the_ends(n, d)
    assert biquadratic > 500 and one_sided_fails > 50


def _random_biquadratic(rng, regular):
    while True:
        N, D = pr_from_parameters(rng.uniform(-1.0, 1.0, 5), 2)
        num, den = N[::-1].copy(), D[::-1].copy()
        if min(np.min(num), np.min(den)) <= 1e-3 * max(np.max(num), np.max(den)):
            continue  # a coefficient near 0: close to a lower-degree function
        if is_regular(num, den) == regular:
            return num, den


def test_random_pr_biquadratics_are_regular_or_not():
    """The PR family is split by regularity, both sides well populated."""
    rng = np.random.default_rng(3)
    flags = []
    for _ in range(200):
        N, D = pr_from_parameters(rng.uniform(-1.0, 1.0, 5), 2)
        num, den = N[::-1].copy(), D[::-1].copy()
        assert pr_report(num, den)["positive_real"]
        flags.append(is_regular(num, den))
        assert flags[-1] == is_regular(den, num)  # closed under inversion by definition
    assert 40 < sum(flags) < 160


@pytest.mark.slow
def test_regular_biquadratics_are_fitted_by_a_two_reactive_layout():
    """The 'if' of Jiang & Smith (2011): random regular PR biquadratics are realised
    exactly (coefficients to 1e-10, the admittance to 1e-8 at the check points) by a
    catalogue layout with two reactive elements and at most three dampers. (The
    converse, that a non-regular biquadratic fits none of the 109 layouts, was checked
    on random functions when this test was written, but each failing search takes
    10-150 s and is left out of the suite; docs/decisions.md gives the figures.)"""
    rng = np.random.default_rng(7)
    for _ in range(2):  # about 30 s: a failing layout search costs seconds
        num, den = _random_biquadratic(rng, regular=True)
        fitted = None
        for budget in TWO_REACTIVE:
            try:
                fitted = fit_catalogue(num, den, budget=budget)
                break
            except RealisationError:
                continue
        assert fitted is not None, (num, den)
        assert fitted.max_relative_error < 1e-8
        kinds = [name.rstrip("0123456789") for name in fitted.parameters]
        assert kinds.count("k") + kinds.count("b") <= 2 and len(kinds) <= 5


def test_catalogue_failure_names_the_non_regular_biquadratic():
    """The minimum function Y = (s^2 + s + 4)/(s^2 + s + 1) is not regular: no layout
    of the default catalogue fits it, and the message says why."""
    with pytest.raises(RealisationError, match="not regular"):
        realise([1.0, 1.0, 4.0], [1.0, 1.0, 1.0], "catalogue")
    # a regular one that fails for lack of budget does not get the note
    with pytest.raises(RealisationError) as err:
        realise([1.0, 0.1, 1.0], [1.0, 1.0, 1.0], "catalogue", budget=(1, 0, 0))
    assert "regular" not in str(err.value)
