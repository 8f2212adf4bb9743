"""Road tracks for vehicles: ISO 8608 spectra, left/right coherence, generation,
classification of a measured profile and the International Roughness Index.

ISO 8608 (1995/2016) describes a road by its displacement PSD
Gd(n) = Gd(n0) (n/n0)^-w, n the spatial frequency [cycle/m], n0 = 0.1 cycle/m and the
waviness w = 2. Classes A to H have geometric means Gd(n0) = 16e-6 * 4^i m^3 and
bounds at half and twice the mean (A from 0, H open above).

Coherence of two parallel tracks a distance B apart. For a homogeneous *isotropic*
surface (Dodds and Robson, J. Sound Vib. 31 (1973) 175-183; Kamash and Robson,
J. Sound Vib. 57 (1978) 89-100) whose single-track PSD is C n^-w, the 2-D spectrum
is proportional to |k|^-(w+1), and integrating it across the tracks gives the ratio of
the cross-spectral density to the single-track PSD

    rho(n) = 2^(1 - nu) / Gamma(nu) x^nu K_nu(x),  x = 2 pi n B,  nu = w / 2,

(x K_1(x) for w = 2), real, 1 at n = 0 and falling towards 0 for wavelengths short
against B. ``rho`` here is that ratio (a correlation per frequency); the
magnitude-squared coherence is rho^2. The derivation uses the integral
int_0^inf cos(a m) (n^2 + m^2)^-(nu+1/2) dm = (a/2n)^nu sqrt(pi)/Gamma(nu+1/2) K_nu(a n);
``tests/test_roads.py`` checks the closed form against quadrature.

IRI (ASTM E1926; Sayers, Transp. Res. Rec. 1501, 1995): the "golden car", a quarter
car with per-unit-sprung-mass parameters k_t/m_s = 653 s^-2, k_s/m_s = 63.3 s^-2,
c_s/m_s = 6.0 s^-1, m_u/m_s = 0.15, driven at 80 km/h over the profile smoothed by a
250 mm moving average, starts with both masses on the profile moving at the slope of
its first 11 m; IRI is the mean |z_s' - z_u'| / V, reported in m/km.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, check_choice, check_positive, check_seed
from ..excitation import ISO8608_CLASSES, ISO8608_N0

__all__ = [
    "RoadSpectrum",
    "road_spectrum",
    "isotropic_coherence",
    "iso8608_class",
    "class_bounds",
    "generate_tracks",
    "track_coefficients",
    "fit_iso8608",
    "iri",
    "GOLDEN_CAR",
    "read_profile_csv",
    "read_track_pair",
    "TRACK_COLUMNS",
]

COHERENCE_MODELS = ("isotropic", "identical", "independent")
#: ASTM E1926 golden car, per unit sprung mass
GOLDEN_CAR = {"k1": 653.0, "k2": 63.3, "c": 6.0, "mu": 0.15, "speed": 80.0 / 3.6}


def class_bounds(road_class: str) -> tuple[float, float]:
    """(lower, upper) Gd(n0) bounds of an ISO 8608 class [m^3] (A from 0, H to inf)."""
    check_choice("road_class", road_class, tuple(ISO8608_CLASSES))
    g = ISO8608_CLASSES[road_class]
    return (0.0 if road_class == "A" else g / 2, math.inf if road_class == "H" else 2 * g)


def iso8608_class(gd_n0: float) -> str:
    """The ISO 8608 class whose bounds hold Gd(n0) [m^3]."""
    g = check_positive("gd_n0", gd_n0, "m^3")
    for c in ISO8608_CLASSES:
        lo, hi = class_bounds(c)
        if lo <= g < hi:
            return c
    raise ParameterError("gd_n0", gd_n0, "a positive value")  # pragma: no cover


def isotropic_coherence(n, track: float, waviness: float = 2.0):
    """Cross/auto spectral ratio rho(n) of two tracks ``track`` [m] apart (isotropic)."""
    from scipy.special import gamma, kv

    b = check_positive("track", track, "m")
    nu = 0.5 * check_positive("waviness", waviness)
    x = 2.0 * math.pi * np.asarray(n, dtype=float) * b
    with np.errstate(invalid="ignore", over="ignore"):
        r = 2.0 ** (1.0 - nu) / gamma(nu) * x**nu * kv(nu, x)
    r = np.where(x == 0, 1.0, r)
    return np.where(np.isfinite(r), r, 0.0)


@dataclass(frozen=True, kw_only=True)
class RoadSpectrum:
    """ISO 8608-style road: Gd(n) = gd_n0 (n/n0)^-waviness inside ``band``.

    Parameters
    ----------
    gd_n0 : float
        Gd(n0) [m^3].
    waviness : float
        w [-], 2 in ISO 8608.
    band : (float, float)
        Spatial frequencies [cycle/m] outside which the PSD is 0.
    coherence : {"isotropic", "identical", "independent"} or float
        Left/right model: the isotropic surface, rho = 1, rho = 0, or a constant rho
        in [0, 1].
    """

    gd_n0: float
    waviness: float = 2.0
    band: tuple = (0.01, 10.0)
    coherence: str | float = "isotropic"

    def __post_init__(self) -> None:
        check_positive("gd_n0", self.gd_n0, "m^3")
        check_positive("waviness", self.waviness)
        lo, hi = self.band
        if not (0 < lo < hi < math.inf):
            raise ParameterError("band", self.band, "0 < low < high cycle/m")
        c = self.coherence
        if isinstance(c, str):
            check_choice("coherence", c, COHERENCE_MODELS)
        elif isinstance(c, bool) or not (isinstance(c, int | float) and 0.0 <= c <= 1.0):
            raise ParameterError("coherence", c, "a model name or a number in [0, 1]")

    def psd(self, n):
        """One-sided displacement PSD Gd(n) [m^3] (0 outside the band)."""
        n = np.asarray(n, dtype=float)
        lo, hi = self.band
        inside = (n >= lo) & (n <= hi)
        with np.errstate(divide="ignore"):
            g = self.gd_n0 * (np.where(n > 0, n, 1.0) / ISO8608_N0) ** -self.waviness
        return np.where(inside, g, 0.0)

    def temporal_psd(self, freq_hz, speed: float):
        """PSD of the road height seen at ``speed`` [m/s]: Gd(f/V)/V [m^2/Hz]."""
        v = check_positive("speed", speed, "m/s")
        return self.psd(np.asarray(freq_hz, float) / v) / v

    def rho(self, n, track: float):
        """Left/right cross/auto ratio at spatial frequency ``n`` for ``track`` [m]."""
        c = self.coherence
        n = np.asarray(n, dtype=float)
        if c == "isotropic":
            return isotropic_coherence(n, track, self.waviness)
        if c == "identical":
            return np.ones_like(n)
        if c == "independent":
            return np.zeros_like(n)
        return np.full_like(n, float(c))


def road_spectrum(road_class: str = "C", **kwargs) -> RoadSpectrum:
    """The :class:`RoadSpectrum` of ISO 8608 class ``road_class`` (geometric mean)."""
    check_choice("road_class", road_class, tuple(ISO8608_CLASSES))
    return RoadSpectrum(gd_n0=ISO8608_CLASSES[road_class], **kwargs)


def track_coefficients(
    spectrum: RoadSpectrum,
    *,
    length: float,
    step: float = 0.05,
    track: float = 1.5,
    seed: int | None = 0,
):
    """The random Fourier coefficients of a generated left/right track pair.

    Returns (dx, n, Z_left, Z_right): the sample spacing dx [m] (``length`` rounded to
    an even number of steps, period L = count dx), the spatial frequencies n_k = k/L
    [cycle/m] and the coefficients in the scaling of :func:`numpy.fft.irfft` on
    ``count`` samples. The profile z(x) = irfft(Z) at x = j dx is the value of the
    trigonometric series (1/count)(Z_0 + 2 Re sum_k Z_k exp(2 pi i n_k x)), which
    :func:`inerterlab.vehicles.spectral.generated_road` evaluates anywhere, not only on the sample grid.
    Gaussian stationary process: complex Gaussian coefficients with E|Z_k|^2 matching
    Gd(n_k) dn (random amplitudes and phases), the right track
    Z_R = rho Z_L + sqrt(1 - rho^2) Z', Z' independent, so its auto-PSD is Gd and its
    cross-PSD with the left track rho Gd. The constant and the Nyquist term are 0.
    """
    L = check_positive("length", length, "m")
    dx = check_positive("step", step, "m")
    if not isinstance(spectrum, RoadSpectrum):
        raise ParameterError("spectrum", spectrum, "a RoadSpectrum (road_spectrum('C'))")
    if seed is not None:
        check_seed("seed", seed)
    if not L / dx >= 16:
        raise ParameterError(
            "step", step, f"a sample spacing giving at least 16 samples over length={L:g} m"
        )
    from ..resources import check_memory

    # two tracks, their spectra and the random draws: about 16 values per sample
    check_memory(
        L / dx * 16,
        what="road tracks (length / step samples)",
        parameter="length/step",
        value=f"{L:g} m / {dx:g} m",
    )
    count = int(round(L / dx))
    count += count % 2
    L = count * dx
    n = np.arange(count // 2 + 1) / L
    rng = np.random.default_rng(seed)
    g = spectrum.psd(n)
    sd = np.sqrt(g / L) * count / 2.0  # |Z| scale so that irfft has variance g dn
    sd[0] = 0.0
    sd[-1] = 0.0

    def draw():
        return sd * (rng.standard_normal(n.size) + 1j * rng.standard_normal(n.size))

    zl, zi = draw(), draw()
    rho = spectrum.rho(n, track)
    zr = rho * zl + np.sqrt(np.clip(1.0 - rho * rho, 0.0, None)) * zi
    return dx, n, zl, zr


def generate_tracks(
    spectrum: RoadSpectrum,
    *,
    length: float,
    step: float = 0.05,
    track: float = 1.5,
    seed: int | None = 0,
):
    """Left and right road profiles (x, z_left, z_right) [m], periodic with period ``length``:
    the series of :func:`track_coefficients` sampled every ``step``."""
    dx, n, zl, zr = track_coefficients(spectrum, length=length, step=step, track=track, seed=seed)
    count = 2 * (n.size - 1)
    x = dx * np.arange(count)
    return x, np.fft.irfft(zl, n=count), np.fft.irfft(zr, n=count)


def _profile(x, z, minimum: int):
    """(x, z, spacing) of a profile checked: equal 1-D finite arrays, evenly spaced."""
    try:
        x = np.asarray(x, dtype=float)
        z = np.asarray(z, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError("x, z", "not numbers", "two 1-D arrays of numbers [m]") from None
    if x.ndim != 1 or x.shape != z.shape or x.size < minimum:
        raise ParameterError(
            "x, z", f"arrays of shape {x.shape} and {z.shape}", f"equal 1-D arrays, >= {minimum}"
        )
    for name, a in (("x", x), ("z", z)):
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise ParameterError(f"{name}[{bad[0]}]", float(a[bad[0]]), "a finite number [m]")
    dx = np.diff(x)
    if np.any(dx <= 0) or not np.allclose(dx, dx[0], rtol=1e-6):
        raise ParameterError("x", "uneven or unordered samples", "evenly spaced distances")
    return x, z, float(dx[0])


def fit_iso8608(x, z, band=(0.011, 2.83), waviness: float | None = 2.0, segment: float = 100.0):
    """Fit Gd(n0) (and optionally w) to a measured profile; return a dict with the class.

    The PSD is Welch's estimate (Hann windows of ``segment`` metres, half overlap) of
    the detrended profile, fitted in log-log space over ``band`` [cycle/m] (ISO 8608
    evaluates 0.011 to 2.83 cycle/m) with the waviness fixed at ``waviness`` or free
    when it is None.
    """
    from scipy.signal import welch

    x, z, dx = _profile(x, z, 16)
    try:
        lo, hi = (check_positive("band", b, "cycle/m") for b in band)
    except (TypeError, ValueError):
        raise ParameterError("band", band, "two frequencies (low, high) [cycle/m]") from None
    if not lo < hi:
        raise ParameterError("band", band, "low < high [cycle/m]")
    band = (lo, hi)
    check_positive("segment", segment, "m")
    if waviness is not None:
        check_positive("waviness", waviness)
    nseg = min(x.size, int(round(segment / dx)))
    if nseg < 8:
        raise ParameterError("segment", segment, f"a length of at least 8 samples ({8 * dx:g} m)")
    n, g = welch(z, fs=1.0 / dx, nperseg=nseg, detrend="linear")
    use = (n >= band[0]) & (n <= band[1]) & (g > 0)
    if use.sum() < 3:
        raise ParameterError("profile", f"{x[-1] - x[0]:g} m", "a profile long enough for the band")
    ln, lg = np.log(n[use] / ISO8608_N0), np.log(g[use])
    if waviness is None:
        slope, icpt = np.polyfit(ln, lg, 1)
        w = -slope
    else:
        w = float(waviness)
        icpt = float(np.mean(lg + w * ln))
    gd = float(math.exp(icpt))
    return {"gd_n0": gd, "waviness": float(w), "road_class": iso8608_class(gd)}


def _golden_matrices():
    p = GOLDEN_CAR
    k1, k2, c, mu = p["k1"], p["k2"], p["c"], p["mu"]
    # states zs, zs', zu, zu'; input the profile height y
    A = np.array(
        [
            [0.0, 1.0, 0.0, 0.0],
            [-k2, -c, k2, c],
            [0.0, 0.0, 0.0, 1.0],
            [k2 / mu, c / mu, -(k1 + k2) / mu, -c / mu],
        ]
    )
    B = np.array([0.0, 0.0, 0.0, k1 / mu])
    return A, B


def _foh_matrices(A, B, h):
    """Phi, G0, G1 with x(h) = Phi x + G0 u0 + G1 (u1 - u0) for u linear over [0, h]."""
    from scipy.linalg import expm

    n, m = A.shape[0], B.shape[1]
    E = np.zeros((n + 2 * m, n + 2 * m))
    E[:n, :n] = A * h
    E[:n, n : n + m] = B * h
    E[n : n + m, n + m :] = np.eye(m)
    F = expm(E)
    return F[:n, :n], F[:n, n : n + m], F[:n, n + m :]


def iri(x, z, smoothing: float | None = 0.25) -> float:
    """International Roughness Index [m/km] of a profile (x [m] evenly spaced, z [m]).

    The golden car runs over the profile (linear between samples, exact
    discretisation) after a moving average over ``smoothing`` metres (None: none).
    """
    x, z, dx = _profile(x, z, 3)
    if x[-1] - x[0] < 11.0:
        raise ParameterError("profile length", x[-1] - x[0], "at least 11 m")
    if smoothing is not None:
        k = max(1, int(round(check_positive("smoothing", smoothing, "m") / dx)))
        if k > 1:
            c = np.concatenate([[0.0], np.cumsum(z)])
            z = (c[k:] - c[:-k]) / k
    v = GOLDEN_CAR["speed"]
    A, B = _golden_matrices()
    phi, g0, g1 = _foh_matrices(A, B[:, None], dx / v)
    i11 = int(round(11.0 / dx))
    slope = (z[i11] - z[0]) / (i11 * dx)
    s = np.array([z[0], slope * v, z[0], slope * v])
    du = np.diff(z)
    rel = np.empty(z.size)
    rel[0] = 0.0
    g0, g1 = g0[:, 0], g1[:, 0]
    for i in range(du.size):
        s = phi @ s + g0 * z[i] + g1 * du[i]
        rel[i + 1] = s[1] - s[3]
    return float(np.mean(np.abs(rel[1:])) / v * 1000.0)


#: header spellings of a vehicle road file's columns (``distance [m]``, ``left [mm]``, ...)
TRACK_COLUMNS = {
    "distance": "distance",
    "position": "distance",
    "x": "distance",
    "s": "distance",
    "left": "left",
    "right": "right",
    "elevation": "elevation",
    "height": "elevation",
    "displacement": "elevation",
    "z": "elevation",
}
_TRACK_QUANTITIES = {"left": "displacement", "right": "displacement", "elevation": "displacement"}
_TRACK_UNITS = {"distance": "m", "left": "m", "right": "m", "elevation": "m"}


def _read_track_table(path, required, headerless, min_rows):
    from ..datafiles import read_columns

    return read_columns(
        path,
        TRACK_COLUMNS,
        quantities=_TRACK_QUANTITIES,
        default_units=_TRACK_UNITS,
        headerless=headerless,
        increasing="distance",
        required=required,
        min_rows=min_rows,
        what="road",
    )


def read_profile_csv(path, track: str | None = None):
    """(distance [m], elevation [m]) of one road profile in a column file.

    The file is read by :func:`inerterlab.datafiles.read_columns`: a header names the
    columns with their units (``distance [m]`` or ``[mm]``, ``[cm]``, ``[km]``;
    ``elevation [mm]``, also ``height``; or the track pair ``left``/``right`` a generated
    road has, of which ``track`` picks one); a column without a unit, and a file without
    a header (two columns), are in metres. The distance must increase strictly; every
    value must be a finite number. At least 16 rows.
    """
    from ..errors import DataFileError

    tab = _read_track_table(path, ("distance",), ("distance", "elevation"), 16)
    hl = (tab.header_line or 0) + 1
    have = [c for c in ("elevation", "left", "right") if c in tab]
    if track is not None:
        check_choice("track", track, ("left", "right", "elevation"))
        if track not in tab:
            raise DataFileError(
                path, f"no column {track!r} for --track (the file has {', '.join(have)})", hl
            )
        return tab["distance"], tab[track]
    if len(have) != 1:
        raise DataFileError(
            path,
            "needs one profile column (elevation) besides distance; it has "
            + (", ".join(have) if have else "none")
            + ("; choose one with --track left or --track right" if len(have) > 1 else ""),
            hl,
        )
    return tab["distance"], tab[have[0]]


def read_track_pair(path, track: float, step: float | None = None):
    """(x [m] from 0, z_left [m], z_right [m]) of a road file.

    An OpenCRG file (``.crg``) is sampled at v = +/- track/2 every ``step`` m (default
    its own increment) by :func:`inerterlab.vehicles.crg.read_crg_tracks`. Any other
    file is a column file (:func:`read_profile_csv` explains the header and units) with
    the columns distance, left and optionally right (the left track is used for both
    when it is missing), returned at its own distances (strictly increasing, not
    necessarily even) for the wheels to be read off by linear interpolation.
    """
    from pathlib import Path

    from ..errors import DataFileError

    p = Path(path)
    if p.suffix.lower() == ".crg":
        from .crg import read_crg_tracks

        return read_crg_tracks(p, track, step)
    tab = _read_track_table(p, ("distance", "left"), ("distance", "left", "right"), 16)
    if "elevation" in tab:
        raise DataFileError(
            p,
            "holds an 'elevation' column; a road to drive over has the columns "
            "distance, left[, right]",
            (tab.header_line or 0) + 1,
        )
    x = tab["distance"]
    left = tab["left"]
    right = tab["right"] if "right" in tab else left
    return x - x[0], left, right
