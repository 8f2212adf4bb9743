"""Frequency response of the chapter-7 system (7.1): linear limit, accuracy, convergence."""

import json

import numpy as np
import pytest

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


def test_brute_backends_agree():
    sys = chapter7_system(0.03)
    w = 2 * np.pi * 1.3
    a = steady_state(sys, w, backend="numba")
    b = steady_state(sys, w, backend="scipy", max_periods=60)
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
    mu = floquet_multipliers(sys, w, state0)
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


def test_one_engine_gives_the_kernel_results():
    """The chapter-7 system in implicit form on the one engine (velocity eliminated)
    balances the residual the specialised kernel balances: the same points converge to
    the same amplitudes and Hill multipliers to round-off, and the one RK4 period
    integrator settles on the kernel's brute-force amplitudes."""
    sys = chapter7_system(0.03)
    form = sys.first_order()
    f = [0.4, 0.9, 1.15, 1.6, 3.0]
    a = frequency_response(sys, "sihb", freq_hz=f, harmonics=15, stability=True)
    b = frequency_response(
        form, "sihb", freq_hz=f, harmonics=15, amplitude=sys.input_amplitude, stability=True,
        stability_harmonics=15,
    )  # fmt: skip
    assert b.settings["engine"] == "FirstOrderEngine" and b.settings["n_samples"] == 128
    np.testing.assert_array_equal(a.converged, b.converged)
    np.testing.assert_allclose(b.amplitude_m.data, a.amplitude_m.data, rtol=1e-12)
    np.testing.assert_allclose(b.max_multiplier.data, a.max_multiplier.data, rtol=1e-9)
    np.testing.assert_array_equal(a.stable.data, b.stable.data)
    ka = frequency_response(sys, "brute", freq_hz=[0.9, 1.6])
    kb = frequency_response(form, "brute", freq_hz=[0.9, 1.6], amplitude=sys.input_amplitude)
    assert kb.converged.all()
    np.testing.assert_allclose(kb.amplitude_m.data, ka.amplitude_m.data, rtol=1e-7)
