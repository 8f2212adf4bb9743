"""Road inputs of the quarter car: drop, bump, sine, ISO 8608 random road, user series.

Every excitation describes the road displacement X1(t) [m] as a list of segments on
which X1 is smooth (SPEC §5). A segment is a row ``[t0, t1, kind, a, b, A, w, phi]``:

* ``kind = 0``: X1 = a + b (t - t0) (flat or linear piece);
* ``kind = 1``: X1 = a + A sin(w t + phi) (sine, the 1 - cos bump).

The integrators restart at every segment edge and never step across one. Where X1
jumps at an edge (the rectangular bump), the tyre damper C_t passes an impulse
C_t * jump to the unsprung mass; the simulation applies it as a velocity jump (see
``docs/decisions.md``).

The car starts at rest in static equilibrium on the road level ``initial_road``
(the value of X1 just before t = 0), plus the initial displacements of a ``drop``.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np

from .errors import (
    DataFileError,
    ParameterError,
    check_choice,
    check_finite,
    check_positive,
)

__all__ = [
    "Excitation",
    "Drop",
    "Bump",
    "Sine",
    "RoadSeries",
    "ISO8608Road",
    "drop",
    "bump",
    "sine",
    "iso8608",
    "road_series",
    "read_road_csv",
    "road_displacement",
    "ISO8608_CLASSES",
    "iso8608_psd",
    "EXCITATIONS",
]

EXCITATIONS = ("drop", "bump", "sine", "iso8608")

#: Gd(n0) geometric means [m^3] of ISO 8608 road classes (SPEC §9), n0 = 0.1 cycle/m
ISO8608_CLASSES = {c: 16e-6 * 4**i for i, c in enumerate(("A", "B", "C", "D", "E", "F", "G", "H"))}
ISO8608_N0 = 0.1  # [cycle/m]
ISO8608_BAND = (0.01, 10.0)  # [cycle/m]


class Excitation:
    """Base of all road inputs.

    Subclasses give :meth:`segments`; :meth:`initial_road` [m] is X1 just before t = 0,
    ``initial_displacements`` the (unsprung, sprung) offsets from equilibrium [m].
    """

    name = "excitation"

    def initial_road(self, horizon: float) -> float:
        """X1 just before t = 0 [m]: the car starts in equilibrium on this level."""
        return 0.0

    @property
    def initial_displacements(self) -> tuple[float, float]:
        return (0.0, 0.0)

    def segments(self, horizon: float) -> np.ndarray:  # pragma: no cover - abstract
        raise ParameterError("excitation", self, "a concrete excitation")

    def describe(self) -> dict:
        """Settings of the input as a plain dict."""
        out = {"input": self.name}
        for k, v in getattr(self, "__dataclass_fields__", {}).items():
            if v.repr:
                out[k] = getattr(self, k)
        return out


def _flat(t0: float, t1: float, level: float) -> list[float]:
    return [t0, t1, 0.0, level, 0.0, 0.0, 0.0, 0.0]


@dataclass(frozen=True, kw_only=True)
class Drop(Excitation):
    """ "Zero input" of ch. 4.2.1.1: flat road, masses released from an offset at rest.

    Parameters
    ----------
    height : float
        Initial displacement [m] (0.05 in the thesis).
    displaced : {"both", "sprung", "unsprung"}
        Which masses start displaced; the thesis does not say, SPEC §5 fixes both.
    """

    height: float = 0.05
    displaced: str = "both"
    name = "drop"

    def __post_init__(self) -> None:
        check_finite("height", self.height)
        check_choice("displaced", self.displaced, ("both", "sprung", "unsprung"))

    @property
    def initial_displacements(self) -> tuple[float, float]:
        h = float(self.height)
        return (
            h if self.displaced in ("both", "unsprung") else 0.0,
            h if self.displaced in ("both", "sprung") else 0.0,
        )

    def segments(self, horizon: float) -> np.ndarray:
        return np.array([_flat(0.0, horizon, 0.0)])


@dataclass(frozen=True, kw_only=True)
class Bump(Excitation):
    """ "Impulse input" of ch. 4.2.1.2: a road pulse.

    Parameters
    ----------
    height : float
        Pulse height [m] (0.05 in the thesis).
    duration : float
        Pulse length [s]; 10 ms by default (the thesis does not state it).
    shape : {"rectangular", "1-cos"}
        Rectangular (jumps up and down, an impulse through the tyre damper) or the
        smooth h/2 (1 - cos(2 pi (t - start)/duration)).
    start : float
        Time the pulse begins [s].
    """

    height: float = 0.05
    duration: float = 0.01
    shape: str = "rectangular"
    start: float = 0.0
    name = "bump"

    def __post_init__(self) -> None:
        check_finite("height", self.height)
        check_positive("duration", self.duration, "s")
        check_choice("shape", self.shape, ("rectangular", "1-cos"))
        if check_finite("start", self.start) < 0:
            raise ParameterError("start", self.start, "a time >= 0 s")

    def segments(self, horizon: float) -> np.ndarray:
        h, d, t0 = float(self.height), float(self.duration), float(self.start)
        rows = []
        if t0 > 0:
            rows.append(_flat(0.0, t0, 0.0))
        if self.shape == "rectangular":
            rows.append(_flat(t0, t0 + d, h))
        else:
            w = 2.0 * math.pi / d
            rows.append([t0, t0 + d, 1.0, 0.5 * h, 0.0, -0.5 * h, w, 0.5 * math.pi - w * t0])
        rows.append(_flat(t0 + d, max(horizon, t0 + d), 0.0))
        return _clip(np.array(rows), horizon)


@dataclass(frozen=True, kw_only=True)
class Sine(Excitation):
    """Sinusoidal road of ch. 4.2.1.3: X1 = amplitude sin(2 pi f t + phase).

    Parameters
    ----------
    amplitude : float
        [m], 0.05 in the thesis.
    frequency : float
        f [Hz], 5 in the thesis (4 m wavelength at about 80 km/h).
    phase : float
        [rad]. The car starts in equilibrium on X1(0) = amplitude sin(phase).
    """

    amplitude: float = 0.05
    frequency: float = 5.0
    phase: float = 0.0
    name = "sine"

    def __post_init__(self) -> None:
        check_finite("amplitude", self.amplitude)
        check_positive("frequency", self.frequency, "Hz")
        check_finite("phase", self.phase)

    def initial_road(self, horizon: float) -> float:
        return float(self.amplitude) * math.sin(float(self.phase))

    def segments(self, horizon: float) -> np.ndarray:
        w = 2.0 * math.pi * float(self.frequency)
        return np.array(
            [[0.0, horizon, 1.0, 0.0, 0.0, float(self.amplitude), w, float(self.phase)]]
        )


@dataclass(frozen=True, kw_only=True, eq=False)
class RoadSeries(Excitation):
    """A measured or generated road displacement, linear between samples.

    Each sample interval is a segment, so the integrators restart at every sample.
    Before the first sample the road holds the first value, after the last one the
    last value.

    Parameters
    ----------
    time : array
        Sample times [s], strictly increasing, >= 0.
    displacement : array
        X1 [m] at those times, finite.
    label : str
        Where the data came from (file name).
    """

    time: np.ndarray
    displacement: np.ndarray
    label: str = "series"
    name = "series"

    def __post_init__(self) -> None:
        t = np.asarray(self.time, dtype=float)
        x = np.asarray(self.displacement, dtype=float)
        if t.ndim != 1 or t.shape != x.shape or t.size < 2:
            raise ParameterError(
                "time", f"array of shape {t.shape}", "1-D arrays of equal length >= 2"
            )
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(x))):
            raise ParameterError("displacement", "non-finite values", "finite numbers")
        if t[0] < 0 or np.any(np.diff(t) <= 0):
            raise ParameterError("time", "unordered samples", "times >= 0, strictly increasing")
        t.setflags(write=False)
        x.setflags(write=False)
        object.__setattr__(self, "time", t)
        object.__setattr__(self, "displacement", x)

    def initial_road(self, horizon: float) -> float:
        return float(self.displacement[0])

    def describe(self) -> dict:
        return {
            "input": "series",
            "label": self.label,
            "samples": int(self.time.size),
            "duration": float(self.time[-1] - self.time[0]),
        }

    def segments(self, horizon: float) -> np.ndarray:
        t, x = self.time, self.displacement
        n = t.size - 1
        seg = np.zeros((n, 8))
        seg[:, 0], seg[:, 1] = t[:-1], t[1:]
        seg[:, 3] = x[:-1]
        seg[:, 4] = np.diff(x) / np.diff(t)
        parts = []
        if t[0] > 0:
            parts.append(np.array([_flat(0.0, t[0], x[0])]))
        parts.append(seg)
        if t[-1] < horizon:
            parts.append(np.array([_flat(t[-1], horizon, x[-1])]))
        return _clip(np.vstack(parts), horizon)


def _clip(seg: np.ndarray, horizon: float) -> np.ndarray:
    """Keep the segments inside [0, horizon], cutting the last one at the horizon."""
    keep = seg[:, 0] < horizon
    seg = seg[keep].copy()
    seg[-1, 1] = min(seg[-1, 1], horizon)
    return seg


def iso8608_psd(n, road_class: str = "C"):
    """ISO 8608 displacement PSD Gd(n) = Gd(n0) (n/n0)^-2 [m^3] (SPEC §9).

    Parameters
    ----------
    n : float or array
        Spatial frequency [cycle/m].
    road_class : {"A", ..., "H"}
        Geometric mean class value.
    """
    check_choice("road_class", road_class, tuple(ISO8608_CLASSES))
    n = np.asarray(n, dtype=float)
    return ISO8608_CLASSES[road_class] * (n / ISO8608_N0) ** -2


@lru_cache(maxsize=32)
def _iso_profile(road_class: str, length: float, step: float, seed: int | None):
    count = int(round(length / step))
    count += count % 2
    n = np.arange(count // 2 + 1) / (count * step)
    lo, hi = ISO8608_BAND
    band = (n >= lo) & (n <= hi)
    amp = np.zeros_like(n)
    amp[band] = np.sqrt(2.0 * iso8608_psd(n[band], road_class) / (count * step))
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0.0, 2.0 * math.pi, size=n.size)
    spectrum = 0.5 * count * amp * np.exp(1j * phase)
    z = np.fft.irfft(spectrum, n=count)
    x = step * np.arange(count + 1)
    z = np.append(z, z[0])  # periodic profile, closed at the end
    z.setflags(write=False)
    x.setflags(write=False)
    return x, z


@dataclass(frozen=True, kw_only=True)
class ISO8608Road(Excitation):
    """Random road of ISO 8608 class ``road_class`` driven at ``speed`` (SPEC §9).

    Method: random-phase sum of sinusoids on the FFT grid of the road length L,
    spatial frequencies n_k = k/L inside 0.01-10 cycle/m, amplitudes
    sqrt(2 Gd(n_k) / L) (the periodogram of the profile equals Gd at every n_k), phases
    uniform from ``numpy.random.default_rng(seed)``; summed by an inverse FFT on a grid
    of ``spatial_step``. The car sees X1(t) = z(speed t), linear between samples,
    which slightly attenuates the top of the band (by sinc^2(pi n dx), 13 % at 10
    cycle/m with dx = 0.02 m). The profile is periodic with period L.

    Parameters
    ----------
    road_class : {"A", "B", "C", "D", "E", "F", "G", "H"}
    speed : float
        V [m/s].
    seed : int or None
        Seed of the phases (None: fresh randomness).
    length : float or None
        L [m]; None means speed x horizon (at least 100 m, so the band reaches
        0.01 cycle/m).
    spatial_step : float
        dx [m] of the profile grid, <= 0.05 so 10 cycle/m stays below Nyquist.
    """

    road_class: str = "C"
    speed: float = 20.0
    seed: int | None = 0
    length: float | None = None
    spatial_step: float = 0.02
    name = "iso8608"

    def __post_init__(self) -> None:
        check_choice("road_class", self.road_class, tuple(ISO8608_CLASSES))
        check_positive("speed", self.speed, "m/s")
        if self.length is not None:
            check_positive("length", self.length, "m")
        s = check_positive("spatial_step", self.spatial_step, "m")
        if s > 0.05:
            raise ParameterError("spatial_step", self.spatial_step, "a step in (0, 0.05] m")
        if self.seed is not None and (
            not isinstance(self.seed, int) or isinstance(self.seed, bool) or self.seed < 0
        ):
            raise ParameterError("seed", self.seed, "an integer >= 0 or None")

    def profile(self, horizon: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(distance [m], elevation [m]) of the generated road."""
        length = self.length
        if length is None:
            length = max(100.0, self.speed * (horizon if horizon is not None else 10.0))
        from .resources import check_memory

        # the profile, its spectrum (complex), phases and the road segments built from it
        check_memory(
            float(length) / float(self.spatial_step) * 16,
            what="ISO 8608 road profile (speed x horizon / spatial_step points)",
            parameter="speed" if self.length is None else "length",
            value=self.speed if self.length is None else self.length,
        )
        return _iso_profile(self.road_class, float(length), float(self.spatial_step), self.seed)

    def series(self, horizon: float | None = None) -> RoadSeries:
        """The road as a time series at this speed."""
        x, z = self.profile(horizon)
        return RoadSeries(
            time=x / self.speed, displacement=z, label=f"ISO 8608 class {self.road_class}"
        )

    def initial_road(self, horizon: float) -> float:
        return float(self.profile(horizon)[1][0])

    def segments(self, horizon: float) -> np.ndarray:
        return self.series(horizon).segments(horizon)

    @cached_property
    def velocity_psd(self) -> float:
        """One-sided PSD of the road velocity (2 pi n0)^2 Gd(n0) V [m^2/s^2/Hz], flat."""
        return (2 * math.pi * ISO8608_N0) ** 2 * ISO8608_CLASSES[self.road_class] * self.speed


def road_displacement(segments: np.ndarray, t) -> tuple[np.ndarray, np.ndarray]:
    """X1 [m] and X1' [m/s] at times ``t`` from a segment table (right-continuous)."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    idx = np.searchsorted(segments[:, 0], t, side="right") - 1
    idx = np.clip(idx, 0, len(segments) - 1)
    s = segments[idx]
    lin = s[:, 2] == 0
    x = np.where(
        lin, s[:, 3] + s[:, 4] * (t - s[:, 0]), s[:, 3] + s[:, 5] * np.sin(s[:, 6] * t + s[:, 7])
    )
    v = np.where(lin, s[:, 4], s[:, 5] * s[:, 6] * np.cos(s[:, 6] * t + s[:, 7]))
    return x, v


# -- factories ---------------------------------------------------------------------
def drop(height: float = 0.05, *, displaced: str = "both") -> Drop:
    """Masses released from ``height`` [m] above equilibrium on a flat road (thesis "zero input").

    >>> drop().initial_displacements
    (0.05, 0.05)
    """
    return Drop(height=height, displaced=displaced)


def bump(
    height: float = 0.05, *, duration: float = 0.01, shape: str = "rectangular", start: float = 0.0
) -> Bump:
    """Road pulse of ``height`` [m] lasting ``duration`` [s] (thesis "impulse input").

    >>> bump().segments(1.0)[:, :2].tolist()
    [[0.0, 0.01], [0.01, 1.0]]
    """
    return Bump(height=height, duration=duration, shape=shape, start=start)


def sine(amplitude: float = 0.05, frequency: float = 5.0, *, phase: float = 0.0) -> Sine:
    """Sinusoidal road X1 = amplitude sin(2 pi frequency t + phase) [m], frequency [Hz]."""
    return Sine(amplitude=amplitude, frequency=frequency, phase=phase)


def iso8608(
    road_class: str = "C",
    speed: float = 20.0,
    *,
    seed: int | None = 0,
    length: float | None = None,
    spatial_step: float = 0.02,
) -> ISO8608Road:
    """ISO 8608 random road of class ``road_class`` at ``speed`` [m/s] (SPEC §9)."""
    return ISO8608Road(
        road_class=road_class, speed=speed, seed=seed, length=length, spatial_step=spatial_step
    )


def road_series(time, displacement, *, label: str = "series") -> RoadSeries:
    """A user road: displacement [m] at ``time`` [s], linear in between."""
    return RoadSeries(
        time=np.asarray(time, float), displacement=np.asarray(displacement, float), label=label
    )


def read_road_csv(path) -> RoadSeries:
    """Read a road file: two columns, time [s] and displacement [m].

    Lines starting with ``#`` and a header line of names are skipped. Every other
    line must hold two finite numbers with time strictly increasing; otherwise a
    :class:`DataFileError` names the file and line.
    """
    from .io import read_text_limited

    p = Path(path)
    text = read_text_limited(p, "road file")
    times: list[float] = []
    values: list[float] = []
    header_seen = False
    for lineno, row in enumerate(csv.reader(text.splitlines()), start=1):
        if not row or not "".join(row).strip() or row[0].lstrip().startswith("#"):
            continue
        cells = [c.strip() for c in row if c.strip() != ""]
        try:
            nums = [float(c) for c in cells]
        except ValueError:
            if not times and not header_seen:
                header_seen = True
                continue
            raise DataFileError(
                p, f"expected two numbers (time s, displacement m), got {row!r}", lineno
            ) from None
        if len(nums) != 2:
            raise DataFileError(
                p, f"expected two columns (time s, displacement m), got {len(nums)}", lineno
            )
        if not all(math.isfinite(v) for v in nums):
            raise DataFileError(p, f"non-finite value in {row!r}", lineno)
        if nums[0] < 0:
            raise DataFileError(p, f"negative time {nums[0]!r}", lineno)
        if times and nums[0] <= times[-1]:
            raise DataFileError(
                p, f"time {nums[0]!r} does not increase (previous {times[-1]!r})", lineno
            )
        times.append(nums[0])
        values.append(nums[1])
    if len(times) < 2:
        raise DataFileError(p, "needs at least two rows of (time s, displacement m)")
    return RoadSeries(time=np.array(times), displacement=np.array(values), label=p.name)
