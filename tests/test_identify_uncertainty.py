"""Trustworthy identification: the full parameter covariance of a fit."""

import dataclasses
import math

import numpy as np
import pytest

from inerterlab.devices import device_preset
from inerterlab.identify import identify, simulate_rig
from inerterlab.identify.fit import _sandwich


def _short_screw_fit(**kwargs):
    # appendix-a2 cut to 2 s per test at 200 Hz: 20+ identification tests -> jackknife
    dev = device_preset("screw")
    data = simulate_rig(dev, matrix="appendix-a2", seed=3, max_duration=2.0, sample_rate=200)
    start = dataclasses.replace(dev, stiffness=dev.stiffness * 1.2, damping=dev.damping * 0.9)
    return identify(data, start, **kwargs)


def test_covariance_diagonal_matches_the_printed_intervals():
    fit = _short_screw_fit()
    cov = fit.covariance
    assert fit.parameter_order == ("stiffness", "damping", "friction")
    assert cov.shape == (3, 3)
    assert np.allclose(cov, cov.T)
    assert np.linalg.eigvalsh(cov).min() >= -1e-12 * np.abs(cov).max()
    for i, name in enumerate(fit.parameter_order):
        p = fit.parameters[name]
        half = 0.5 * (p.ci95[1] - p.ci95[0])
        assert p.quantile > 1.9
        assert np.sqrt(cov[i, i]) == pytest.approx(p.std_error, rel=1e-12)
        assert half / p.quantile == pytest.approx(np.sqrt(cov[i, i]), rel=1e-9)
    # the screw's stiffness and damping are estimated from the same sines: correlated
    corr = fit.correlation()
    assert np.allclose(np.diag(corr), 1.0)
    assert np.abs(corr[np.triu_indices(3, 1)]).max() > 0.05
    # propagation carries each parameter's printed interval (t quantile) by default
    from inerterlab.identify.propagate import _source

    _, wide, _ = _source(fit)
    _, raw, _ = _source(fit, widen=False)
    assert np.allclose(raw, cov)
    for i, name in enumerate(fit.parameter_order):
        p = fit.parameters[name]
        assert 1.959964 * np.sqrt(wide[i, i]) == pytest.approx(0.5 * (p.ci95[1] - p.ci95[0]))
    assert np.allclose(wide / np.sqrt(np.outer(np.diag(wide), np.diag(wide))), corr)
    d = fit.to_dict()["covariance"]
    assert d["parameters"] == list(fit.parameter_order)
    assert np.allclose(d["matrix"], cov)


def test_fixed_parameter_has_zero_rows():
    fit = _short_screw_fit(fixed=("friction",))
    cov = fit.covariance
    assert np.all(cov[2] == 0) and np.all(cov[:, 2] == 0)
    assert cov[0, 0] > 0 and cov[1, 1] > 0
    assert fit.parameters["friction"].ci95 == (fit.parameters["friction"].value,) * 2


def test_jackknife_covariance_is_the_leave_one_test_out_spread():
    # plain least squares in a linear model: the one-step leave-one-test-out estimate
    # is exact, so the jackknife covariance (off-diagonal included) must equal
    # (G - 1)/G sum (theta_-g - mean)(theta_-g - mean)^T of actual refits
    rng = np.random.default_rng(11)
    G, n = 10, 40
    X = np.column_stack([rng.standard_normal(G * n), rng.standard_normal(G * n) + 0.5])
    X[:, 1] += 0.7 * X[:, 0]  # correlated columns -> correlated estimates
    y = X @ np.array([1.0, 2.0]) + rng.standard_normal(G * n) * (1 + np.repeat(np.arange(G), n))
    th = np.linalg.lstsq(X, y, rcond=None)[0]
    spread = _sandwich(X, X @ th - y, "linear", 1.0, [n] * G, interval="jackknife")
    loo = []
    for g in range(G):
        keep = np.ones(G * n, bool)
        keep[g * n : (g + 1) * n] = False
        loo.append(np.linalg.lstsq(X[keep], y[keep], rcond=None)[0])
    D = np.array(loo) - np.mean(loo, axis=0)
    expect = D.T @ D * (G - 1) / G
    assert np.allclose(spread.cov, expect, rtol=1e-8)
    assert abs(expect[0, 1]) > 0.1 * np.sqrt(expect[0, 0] * expect[1, 1])


# -- propagation to ride metrics -------------------------------------------------------
def _agree(a, b, tol=0.1):
    """Both intervals' ends within tol x the (delta) interval width."""
    width = a["ci95"][1] - a["ci95"][0]
    return (
        abs(a["ci95"][0] - b["ci95"][0]) <= tol * width
        and abs(a["ci95"][1] - b["ci95"][1]) <= tol * width
    )


def test_delta_is_exact_and_monte_carlo_agrees_for_a_linear_metric():
    # g = a . theta: var g = a^T Sigma a exactly, including the strong negative
    # correlation (ignoring it would give sqrt(sum a_i^2 Sigma_ii), 2.4 x too wide)
    from inerterlab.identify import propagate_function

    a = np.array([2.0, 3.0])
    mean = np.array([10.0, 5.0])
    cov = np.array([[1.0, -0.8 * 0.5], [-0.8 * 0.5, 0.25]]) * 0.04
    f = lambda th: {"g": float(a @ th)}  # noqa: E731
    d = propagate_function(f, mean, cov, method="delta")["g"]
    exact = np.sqrt(a @ cov @ a)
    assert d["value"] == pytest.approx(35.0)
    assert d["std"] == pytest.approx(exact, rel=1e-9)
    assert d["ci95"][1] - d["value"] == pytest.approx(1.959964 * exact, rel=1e-6)
    assert np.sqrt(a**2 @ np.diag(cov)) > 2 * exact
    mc = propagate_function(f, mean, cov, method="monte-carlo", n=4000, seed=1)["g"]
    assert mc["std"] == pytest.approx(exact, rel=0.05)
    assert _agree(d, mc)


def test_linear_car_h2_delta_and_monte_carlo_agree():
    # H2 norms of the linear traditional car against its damper and spring, with a
    # covariance small enough that the norm is linear over its spread
    from inerterlab import quarter_car
    from inerterlab.identify import propagate

    def car(p):
        return quarter_car("traditional", damping=p["damping"], stiffness=p["stiffness"])

    src = (
        [5000.0, 90_000.0],
        np.array([[50.0**2, 0.3 * 50 * 900], [0.3 * 50 * 900, 900.0**2]]),
        ["damping", "stiffness"],
    )
    d = propagate(src, car, method="delta")
    mc = propagate(src, car, method="monte-carlo", n=600, seed=2)
    for k in (
        "h2_body_acc",
        "h2_body_acc_wk",
        "h2_tyre_grip",
        "h2_suspension_deflection",
        "body_resonance_hz",
    ):
        assert d[k]["std"] > 0, k
        assert mc[k]["value"] == d[k]["value"]
        assert _agree(d[k], mc[k]), (k, d[k], mc[k])
    # the plug-in H2 is the package's own h2_norms
    from inerterlab.metrics import h2_norms

    assert d["h2_body_acc_wk"]["value"] == pytest.approx(
        h2_norms(car({"damping": 5000.0, "stiffness": 90_000.0}))["body_acc_wk"], rel=1e-12
    )


@pytest.mark.slow
def test_linearised_device_car_matches_its_simulation_on_a_random_road():
    # statistical linearisation of the friction (and flywheel) on the road it is used on
    from inerterlab import quarter_car
    from inerterlab.excitation import iso8608
    from inerterlab.identify import linearised_car, ride_metrics
    from inerterlab.identify.propagate import _road_scale
    from inerterlab.metrics import h2_norms_state_space

    car = quarter_car("device")
    lin = linearised_car(car, road_class="C", speed=20.0)
    ((arg, c_f),) = lin.info["equivalents"].values()  # the device's friction
    assert arg == "velocity"
    # F tanh(v / v_eps) with v_eps far below sigma: near the sign law's F sqrt(2/pi) / sigma
    (sigma,) = lin.info["argument_rms"].values()
    dev = car.info["model"].device
    assert c_f == pytest.approx(dev.friction * math.sqrt(2.0 / math.pi) / sigma, rel=2e-3)
    sim = ride_metrics(car, iso8608("C", 20.0, seed=2), 30.0, linear=False)
    n = h2_norms_state_space(lin).norms
    s = _road_scale("C", 20.0)
    assert n["body_acc_wk"] * s == pytest.approx(sim["rms_body_acc_wk"], rel=0.05)
    assert n["tyre_grip"] * s == pytest.approx(sim["rms_tyre_grip"], rel=0.05)


def test_propagate_device_car_from_a_covariance():
    from inerterlab import quarter_car
    from inerterlab.excitation import drop
    from inerterlab.identify import propagate

    cov = np.diag([3e4**2, 200.0**2, 10.0**2])
    src = ([7.76e5, 8100.0, 190.0], cov, ["stiffness", "damping", "friction"])
    out = propagate(src, quarter_car("device-afw"), drop(0.05), 3.0, method="delta")
    for k in (
        "rms_body_acc",
        "rms_body_acc_wk",
        "rms_tyre_grip",
        "rms_deflection",
        "h2_body_acc",
        "body_resonance_hz",
    ):
        assert out[k]["ci95"][0] < out[k]["value"] < out[k]["ci95"][1], k
    # zero covariance: zero width
    zero = propagate((src[0], 0 * cov, src[2]), quarter_car("device"), None, method="delta")
    assert zero["h2_body_acc"]["std"] == 0.0


def test_propagate_refuses_a_bad_covariance():
    from inerterlab import quarter_car
    from inerterlab.errors import ParameterError
    from inerterlab.identify import propagate

    with pytest.raises(ParameterError, match="semi-definite"):
        propagate(
            ([1.0, 2.0], [[1.0, 2.0], [2.0, 1.0]], ["damping", "friction"]), quarter_car("device")
        )
    with pytest.raises(ParameterError, match="2 x 2"):
        propagate(([1.0, 2.0], np.eye(3), ["damping", "friction"]), quarter_car("device"))


# -- the car file and the CLI ----------------------------------------------------------
CAR_TOML = """
suspension = "device"
friction_velocity = "1 mm/s"

[car]
sprung_mass = "370 kg"
stiffness = "90 kN/m"
damping = "5000 N s/m"

[road]
type = "drop"
height = "50 mm"
horizon = "3 s"

[propagation]
method = "delta"
"""


def test_car_file_reads_units(tmp_path):
    from inerterlab.identify.carfile import load_car_file

    p = tmp_path / "car.toml"
    p.write_text(CAR_TOML)
    cf = load_car_file(p)
    assert cf.car.suspension == "device"
    assert cf.car.parameters.stiffness == 90_000.0
    assert cf.car.device.friction_velocity == pytest.approx(1e-3)
    assert cf.excitation.height == pytest.approx(0.05)
    assert cf.horizon == 3.0 and cf.method == "delta"


@pytest.mark.parametrize(
    ("change", "key"),
    [
        (('stiffness = "90 kN/m"', "stiffness = 90000"), "car.stiffness"),
        (('sprung_mass = "370 kg"', 'sprung_mass = "370 lb"'), "car.sprung_mass"),
        (('height = "50 mm"', 'heigth = "50 mm"'), "road.heigth"),
        (('suspension = "device"', 'suspension = "afw"'), "suspension"),
        (('method = "delta"', 'method = "exact"'), "propagation.method"),
        (('sprung_mass = "370 kg"', 'sprung_mass = "-3 kg"'), "car.sprung_mass"),
    ],
)
def test_car_file_errors_name_file_and_key(tmp_path, change, key):
    from inerterlab.errors import DataFileError
    from inerterlab.identify.carfile import load_car_file

    p = tmp_path / "car.toml"
    p.write_text(CAR_TOML.replace(*change))
    with pytest.raises(DataFileError) as e:
        load_car_file(p)
    assert str(p) in str(e.value) and key in str(e.value)
    assert e.value.line is not None


def test_cli_identify_propagate(tmp_path):
    import json
    import subprocess
    import sys

    run = lambda *a: subprocess.run(  # noqa: E731
        [sys.executable, "-c", "import sys; from inerterlab.cli import main; sys.exit(main())", *a],
        capture_output=True,
        text=True,
    )
    out = run(
        "rig-simulate",
        "--device",
        "screw",
        "--matrix",
        "appendix-a2",
        "--max-duration",
        "0.5",
        "--sample-rate",
        "100",
        "--seed",
        "1",
        "--out",
        str(tmp_path / "d"),
    )
    assert out.returncode == 0, out.stderr
    car = tmp_path / "car.toml"
    car.write_text(CAR_TOML)
    out = run(
        "identify",
        "--device",
        "screw",
        "--data",
        str(tmp_path / "d"),
        "--json",
        "--propagate",
        str(car),
    )
    assert out.returncode == 0, out.stderr
    res = json.loads(out.stdout)
    rm = res["ride_metrics"]
    for k in (
        "rms_body_acc",
        "rms_body_acc_wk",
        "rms_tyre_grip",
        "rms_deflection",
        "h2_body_acc",
        "body_resonance_hz",
    ):
        assert rm[k]["ci95"][0] <= rm[k]["value"] <= rm[k]["ci95"][1], k
    assert len(res["covariance"]["matrix"]) == 3
    car.write_text(CAR_TOML.replace('"5000 N s/m"', "5000"))
    bad = run(
        "identify", "--device", "screw", "--data", str(tmp_path / "d"), "--propagate", str(car)
    )
    assert bad.returncode == 2
    assert "car.toml" in bad.stderr and "car.damping" in bad.stderr


# -- Sobol indices ---------------------------------------------------------------------
def test_sobol_reproduces_the_ishigami_indices():
    # Ishigami, a = 7, b = 0.1, x uniform on [-pi, pi]^3: known S1 = 0.314, 0.442, 0 and
    # ST = 0.558, 0.442, 0.244; x3 acts only through its interaction with x1
    from inerterlab.identify.sensitivity import sobol_indices

    def f(X):
        return {
            "y": np.sin(X[:, 0]) + 7 * np.sin(X[:, 1]) ** 2 + 0.1 * X[:, 2] ** 4 * np.sin(X[:, 0])
        }

    r = sobol_indices(f, {f"x{i}": (-np.pi, np.pi) for i in (1, 2, 3)}, n=2048, vectorized=True)
    t = r.to_pandas().set_index("parameter")
    assert r.runs == 2048 * 5
    for name, s1, st in (("x1", 0.314, 0.558), ("x2", 0.442, 0.442), ("x3", 0.0, 0.244)):
        assert abs(t.loc[name, "S1"] - s1) <= t.loc[name, "S1_conf"], (name, t.loc[name])
        assert abs(t.loc[name, "ST"] - st) <= t.loc[name, "ST_conf"], (name, t.loc[name])
        assert t.loc[name, "S1_conf"] < 0.08 and t.loc[name, "ST_conf"] < 0.08


def test_ride_sensitivity_table_and_plot():
    from matplotlib.figure import Figure

    from inerterlab import quarter_car
    from inerterlab.excitation import drop
    from inerterlab.identify.sensitivity import ride_sensitivity

    r = ride_sensitivity(quarter_car("device-afw"), drop(0.05), 2.0, n=8, seed=1)
    t = r.to_pandas()
    assert set(t["parameter"]) == {"stiffness", "damping", "friction", "changing_ratio"}
    assert set(t["output"]) == {
        "rms_body_acc",
        "rms_body_acc_wk",
        "rms_tyre_grip",
        "rms_deflection",
    }
    assert r.bounds["damping"] == pytest.approx((8100 * 0.8, 8100 * 1.2))
    assert r.runs == 8 * 6
    assert np.all(np.isfinite(t[["S1", "ST"]].to_numpy()))
    fig = r.plot(title="drop")
    assert isinstance(fig, Figure) and len([a for a in fig.axes if a.get_visible()]) == 4


# -- D-optimal campaign design ---------------------------------------------------------
def _design_candidates():
    from inerterlab.identify import TestSpec

    rows = [("sine", f, a) for f in (0.5, 1.0, 2.0, 4.0) for a in (0.005, 0.02)]
    rows += [("triangle", 0.5, 0.02), ("triangle", 1.0, 0.01)]
    return [
        TestSpec(
            number=i, signal=s, frequency=f, amplitude=a, duration=2.0, purpose="identification"
        )
        for i, (s, f, a) in enumerate(rows)
    ]


def test_d_optimal_design_finds_the_best_subset_and_predicts_the_fit():
    import itertools

    from inerterlab.identify import simulate_rig
    from inerterlab.identify.design import design_campaign

    dev = device_preset("screw")
    cands = _design_candidates()
    # the former default window (0.1 s), on design and fit alike: with 0.16 s these
    # candidates leave the first four tests within 1 of the optimum's log det
    d = design_campaign(dev, 4, matrix=cands, sample_rate=200, noise=5.0, reversal_window=0.1)
    info = d.information
    assert info.shape == (10, 3, 3)

    def logdet(idx):
        return np.linalg.slogdet(info[list(idx)].sum(axis=0))[1]

    best = max(itertools.combinations(range(10), 4), key=logdet)
    assert logdet(d.indices) == pytest.approx(logdet(best), abs=1e-9)
    assert logdet(d.indices) > logdet(range(4)) + 1.0  # not just the first tests
    tab = d.to_pandas()
    assert np.all(tab["ratio"] >= 1.0) and d.efficiency() < 1.0
    # the predicted standard errors are those of the fit on the chosen tests
    data = simulate_rig(
        dev,
        matrix=d.chosen,
        sample_rate=200,
        noise=5.0,
        displacement_noise=0.0,
        velocity_noise=0.0,
        spikes=False,
        seed=5,
    )
    fit = identify(data, dev, loss="linear", reversal_window=0.1)
    for name, se in zip(d.names, d.standard_errors(), strict=True):
        assert 0.7 < fit.parameters[name].std_error / se < 1.4, (name, fit.parameters[name], se)


# -- the default interval: sandwich with an autoregressive noise model ------------------
def _regression_replications(noise, reps, *, seed=5, tests=10, n=300):
    """Least squares y = X theta + e over ``tests`` records of n samples, X smooth
    (sine, cosine of a slow motion, as a rig's x and v), e from ``noise(rng, n)`` per
    record. Returns the errors, the sandwich standard errors and quantiles, and the
    exact covariance (X^T X)^-1 X^T Sigma X (X^T X)^-1 from the noise's autocovariance."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.005
    X = np.concatenate(
        [
            np.column_stack([np.sin(2 * np.pi * f * t + ph), np.cos(2 * np.pi * f * t + ph)])
            for f, ph in zip(rng.uniform(0.2, 2.0, tests), rng.uniform(0, 6.3, tests), strict=True)
        ]
    )
    theta = np.array([1.0, -2.0])
    err, se, q = [], [], []
    for _ in range(reps):
        y = X @ theta + np.concatenate([noise(rng, n) for _ in range(tests)])
        th = np.linalg.lstsq(X, y, rcond=None)[0]
        spread = _sandwich(X, X @ th - y, "linear", 1.0, [n] * tests)
        err.append(th - theta)
        se.append(spread.se)
        q.append(spread.quantile)
    return np.array(err), np.array(se), np.array(q), X, spread


def _exact_covariance(X, acov, tests, n):
    """(X^T X)^-1 X^T Sigma X (X^T X)^-1 with Sigma block-Toeplitz from ``acov``."""
    lag = np.abs(np.subtract.outer(np.arange(n), np.arange(n)))
    S = np.where(lag < acov.size, acov[np.minimum(lag, acov.size - 1)], 0.0)
    A = np.linalg.inv(X.T @ X)
    mid = sum(X[g * n : (g + 1) * n].T @ S @ X[g * n : (g + 1) * n] for g in range(tests))
    return A @ mid @ A


def _check_calibrated(err, se, q, cov):
    true_se = np.sqrt(np.diag(cov))
    # the stated standard errors match the exact ones on average, and the spread of
    # the estimates (a check of the exact formula itself)
    assert np.allclose(se.mean(axis=0) / true_se, 1.0, atol=0.1), se.mean(axis=0) / true_se
    assert np.allclose(err.std(axis=0) / true_se, 1.0, atol=0.12), err.std(axis=0) / true_se
    cover = (np.abs(err) <= q * se).mean(axis=0)
    # 95 % nominal; over 300 replications the binomial standard error is 1.3 %
    assert np.all((cover >= 0.91) & (cover <= 0.99)), cover


def test_sandwich_intervals_cover_with_ar1_noise():
    # e_i = 0.7 e_(i-1) + N(0, 1) (stationary start): the long-run variance is
    # (1 + phi)/(1 - phi) = 5.7 x the variance, so white-noise intervals would cover
    # only ~60 %; the flat-top HAC meat must recover the exact covariance
    phi, reps, tests, n = 0.7, 300, 10, 300

    def ar1(rng, m):
        e = np.empty(m)
        e[0] = rng.standard_normal() / np.sqrt(1 - phi**2)
        w = rng.standard_normal(m)
        for i in range(1, m):
            e[i] = phi * e[i - 1] + w[i]
        return e

    err, se, q, X, spread = _regression_replications(ar1, reps, tests=tests, n=n)
    acov = phi ** np.arange(n) / (1 - phi**2)
    _check_calibrated(err, se, q, _exact_covariance(X, acov, tests, n))
    assert spread.interval[0].startswith("sandwich, AR(")
    assert np.all(q == pytest.approx(1.959964))


def test_sandwich_intervals_cover_with_differenced_noise():
    # e = 5 (w_i - w_(i-1)) + white: like the screw's residual (motion noise
    # differentiated through the inertance), large but with a small long-run variance
    # at the slow regressors; the Bartlett (Newey-West) weights overstate it several
    # fold, the flat top must not
    reps, tests, n = 300, 10, 300

    def diff_noise(rng, m):
        w = rng.standard_normal(m + 1)
        return 5.0 * np.diff(w) + rng.standard_normal(m)

    err, se, q, X, _ = _regression_replications(diff_noise, reps, seed=9, tests=tests, n=n)
    acov = np.array([2 * 25.0 + 1.0, -25.0])
    _check_calibrated(err, se, q, _exact_covariance(X, acov, tests, n))


@pytest.mark.parametrize("name", ["device", "device-afw", "afw"])
def test_linearised_car_is_its_own_fixed_point(name):
    """Each equivalent is its element's Gaussian gain at its argument's RMS, and that RMS
    is the one of the equivalent car under the class C road's white velocity: the
    argument's row from the car's outputs, an independent Lyapunov solve (scipy) on
    the state space the function returns."""
    from scipy.linalg import solve_continuous_lyapunov

    from inerterlab import quarter_car
    from inerterlab.identify import linearised_car
    from inerterlab.identify.propagate import _road_scale
    from inerterlab.systems.gaussian import gaussian_gains

    car = quarter_car(name)
    lin = linearised_car(car, road_class="C", speed=20.0)
    assert lin.info["iterations"] >= 2 and lin.info["equivalents"]
    P = solve_continuous_lyapunov(lin.A, -np.outer(lin.B, lin.B))
    names = list(lin.state_names)
    for el, (arg, g) in lin.info["equivalents"].items():
        sigma = lin.info["argument_rms"][el]
        assert g == pytest.approx(gaussian_gains(car, car.element_names.index(el), sigma), rel=1e-8)
        # the strut's elements sit between the body (or the device's node) and the wheel
        assert arg in ("velocity", "acceleration")
    # the flywheel's argument (and the friction's beside it): the relative velocity of
    # the branch's ends, both states where the branch has a mass of its own
    if name == "device":  # its branch node is massless: its velocity is not a state
        return
    top = "hyd.n3.v" if name == "device-afw" else "body.v"
    c = np.zeros(len(names))
    c[names.index(top)] = 1.0
    c[names.index("wheel.v")] = -1.0
    s = _road_scale("C", 20.0) * math.sqrt(c @ P @ c)
    for el in lin.info["argument_rms"]:
        assert lin.info["argument_rms"][el] == pytest.approx(s, rel=1e-7)


def test_linearised_car_from_a_nearby_fixed_point():
    """Started from the equivalents of a car nearby (as a propagation's draws start from
    the estimate's), the same fixed point in fewer passes; a start that names other
    elements is refused by name."""
    from inerterlab import quarter_car
    from inerterlab.errors import ParameterError
    from inerterlab.identify import linearised_car
    from inerterlab.identify.propagate import device_car

    car = quarter_car("device-afw")
    near = linearised_car(device_car(car, {"damping": 8400.0, "friction": 200.0}))
    cold = linearised_car(car)
    warm = linearised_car(car, start=near.info["equivalents"])
    assert warm.info["iterations"] < cold.info["iterations"]
    for name, (arg, g) in cold.info["equivalents"].items():
        assert warm.info["equivalents"][name][0] == arg
        assert warm.info["equivalents"][name][1] == pytest.approx(g, rel=1e-9)
    np.testing.assert_allclose(warm.A, cold.A, rtol=1e-9, atol=1e-9 * np.abs(cold.A).max())
    with pytest.raises(ParameterError, match="start"):
        linearised_car(car, start={"hyd.fric": 3000.0})
