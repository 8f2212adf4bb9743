"""Frequency response of the chapter-7 system (7.1): linear limit, accuracy, convergence."""

import json

import numpy as np
import pytest

import _frequency_oracle as oracle
from inerterlab import constant_flywheel
from inerterlab.errors import ParameterError
from inerterlab.frequency import (
    InerterSuspension,
    chapter7_system,
    floquet_multipliers,
    frequency_response,
    hill_exponents,
    make_engine,
    nrmse,
    steady_state,
)
from inerterlab.systems.oscillators import FREQ_SLOT

LINEAR = InerterSuspension(base_amplitude=0.02, flywheel=constant_flywheel(1e-3))
FREQS = np.array([0.2, 0.7, 1.1, 1.4, 2.0, 4.0])


@pytest.mark.parametrize("method", ["shb", "mhb", "sihb"])
def test_linear_limit_equals_transfer_function(method):
    fr = frequency_response(LINEAR, method, freq_hz=FREQS)
    exact = LINEAR.linear_amplitude(fr.omega, inertance=LINEAR.transmission.ratio**2 * 1e-3)
    assert fr.converged.all()
    np.testing.assert_allclose(fr.amplitude_m.data, exact, rtol=1e-9)
    assert np.ma.filled(fr.stable, False).all()


def test_linear_limit_continuation_and_brute():
    b = LINEAR.transmission.ratio**2 * 1e-3
    fc = frequency_response(LINEAR, "continuation", fmin=0.2, fmax=3.0, harmonics=3)
    assert fc.settings["continuation_message"] == "" and len(fc) > 10
    np.testing.assert_allclose(
        fc.amplitude_m.data, LINEAR.linear_amplitude(fc.omega, inertance=b), rtol=1e-8
    )
    fb = frequency_response(LINEAR, "brute", freq_hz=FREQS[:4])
    np.testing.assert_allclose(
        fb.amplitude_m.data, LINEAR.linear_amplitude(fb.omega, inertance=b), rtol=1e-6
    )


def test_traditional_suspension_closed_form():
    sys = chapter7_system(0.05, preset="none")
    fr = frequency_response(sys, "mhb", freq_hz=FREQS, harmonics=3)
    np.testing.assert_allclose(fr.amplitude_m.data, sys.linear_amplitude(fr.omega), rtol=1e-9)


@pytest.fixture(scope="module")
def brute_3cm():
    return frequency_response(chapter7_system(0.03), "brute", fmin=0.1, fmax=3.0, df=0.25)


def test_sihb_and_mhb_match_brute(brute_3cm):
    sys = chapter7_system(0.03)
    grid = brute_3cm.freq_hz
    for method in ("mhb", "sihb"):
        fr = frequency_response(sys, method, freq_hz=grid, harmonics=15)
        assert fr.converged.all()
        assert nrmse(fr, brute_3cm) <= 5e-4
    shb = frequency_response(sys, "shb", freq_hz=grid)
    assert nrmse(shb, brute_3cm) > nrmse(fr, brute_3cm)


def test_convergence_in_harmonics(brute_3cm):
    sys = chapter7_system(0.03)
    errors = [
        nrmse(frequency_response(sys, "mhb", freq_hz=brute_3cm.freq_hz, harmonics=h), brute_3cm)
        for h in (1, 3, 7, 15)
    ]
    assert all(a > b for a, b in zip(errors, errors[1:], strict=False))
    assert errors[-1] < 2e-4


def test_brute_force_against_the_scipy_oracle():
    """The compiled RK4 brute force against scipy's DOP853 at rtol 1e-10 on the numpy
    residual (tests/_frequency_oracle.py), from rest to the settled orbit."""
    sys = chapter7_system(0.03)
    w = 2 * np.pi * 1.3
    a = steady_state(sys, w)
    b = oracle.steady_state(sys, w, max_periods=60)
    assert a.settled and b.settled
    assert a.amplitude == pytest.approx(b.amplitude, rel=1e-6)


def test_resonance_falls_with_amplitude():
    f = []
    for amp in (0.01, 0.05, 0.2):
        fr = frequency_response(
            chapter7_system(amp), "sihb", fmin=0.5, fmax=2.0, df=0.02, harmonics=7
        )
        f.append(fr.resonance("down")["freq_hz"])
    assert f[0] > f[1] > f[2]


def test_hill_agrees_with_floquet_on_ch7():
    sys = chapter7_system(0.05)
    eng = make_engine(sys, 15)
    w = 2 * np.pi * 1.1
    X, ok, *_ = eng.newton(np.zeros(31), w, 1e-12, 50, 0.05)
    assert ok
    lam = hill_exponents(eng, X, w)
    state0 = [X @ eng.basis.E[0], w * (X @ eng.basis.E1[0])]
    mu = oracle.floquet_multipliers(sys, w, state0)
    # the package's (RK4 monodromy) against the oracle's (DOP853): the flow has kinks
    # (the saturation speed), so the central differences of either carry errors of a
    # few 1e-4 (the oracle moves by 2.8e-4 from rtol 1e-11 to 1e-13); with 64000 steps a
    # period the RK4 meets the oracle at rtol 1e-13 to 1.6e-5 (measured)
    np.testing.assert_allclose(np.sort(np.abs(floquet_multipliers(sys, w, state0))),
                               np.sort(np.abs(mu)), rtol=1e-3)  # fmt: skip
    fine = np.sort(np.abs(floquet_multipliers(sys, w, state0, steps_per_period=64000)))
    tight = np.sort(np.abs(oracle.floquet_multipliers(sys, w, state0, rtol=1e-13)))
    np.testing.assert_allclose(fine, tight, rtol=1e-4)
    # the kink of m_e(v) at the saturation speed makes the variational equation's
    # coefficients discontinuous, so Hill's truncation converges slowly: agree to 1 %
    np.testing.assert_allclose(
        np.sort(np.abs(mu)), np.sort(np.abs(np.exp(lam * 2 * np.pi / w))), rtol=1e-2
    )
    assert np.max(np.abs(mu)) < 1


@pytest.mark.parametrize("law", ["momentum", "thesis-literal"])
def test_other_laws_solve_and_match_brute(law):
    sys = chapter7_system(0.03, law=law)
    fr = frequency_response(sys, "sihb", freq_hz=[0.6, 1.0, 1.4], harmonics=15, direction="down")
    fb = frequency_response(sys, "brute", freq_hz=[0.6, 1.0, 1.4])
    assert fr.converged.all()
    # the momentum law's inertance I + w dI/dw jumps at the saturation speed (dI/dw
    # drops to zero), so both H = 15 and fixed-step RK4 converge more slowly than for
    # the continuous thesis law
    assert nrmse(fr, fb) < (3e-3 if law == "momentum" else 5e-4)


def test_failed_points_are_reported_not_numbers():
    fr = frequency_response(chapter7_system(0.2), "mhb", freq_hz=[0.8, 1.0], max_iter=1)
    assert not fr.converged.any()
    assert all(fr.failure_reason)
    assert np.ma.getmaskarray(fr.amplitude_m).all()
    d = fr.to_dict()
    assert d["amplitude_m"] == [None, None] and d["converged"] == [False, False]
    json.dumps(d, allow_nan=False)
    df = fr.to_pandas()
    assert df["amplitude_m"].isna().all()


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"fmin": 2.0, "fmax": 1.0, "df": 0.1}, "fmin"),
        ({"fmin": 1.0, "fmax": 2.0, "df": 0.0}, "df"),
        ({"fmin": 1.0, "fmax": 2.0, "df": 0.1, "harmonics": 0}, "harmonics"),
        ({"fmin": 1.0, "fmax": 2.0, "df": 0.1, "direction": "left"}, "direction"),
    ],
)
def test_bad_input_names_the_parameter(kwargs, name):
    with pytest.raises(ParameterError, match=name):
        frequency_response(chapter7_system(0.01), "mhb", **kwargs)


def test_result_table_and_plot(tmp_path):
    fr = frequency_response(chapter7_system(0.05), "sihb", fmin=0.5, fmax=2.0, df=0.1, harmonics=7)
    df = fr.to_pandas()
    assert list(df["direction"].unique()) == ["down", "up"]
    assert len(df) == 2 * 16
    fig = fr.plot()
    fig.savefig(tmp_path / "fr.png")
    assert (tmp_path / "fr.png").stat().st_size > 1000


@pytest.mark.slow
@pytest.mark.parametrize("amp", [0.01, 0.03, 0.05])
def test_nrmse_below_005_percent(amp):
    sys = chapter7_system(amp)
    fb = frequency_response(sys, "brute", fmin=0.1, fmax=3.0, df=0.05)
    for method in ("mhb", "sihb"):
        fr = frequency_response(sys, method, freq_hz=fb.freq_hz, harmonics=15, stability=False)
        assert fr.converged.all()
        assert nrmse(fr, fb) <= 5e-4


@pytest.mark.parametrize(("law", "preset"), [("thesis", "metal"), ("momentum", "nylon"),
                                             ("thesis", "none")])  # fmt: skip
def test_template_is_the_core_base_excited_body(law, preset):
    """The chapter-7 template (systems/oscillators.py) and the model core's
    ``base_excited(M, "k | c | afw")``, built from the elements, give the body the same
    acceleration at any state and base motion (below and above the saturation speed)."""
    sys = chapter7_system(0.03, preset=preset, law=law)
    form = sys.first_order()
    core = sys.core_system()
    assert core.state_names == ("body.x", "body.v")
    itab, ftab = core.tables
    rng = np.random.default_rng(7)
    w = 2 * np.pi * 1.3
    for _ in range(40):
        t = rng.uniform(0, 1)
        x, v = rng.normal(0, 0.05), rng.normal(0, 1.0)
        tau = w * t
        road = np.zeros(FREQ_SLOT + 1)  # the base's motion, then the frequency
        road[:3] = 0.03 * np.array([np.sin(tau), w * np.cos(tau), -w * w * np.sin(tau)])
        road[FREQ_SLOT] = w
        a = np.zeros(2)
        assert form.rhs(t, np.array([x, v]), road, form.int_table, form.float_table, a)
        b = np.zeros(2)
        assert core.rhs(t, np.array([x, v]), road, itab, ftab, b)
        assert a[1] == pytest.approx(b[1], rel=1e-12, abs=1e-12 * abs(b[1]) + 1e-12)


def test_engine_and_brute_force_on_the_template():
    """The balance runs on the one engine (velocity eliminated: 2H+1 unknowns), and its
    amplitudes agree with time integration to steady state (RK4 and scipy's DOP853)."""
    sys = chapter7_system(0.03)
    f = [0.4, 0.9, 1.6, 3.0]
    a = frequency_response(sys, "sihb", freq_hz=f, harmonics=15, direction="down")
    assert a.settings["engine"] == "FirstOrderEngine" and a.settings["n_samples"] == 128
    assert a.coefficients.shape[1:] == (1, 31)
    b = frequency_response(sys, "brute", freq_hz=f)
    assert a.converged.all() and b.converged.all()
    assert nrmse(a, b) <= 5e-4
