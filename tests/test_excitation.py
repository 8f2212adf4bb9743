"""Road inputs: segments, user files, ISO 8608 roads."""

import numpy as np
import pytest
from scipy.signal import periodogram, welch

from inerterlab.errors import DataFileError, ParameterError
from inerterlab.excitation import (
    bump,
    drop,
    iso8608,
    iso8608_psd,
    read_road_csv,
    road_displacement,
    sine,
)


def test_segments_and_road_values():
    seg = bump(0.05, duration=0.01).segments(1.0)
    x, v = road_displacement(seg, [0.0, 0.005, 0.01, 0.5])
    np.testing.assert_allclose(x, [0.05, 0.05, 0.0, 0.0])
    seg = bump(0.04, duration=0.2, shape="1-cos", start=0.1).segments(1.0)
    x, v = road_displacement(seg, [0.05, 0.1, 0.2, 0.3, 0.4])
    np.testing.assert_allclose(x, [0.0, 0.0, 0.04, 0.0, 0.0], atol=1e-15)
    x, v = road_displacement(sine(0.05, 5.0).segments(2.0), [0.05])
    assert x[0] == pytest.approx(0.05) and v[0] == pytest.approx(0.0, abs=1e-12)
    assert drop(displaced="sprung").initial_displacements == (0.0, 0.05)
    with pytest.raises(ParameterError, match="shape"):
        bump(shape="square")


def test_csv_road_round_trip_and_errors(tmp_path):
    p = tmp_path / "road.csv"
    p.write_text("# measured road\ntime,displacement\n0,0\n0.1,0.01\n0.2,0.0\n")
    r = read_road_csv(p)
    np.testing.assert_allclose(r.displacement, [0, 0.01, 0])
    bad = tmp_path / "bad.csv"
    bad.write_text("time,displacement\n0,0\n0.1,nan\n")
    with pytest.raises(
        DataFileError, match=r"bad.csv, line 3: displacement value .nan. is not finite"
    ):
        read_road_csv(bad)
    bad.write_text("0,0\n0.1,abc\n")
    with pytest.raises(DataFileError, match="line 2"):
        read_road_csv(bad)
    bad.write_text("0,0\n0.1,0.2\n0.05,0\n")
    with pytest.raises(DataFileError, match="line 3: time"):
        read_road_csv(bad)
    with pytest.raises(DataFileError, match="cannot read"):
        read_road_csv(tmp_path / "missing.csv")


@pytest.mark.parametrize("road_class", ["A", "C", "E"])
def test_iso8608_profile_matches_target_psd(road_class):
    """Stated tolerance: Welch PSD (65536-sample Hann segments) within 10 % of Gd in every
    octave band from 0.02 to 5.12 cycle/m; the full-length periodogram equals Gd."""
    road = iso8608(road_class, 20.0, seed=3, length=2000.0)
    x, z = road.profile()
    dx = x[1] - x[0]
    f, g = welch(z[:-1], fs=1.0 / dx, nperseg=2**16, detrend=False)
    fp, gp = periodogram(z[:-1], fs=1.0 / dx, window="boxcar", detrend=False)
    for lo in 0.02 * 2.0 ** np.arange(8):
        band = (f >= lo) & (f < 2 * lo)
        ratio = g[band].mean() / iso8608_psd(f[band], road_class).mean()
        assert ratio == pytest.approx(1.0, abs=0.10), lo
        band = (fp >= lo) & (fp < 2 * lo)
        ratio = gp[band].mean() / iso8608_psd(fp[band], road_class).mean()
        assert ratio == pytest.approx(1.0, rel=1e-9), lo
    # nothing outside the 0.01-10 cycle/m band
    assert np.all(gp[(fp > 10.01) | ((fp > 0) & (fp < 0.0099))] < 1e-20)


def test_iso8608_seed_and_validation():
    a = iso8608("C", 10.0, seed=1).profile(10.0)[1]
    b = iso8608("C", 10.0, seed=1).profile(10.0)[1]
    c = iso8608("C", 10.0, seed=2).profile(10.0)[1]
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    with pytest.raises(ParameterError, match="road_class"):
        iso8608("Z")
    with pytest.raises(ParameterError, match="spatial_step"):
        iso8608("C", spatial_step=0.2)
