"""A generated road's wheel heights: the road's own Fourier series evaluated where each
wheel is (the front wheels between the road's samples, not interpolated)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from inerterlab.vehicles import example_vehicle_path, load_vehicle
from inerterlab.vehicles.roads import generate_tracks, road_spectrum, track_coefficients
from inerterlab.vehicles.spectral import generated_road

# 17 m/s with 2 ms samples: 34 mm apart, so the example car's front wheels (a wheelbase
# of 2.6 m ahead) sit between the samples
SPEED, DT = 17.0, 0.002


def test_generated_road_is_the_generated_tracks_series():
    p = load_vehicle(example_vehicle_path())
    road = road_spectrum("C")
    width = 0.5 * (p.front_track + p.rear_track)
    g = generated_road(p, road, length=200.0, speed=SPEED, dt=DT, track=width, seed=4)
    x, zl, zr = generate_tracks(road, length=200.0, step=SPEED * DT, track=width, seed=4)
    nt = g.shape[0]
    # the rear wheels are on the sample grid: the same numbers as the written profile
    np.testing.assert_allclose(g[:, 2], zl[:nt], atol=1e-15)
    np.testing.assert_allclose(g[:, 3], zr[:nt], atol=1e-15)
    # the front wheels: the trigonometric series summed directly
    dx, n, cl, _ = track_coefficients(road, length=200.0, step=SPEED * DT, track=width, seed=4)
    count = 2 * (n.size - 1)
    for row in (1, 7, 1234):
        ph = np.exp(2j * math.pi * n * (row * dx + p.wheelbase))
        z = (2.0 * np.sum(cl * ph).real - cl[0].real) / count
        assert g[row, 0] == pytest.approx(z, abs=1e-14)
    # a half car's wheels are the left track's
    h = generated_road(p.half_car(), road, length=200.0, speed=SPEED, dt=DT, track=width, seed=4)
    np.testing.assert_array_equal(h, g[:, [0, 2]])
