"""Trustworthy identification: the full parameter covariance of a fit."""

import dataclasses

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
    spread = _sandwich(X, X @ th - y, "linear", 1.0, [n] * G)
    loo = []
    for g in range(G):
        keep = np.ones(G * n, bool)
        keep[g * n : (g + 1) * n] = False
        loo.append(np.linalg.lstsq(X[keep], y[keep], rcond=None)[0])
    D = np.array(loo) - np.mean(loo, axis=0)
    expect = D.T @ D * (G - 1) / G
    assert np.allclose(spread.cov, expect, rtol=1e-8)
    assert abs(expect[0, 1]) > 0.1 * np.sqrt(expect[0, 0] * expect[1, 1])
