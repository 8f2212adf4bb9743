"""Road tracks: isotropic coherence, generated tracks, ISO 8608 classification, IRI."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from inerterlab.errors import ParameterError
from inerterlab.vehicles.roads import (
    GOLDEN_CAR,
    _golden_matrices,
    class_bounds,
    fit_iso8608,
    generate_tracks,
    iri,
    iso8608_class,
    isotropic_coherence,
    road_spectrum,
)


@pytest.mark.parametrize("waviness", [2.0, 2.5])
def test_isotropic_coherence_matches_quadrature(waviness):
    # cross / auto spectral density of parallel tracks on a surface with 2-D spectrum
    # |k|^-(w+1): integrate across the tracks numerically
    track = 1.5
    for n in (0.02, 0.1, 0.3, 1.0):

        def s2(m, n=n):
            return (n * n + m * m) ** (-(waviness + 1) / 2)

        auto = quad(s2, 0, np.inf)[0]
        cross = quad(s2, 0, np.inf, weight="cos", wvar=2 * math.pi * track)[0]
        assert isotropic_coherence(n, track, waviness) == pytest.approx(cross / auto, rel=1e-7)


def test_isotropic_coherence_limits():
    assert float(isotropic_coherence(0.0, 1.5)) == 1.0
    assert float(isotropic_coherence(100.0, 1.5)) < 1e-100
    r = isotropic_coherence(np.geomspace(0.01, 10, 50), 1.5)
    assert np.all(np.diff(r) < 0)


def test_class_bounds_and_lookup():
    assert class_bounds("A") == (0.0, 32e-6)
    assert class_bounds("C") == (128e-6, 512e-6)
    assert iso8608_class(256e-6) == "C"
    assert iso8608_class(1e-3) == "D"
    assert iso8608_class(1.0) == "H"


def test_generated_tracks_have_the_spectrum_and_the_coherence():
    from scipy.signal import csd, welch

    road = road_spectrum("D")
    x, zl, zr = generate_tracks(road, length=20000.0, step=0.1, track=1.5, seed=3)
    n, gl = welch(zl, fs=10.0, nperseg=2000)
    _, gr = welch(zr, fs=10.0, nperseg=2000)
    _, glr = csd(zl, zr, fs=10.0, nperseg=2000)
    band = (n > 0.05) & (n < 2.0)
    # averages over the band: Welch's estimate with ~40 segments has ~16 % scatter per bin
    assert np.mean(gl[band] / road.psd(n[band])) == pytest.approx(1.0, abs=0.05)
    assert np.mean(gr[band] / road.psd(n[band])) == pytest.approx(1.0, abs=0.05)
    mid = (n > 0.05) & (n < 0.3)
    ratio = np.mean(glr[mid].real / gl[mid]) / np.mean(isotropic_coherence(n[mid], 1.5))
    assert ratio == pytest.approx(1.0, abs=0.08)


@pytest.mark.parametrize("road_class", list("ABCDEFGH"))
def test_generated_road_is_classified_into_its_class(road_class):
    road = road_spectrum(road_class)
    x, z, _ = generate_tracks(road, length=2000.0, step=0.05, seed=11)
    fit = fit_iso8608(x, z)
    assert fit["road_class"] == road_class
    assert fit["gd_n0"] == pytest.approx(road.gd_n0, rel=0.15)
    free = fit_iso8608(x, z, waviness=None)
    assert free["waviness"] == pytest.approx(2.0, abs=0.1)


def test_iri_of_a_pure_slope_is_zero():
    x = np.arange(0, 500.0, 0.25)
    assert iri(x, 0.01 * x + 0.3) == pytest.approx(0.0, abs=1e-12)


def _golden_relative_velocity_gain(wavelength):
    """|z_s' - z_u'| per unit profile height at the golden car's speed."""
    A, B = _golden_matrices()
    w = 2 * math.pi * GOLDEN_CAR["speed"] / wavelength
    x = np.linalg.solve(1j * w * np.eye(4) - A, B)
    return abs(x[1] - x[3])


@pytest.mark.parametrize("wavelength", [1.0, 2.5, 15.0])
def test_iri_of_a_sine_follows_the_golden_car_response(wavelength):
    dx, amp = 0.05, 0.002
    x = np.arange(0, 4000.0, dx)
    z = amp * np.sin(2 * math.pi * x / wavelength)
    k = int(round(0.25 / dx))  # the moving average scales a sine by a discrete sinc
    smooth = math.sin(math.pi * k * dx / wavelength) / (k * math.sin(math.pi * dx / wavelength))
    # the golden car runs on the profile linear between samples: the sine's own
    # component of that polyline is scaled by sinc^2(pi dx / wavelength)
    smooth *= (math.sin(math.pi * dx / wavelength) / (math.pi * dx / wavelength)) ** 2
    # mean |sin| = 2/pi; IRI in m/km
    want = (
        2
        / math.pi
        * amp
        * smooth
        * _golden_relative_velocity_gain(wavelength)
        / GOLDEN_CAR["speed"]
        * 1000
    )
    assert iri(x, z) == pytest.approx(want, rel=5e-3)


def test_iri_errors():
    with pytest.raises(ParameterError, match="11 m"):
        iri(np.arange(0, 5, 0.25), np.zeros(20))
    with pytest.raises(ParameterError, match="evenly"):
        iri(np.array([0.0, 1.0, 3.0, 20.0]), np.zeros(4))
    with pytest.raises(ParameterError, match="coherence"):
        road_spectrum("C", coherence=1.5)


def test_iri_of_a_random_road_matches_gaussian_theory():
    # For a Gaussian profile, mean |z_s' - z_u'| = sqrt(2/pi) sigma, sigma^2 the integral
    # of |H|^2 times the profile PSD (here times sinc^4: the golden car runs on the
    # profile joined by straight lines, which scales each component by sinc^2).
    dx, v = 0.05, GOLDEN_CAR["speed"]
    road = road_spectrum("C", band=(0.01, 2.0))
    vals = []
    for seed in range(3):
        x, z, _ = generate_tracks(road, length=6000.0, step=dx, seed=seed)
        vals.append(iri(x, z, smoothing=None))
    n = np.linspace(0.01, 2.0, 20001)
    A, B = _golden_matrices()
    w = 2 * math.pi * n * v
    rhs = np.broadcast_to(B[:, None], (n.size, 4, 1))
    H = np.linalg.solve(1j * w[:, None, None] * np.eye(4) - A, rhs)[:, :, 0]
    gain = np.abs(H[:, 1] - H[:, 3]) ** 2 * np.sinc(n * dx) ** 4
    sigma = math.sqrt(np.trapezoid(gain * road.psd(n), n))
    want = math.sqrt(2 / math.pi) * sigma / v * 1000
    assert np.mean(vals) == pytest.approx(want, rel=0.03)
