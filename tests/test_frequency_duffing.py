"""Harmonic balance on the Duffing oscillator against published reference values.

NLvib example 01 (docs/model.md §10): mu x'' + zeta x' + kappa x + gamma x^3 = P cos(Omega t),
mu=1, zeta=0.05, kappa=1, gamma=0.1, P=0.18 (NLvib uses zeta as the damping
coefficient; see inerterlab/data/errata.md). These numbers come from an independent code.
"""

import numpy as np
import pytest

import _frequency_oracle as oracle
from inerterlab.errors import ParameterError
from inerterlab.frequency import (
    DuffingOscillator,
    UserSystem,
    continue_branch,
    floquet_multipliers,
    frequency_response,
    hill_exponents,
    make_engine,
    steady_state,
)
from inerterlab.frequency.harmonic import is_stable

DUFFING = DuffingOscillator.nlvib_example()


def _peak(path):
    a = np.hypot(path.coefficients[:, 1], path.coefficients[:, 2])
    i = int(np.argmax(a))
    # parabola through the three points around the maximum, in the path index
    s = np.arange(i - 1, i + 2)
    ca = np.polyfit(s, a[s], 2)
    cw = np.polyfit(s, path.omega[s], 2)
    s_star = -ca[1] / (2 * ca[0])
    return np.polyval(ca, s_star), np.polyval(cw, s_star)


@pytest.fixture(scope="module")
def path7():
    eng = make_engine(DUFFING, 7)
    return eng, continue_branch(eng, np.zeros(15), 0.8, 1.6, step=0.01, max_step=0.02)


def test_one_harmonic_peak():
    eng = make_engine(DUFFING, 1)
    path = continue_branch(eng, np.zeros(3), 0.8, 1.6, step=0.01, max_step=0.01)
    assert path.completed
    a, w = _peak(path)
    assert a == pytest.approx(2.8416, rel=1e-3)
    assert w == pytest.approx(1.2666, rel=1e-3)


def test_one_harmonic_balance_is_the_closed_form():
    """With one harmonic the balance of the cubic is exact on enough samples: the
    amplitude A solves ((k - m w^2 + 3/4 g A^2)^2 + (c w)^2) A^2 = P^2, and the peak lies
    on the backbone m w^2 = k + 3/4 g A^2 at A = P / (c w)."""
    m, c, k, g, p = 1.0, 0.05, 1.0, 0.1, 0.18
    freqs = np.array([0.05, 0.1, 0.15, 0.25, 0.4])  # Hz, below the fold: one solution
    fr = frequency_response(DUFFING, "shb", freq_hz=freqs)
    assert fr.converged.all() and fr.settings["engine"] == "FirstOrderEngine"
    a = fr.first_harmonic().data
    w = fr.omega
    closed = ((k - m * w**2 + 0.75 * g * a**2) ** 2 + (c * w) ** 2) * a**2
    np.testing.assert_allclose(closed, p**2, rtol=1e-9)
    path = continue_branch(make_engine(DUFFING, 1), np.zeros(3), 0.8, 1.6, step=0.01,
                           max_step=0.01)  # fmt: skip
    peak, wp = _peak(path)
    assert m * wp**2 == pytest.approx(k + 0.75 * g * peak**2, rel=2e-3)
    assert peak == pytest.approx(p / (c * wp), rel=2e-3)


def test_linear_limit_equals_transfer_function():
    """Without the cubic term the balance is the linear response P / |k - m w^2 + i c w|."""
    lin = DuffingOscillator(mass=2.0, damping=0.3, stiffness=5.0, cubic_stiffness=0.0, force=0.7)
    freqs = np.array([0.1, 0.25, 0.3, 0.5, 1.0])
    w = 2 * np.pi * freqs
    exact = 0.7 / np.abs(5.0 - 2.0 * w**2 + 0.3j * w)
    for method in ("shb", "mhb", "sihb"):
        fr = frequency_response(lin, method, freq_hz=freqs, direction="up")
        np.testing.assert_allclose(fr.amplitude_m.data, exact, rtol=1e-9, err_msg=method)
        assert fr.stable.all()


def test_seven_harmonics_peak(path7):
    _, path = path7
    assert path.completed
    a, w = _peak(path)
    assert a == pytest.approx(2.8302, rel=1e-3)
    assert w == pytest.approx(1.2687, rel=1e-3)


def _solutions_at(eng, path, omega):
    sols = []
    w = path.omega
    for i in np.flatnonzero(np.diff(np.sign(w - omega)) != 0):
        X, ok, *_ = eng.newton(path.coefficients[i], omega, 1e-12, 50, 1.0)
        assert ok
        sols.append(X)
    return sorted(sols, key=lambda X: -np.hypot(X[1], X[2]))


def test_three_solutions_and_stability(path7):
    eng, path = path7
    sols = _solutions_at(eng, path, 1.2)
    amps = [np.hypot(X[1], X[2]) for X in sols]
    np.testing.assert_allclose(amps, [2.5092, 2.2605, 0.4175], rtol=1e-3)
    period = 2 * np.pi / 1.2
    for X, expect_stable in zip(sols, [True, False, True], strict=True):
        lam = hill_exponents(eng, X, 1.2)
        assert is_stable(lam, 1.2) == expect_stable
        # Floquet multipliers from the time-domain monodromy matrix agree with Hill
        b = eng.basis
        state0 = [X @ b.E[0], 1.2 * (X @ b.E1[0])]
        mu = oracle.floquet_multipliers(DUFFING, 1.2, state0)
        np.testing.assert_allclose(np.sort(np.abs(floquet_multipliers(DUFFING, 1.2, state0))),
                                   np.sort(np.abs(mu)), rtol=1e-7)  # fmt: skip
        assert (np.max(np.abs(mu)) > 1.0) == (not expect_stable)
        hill_mu = np.sort(np.abs(np.exp(lam * period)))
        np.testing.assert_allclose(np.sort(np.abs(mu)), hill_mu, rtol=1e-4)


def test_time_integration_lands_on_outer_branches(path7):
    eng, path = path7
    sols = _solutions_at(eng, path, 1.2)
    low = steady_state(DUFFING, 1.2, rtol=1e-9)
    assert low.settled
    assert low.amplitude == pytest.approx(0.4175, rel=2e-3)  # half peak-to-peak ~ |X1| here
    b = eng.basis
    top = sols[0]
    high = steady_state(DUFFING, 1.2, initial_state=[top @ b.E[0], 1.2 * (top @ b.E1[0])])
    assert high.settled
    hb_amp = 0.5 * (np.max(b.E @ top) - np.min(b.E @ top))
    assert high.amplitude == pytest.approx(hb_amp, rel=1e-4)
    assert high.amplitude > 2.4


def test_analytic_jacobian_matches_finite_differences():
    eng = make_engine(DUFFING, 5)
    rng = np.random.default_rng(1)
    X = rng.normal(size=11)
    _, J = eng.residual_jacobian(X, 1.1)
    h = 1e-6
    fd = np.column_stack(
        [
            (eng.residual(X + h * e, 1.1) - eng.residual(X - h * e, 1.1)) / (2 * h)
            for e in np.eye(11)
        ]
    )
    np.testing.assert_allclose(J, fd, atol=1e-7 * np.abs(J).max())


def test_user_system_equals_builtin():
    def duffing(tau, omega, x, xd, xdd):
        return xdd + 0.05 * xd + x + 0.1 * x**3 - 0.18 * np.cos(tau)

    user = UserSystem(residual=duffing)
    a = frequency_response(user, "sihb", fmin=0.15, fmax=0.25, df=0.01, harmonics=5)
    b = frequency_response(DUFFING, "sihb", fmin=0.15, fmax=0.25, df=0.01, harmonics=5)
    assert a.settings["engine"] == b.settings["engine"] == "FirstOrderEngine"
    # the same points converge (one jump point past the lower fold may fail in both)
    np.testing.assert_array_equal(a.converged, b.converged)
    assert a.converged.sum() >= len(a) - 1
    ok = a.converged
    np.testing.assert_allclose(a.amplitude_m.data[ok], b.amplitude_m.data[ok], rtol=1e-9)
    np.testing.assert_array_equal(a.stable.data[ok], b.stable.data[ok])
    # both scans cover the hysteresis: the up scan climbs the upper branch
    assert b.amplitude_m.max() > 2.8


def test_sample_count_is_checked():
    with pytest.raises(ParameterError, match="n_samples"):
        make_engine(DUFFING, 7, 14)
    with pytest.warns(RuntimeWarning, match="alias"):
        make_engine(DUFFING, 7, 20)
    with pytest.raises(ParameterError, match="harmonics"):
        make_engine(DUFFING, 0)


def test_user_residual_numba_cannot_compile_is_refused():
    def residual(tau, omega, x, xd, xdd):
        import math  # an import inside the function: numba refuses to compile it

        return xdd + x * math.pi

    with pytest.raises(ParameterError, match="residual"):
        frequency_response(UserSystem(residual=residual), "mhb", freq_hz=[0.2], harmonics=3)


def test_stability_shared_only_between_one_solution():
    """Where the down and up scans meet one solution its stability is computed once;
    on the hysteresis band (two solutions at one frequency) each keeps its own. Every
    point's multiplier equals the one computed for that point alone."""
    from inerterlab.frequency.response import SAME_SOLUTION, _same_solution

    fr = frequency_response(DUFFING, "sihb", fmin=0.13, fmax=0.3, df=0.005, harmonics=5)
    n = len(fr)
    flat = fr.coefficients.reshape(n, -1)
    w = 2 * np.pi * fr.freq_hz
    first = _same_solution(w, flat, fr.converged, SAME_SOLUTION * fr.settings["rtol"])
    down = np.flatnonzero(fr.direction == "down")[::-1]  # ascending, as the up scan
    up = np.flatnonzero(fr.direction == "up")
    np.testing.assert_array_equal(w[down], w[up])
    gap = np.abs(fr.amplitude_m.data[up] - fr.amplitude_m.data[down])
    band, one = gap > 0.5, gap < 1e-6
    assert band.sum() >= 3 and one.sum() >= 10
    # the down scan is solved first: an up point on its solution takes its stability
    np.testing.assert_array_equal(first[up[one]], down[one])
    np.testing.assert_array_equal(first[up[band]], up[band])
    np.testing.assert_array_equal(first[down], down)
    eng = make_engine(DUFFING, 5)
    for i in np.flatnonzero(fr.converged):
        best, _ = eng.stability(w[i : i + 1], flat[i : i + 1], np.array([True]))
        np.testing.assert_allclose(fr.max_multiplier.data[i], np.exp(best[0] * 2 * np.pi / w[i]),
                                   rtol=1e-8)  # fmt: skip
        assert bool(fr.stable.data[i]) == bool(best[0] < 1e-7 * w[i])
