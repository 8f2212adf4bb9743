"""Model core, events: kinks of the force laws (free-play contact, flywheel saturation)
located by the elements' switching functions, against a closed form and against the
quarter-car kernel (an independent implementation that locates its kinks itself)."""

import math

import numpy as np

import _quarter_car_oracle as oracle
from inerterlab.elements import Backlash
from inerterlab.excitation import bump, sine
from inerterlab.systems import base_excited, quarter_car

M, K, G, V0 = 2.0, 2e4, 0.002, 0.3  # mass [kg], contact stiffness [N/m], half play [m], m/s


def _rattle(t):
    """A mass moving at V0 from the middle of a free play +-G between two contact
    springs K: free flight, half a period of contact, flight back, ... (closed form)."""
    w = math.sqrt(K / M)
    fly, touch = 2 * G / V0, math.pi / w
    s = (np.asarray(t) + 0.5 * fly) % (2 * (fly + touch))
    x = np.empty_like(s)
    for i, u in enumerate(s):
        if u < fly:
            x[i] = -G + V0 * u
        elif u < fly + touch:
            x[i] = G + V0 / w * math.sin(w * (u - fly))
        elif u < 2 * fly + touch:
            x[i] = G - V0 * (u - fly - touch)
        else:
            x[i] = -G - V0 / w * math.sin(w * (u - 2 * fly - touch))
    return x


def test_free_play_contacts_are_located():
    sys_ = base_excited(M, "gap", {"gap": Backlash(stiffness=K, free_play=2 * G)})
    amp = G + V0 / math.sqrt(K / M)
    errs = {}
    for rtol in (1e-8, 1e-10):
        res = sys_.simulate(bump(1e-300), 0.5, rtol=rtol, x0=np.array([0.0, V0]),
                            method="adaptive", sample_rate=10_000)  # fmt: skip
        errs[rtol] = np.abs(res.outputs["body.x"] - _rattle(res.time)).max() / amp
        # two contacts made and two broken per period of 2 (2G/V0 + pi/w)
        period = 2 * (2 * G / V0 + math.pi / math.sqrt(K / M))
        assert abs(res.stats["events"] - 4 * 0.5 / period) <= 1.5
    assert errs[1e-10] < 2e-8
    assert errs[1e-8] / errs[1e-10] > 30.0  # the error falls with the tolerance


def test_flywheel_saturation_against_the_scipy_oracle():
    """The afw car (k | c | afw) at rtol 1e-8 within 1e-7 of the scipy oracle (the
    independent equations, DOP853) at rtol 1e-11 (largest state error over the state's
    peak): with its kinks unlocated the core was at 1.4e-5."""
    ex, T = sine(0.05, 5.0), 2.0
    ref = oracle.simulate(quarter_car("afw"), ex, T, rtol=1e-11)
    core = quarter_car("afw")
    res = core.simulate(ex, T, rtol=1e-8, method="adaptive")
    assert res.stats["events"] > 0
    idx = [core.state_names.index(n) for n in ("wheel.x", "wheel.v", "body.x", "body.v")]
    a, b = res.states[:, idx], ref.states[:, :4]
    assert (np.abs(a - b).max(axis=0) / np.abs(b).max(axis=0)).max() < 1e-7


def test_flywheel_grazing_its_saturation_speed():
    """The strut's relative velocity just reaches the flywheel's saturation speed (its
    peak 1.00007 times it, on the core's run at rtol 1e-11): the flywheel saturates for
    a moment and leaves saturation within the next step. That return was missed while
    a switching function started the step after its crossing at 0 (no sign change at
    the step's end): the element kept the saturated law, 1.9e-2 of a state's peak off
    the scipy oracle (the independent equations, DOP853 at rtol 1e-11)."""
    ex, T = sine(0.003212, 2.0), 1.0
    ref = oracle.simulate(quarter_car("afw"), ex, T, rtol=1e-11)
    core = quarter_car("afw")
    idx = [core.state_names.index(n) for n in ("wheel.x", "wheel.v", "body.x", "body.v")]
    b = ref.states[:, :4]
    for method in ("adaptive", "auto"):
        res = core.simulate(ex, T, rtol=1e-8, method=method)
        assert res.stats["events"] >= 1
        a = res.states[:, idx]
        assert (np.abs(a - b).max(axis=0) / np.abs(b).max(axis=0)).max() < 1e-7


def _twin_rattles(lead: float):
    """Two masses of the free-play system of :func:`_rattle`, independent (each on its
    own play over the one base), the second started ``lead`` seconds along its own
    flight: its contacts come ``lead`` earlier, at the first's instants when 0."""
    from inerterlab.systems._network import Layout, elements_of
    from inerterlab.systems.core import _laid_out

    tree, els = elements_of("gap", {"gap": Backlash(stiffness=K, free_play=2 * G)})

    def make(arrange):
        lay = Layout(arrange)
        base = lay.node("base", "road")
        for name in ("one", "two"):
            body = lay.node(name, "mass", M)
            lay.place(tree, body, base, els, path=name, fixed=(True, False))
        return lay

    sys_ = _laid_out("twins", "two rattling masses", make, {})[0]
    x0 = np.zeros(sys_.n_states)
    x0[sys_.state_names.index("one.v")] = V0
    x0[sys_.state_names.index("two.x")] = V0 * lead
    x0[sys_.state_names.index("two.v")] = V0
    return sys_.simulate(bump(1e-300), 0.5, rtol=1e-10, x0=x0, method="adaptive",
                         sample_rate=10_000)  # fmt: skip


def test_simultaneous_contacts_switch_together():
    """Two identical rattling masses make and break their contacts at the same
    instants, one event each: each moves as the one mass alone does (and as the closed
    form), to rounding (1e-16; 2e-7 when the second switched a step late); with the second's
    contacts 1e-9 s earlier the events are two, each located, and the second mass
    follows the closed form shifted by that lead."""
    amp = G + V0 / math.sqrt(K / M)
    one = base_excited(M, "gap", {"gap": Backlash(stiffness=K, free_play=2 * G)}).simulate(
        bump(1e-300), 0.5, rtol=1e-10, x0=np.array([0.0, V0]), method="adaptive",
        sample_rate=10_000)  # fmt: skip
    x1 = one.outputs["body.x"]
    both = _twin_rattles(0.0)
    assert both.stats["events"] == one.stats["events"]  # one event: both switch
    for name in ("one", "two"):
        x = both.outputs[f"{name}.x"]
        assert np.abs(x - x1).max() / amp < 1e-12, name
        assert np.abs(x - _rattle(both.time)).max() / amp < 2e-8, name
    lead = 1e-9
    apart = _twin_rattles(lead)
    assert apart.stats["events"] == 2 * one.stats["events"]
    # 3e-8 (each mass's contacts cut the other's steps; the one mass alone: 5e-9)
    assert np.abs(apart.outputs["one.x"] - _rattle(apart.time)).max() / amp < 1e-7
    assert np.abs(apart.outputs["two.x"] - _rattle(apart.time + lead)).max() / amp < 1e-7


def test_a_return_is_searched_after_the_last_point_of_the_new_sign():
    """A switching function that started the step just past its crossing (PAST_KINK)
    and is back across at the step's end: the search halves towards the start until the
    function still has its new sign there, and brackets the return after that point;
    a function back across everywhere down to RETURN_LEAST turned back at once (the
    crossing's rounding, or a sliding mode): the driver then takes no event. (A search
    from the start stopped in the crossing's rounding: a one-way clutch's rig then
    switched sides at one instant until its 10^7 steps ran out.)"""
    from inerterlab.systems._integrate import PAST_KINK, RETURN_LEAST, _return_scan

    g0, g1 = PAST_KINK, -0.3
    # at x = 0.5 already back (g1's sign): the bracket's end moves there, next x = 0.25
    assert _return_scan(0.5, -0.1, g0, 0.0, 1.0, g0, g1) == (True, 0.25, 0.0, 0.5, g0, -0.1)
    # at x = 0.25 still of g0's sign: the bracket [0.25, 0.5] of the return
    assert _return_scan(0.25, 0.02, g0, 0.0, 0.5, g0, -0.1) == (False, 0.25, 0.25, 0.5, 0.02, -0.1)
    # the rounding's exact zero moves nothing but x
    assert _return_scan(0.125, 0.0, g0, 0.0, 0.25, g0, -0.1) == (True, 0.0625, 0.0, 0.25, g0, -0.1)
    assert 0.5**20 < RETURN_LEAST < 0.5**19  # at most 20 points before giving up
