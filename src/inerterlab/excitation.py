"""Road inputs of the quarter car: drop, bump, sine, ISO 8608 random road, user series.

Every excitation describes the road displacement X1(t) [m] as a list of segments on
which X1 is smooth (docs/model.md §5). A segment is a row ``[t0, t1, kind, a, b, A, w, phi]``:

* ``kind = 0``: X1 = a + b (t - t0) (flat or linear piece);
* ``kind = 1``: X1 = a + A sin(w t + phi) (sine, the 1 - cos bump);
* ``kind = 2`` (a measured drive, :class:`DriveSeries`; rows of nine numbers
  ``[t0, t1, 2, x0, v0, c2, c3, a0, a1]``): X1 = x0 + v0 s + c2 s^2 + c3 s^3 with
  s = t - t0 (the cubic Hermite through the samples), and the acceleration read
  separately, linear from a0 to a1 (the acceleration channel, not the cubic's second
  derivative). Only the core systems (:mod:`inerterlab.systems`) take it.

The integrators restart at every segment edge and never step across one. Where X1
jumps at an edge (the rectangular bump), the tyre damper C_t passes an impulse
C_t * jump to the unsprung mass; the simulation applies it as a velocity jump (see
``docs/decisions.md``).

The car starts at rest in static equilibrium on the road level ``initial_road``
(the value of X1 just before t = 0), plus the initial displacements of a ``drop``.
"""

from __future__ import annotations

import hashlib
import math
import threading
import warnings
from collections import OrderedDict
from dataclasses import dataclass
from functools import cached_property, lru_cache
from pathlib import Path
from typing import NamedTuple

import numpy as np

from .datafiles import read_columns
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
    "DriveSeries",
    "ISO8608Road",
    "drop",
    "bump",
    "sine",
    "iso8608",
    "road_series",
    "drive_series",
    "read_road_csv",
    "road_displacement",
    "road_steps",
    "ISO8608_CLASSES",
    "iso8608_psd",
    "EXCITATIONS",
    "RoadTooShortWarning",
    "PreparedRoad",
]

EXCITATIONS = ("drop", "bump", "sine", "iso8608")
BUMP_EDGES = ("step", "ramp", "half-cosine")

#: Gd(n0) geometric means [m^3] of ISO 8608 road classes (docs/model.md §9), n0 = 0.1 cycle/m
ISO8608_CLASSES = {c: 16e-6 * 4**i for i, c in enumerate(("A", "B", "C", "D", "E", "F", "G", "H"))}
ISO8608_N0 = 0.1  # [cycle/m]
ISO8608_BAND = (0.01, 10.0)  # [cycle/m]


class RoadTooShortWarning(UserWarning):
    """A road input ends before the simulation horizon and is held at its last value."""


class Excitation:
    """Base of all road inputs.

    Subclasses give :meth:`segments`; :meth:`initial_road` [m] is X1 just before t = 0,
    ``initial_displacements`` the (unsprung, sprung) offsets from equilibrium [m].
    """

    name = "excitation"
    #: False for a measured drive (a rig input: displacement, velocity and acceleration
    #: samples), which a quarter car does not take as its road
    is_road = True

    def initial_road(self, horizon: float) -> float:
        """X1 just before t = 0 [m]: the car starts in equilibrium on this level."""
        return 0.0

    def initial_road_velocity(self, horizon: float) -> float:
        """X1' just before t = 0 [m/s]: 0 (the road at rest), so a road that starts
        moving passes the impulse of its velocity jump through the inertances on it."""
        return 0.0

    @property
    def initial_displacements(self) -> tuple[float, float]:
        return (0.0, 0.0)

    def segments(self, horizon: float) -> np.ndarray:  # pragma: no cover - abstract
        raise ParameterError("excitation", self, "a concrete excitation")

    def prepared(self, horizon: float) -> PreparedRoad:
        """The segments up to ``horizon`` and what the integrators read from them
        (:class:`PreparedRoad`), kept for the last :data:`PREPARED_KEPT` (input, horizon)
        of an immutable input (a frozen dataclass, as every input of this module), by
        its value: a study that runs one road many times, or builds the same road
        again for each point, builds its segments once (an ISO 8608 road's 10 s take
        about 1 ms). Its arrays are shared: read them, do not write."""
        frozen = getattr(getattr(type(self), "__dataclass_params__", None), "frozen", False)
        key = (self, horizon)
        if frozen:
            try:
                got = _PREPARED.get(key)
            except TypeError:  # a field that is not hashable (an array): not kept
                frozen = False
            else:
                if got is not None:
                    return got
        got = _prepare(self, horizon)
        if frozen and got.segments.nbytes <= PREPARED_MAX_BYTES:
            with _PREPARED_LOCK:
                _PREPARED[key] = got
                while len(_PREPARED) > PREPARED_KEPT:
                    _PREPARED.popitem(last=False)
        return got

    def end_time(self) -> float:
        """Last time [s] the input is defined for (infinite for inputs without an end)."""
        return math.inf

    def check_horizon(self, horizon: float, *, stacklevel: int = 2) -> bool:
        """Warn (:class:`RoadTooShortWarning`) if the input ends before ``horizon``.

        Returns True if it covers the horizon.
        """
        end = self.end_time()
        if end >= horizon * (1 - 1e-12):
            return True
        warnings.warn(
            f"the road {self.describe().get('label', self.name)} ends at {end:g} s, before "
            f"the horizon {horizon:g} s; it is held at its last value from there on",
            RoadTooShortWarning,
            stacklevel=stacklevel + 1,
        )
        return False

    def describe(self) -> dict:
        """Settings of the input as a plain dict."""
        out = {"input": self.name}
        for k, v in getattr(self, "__dataclass_fields__", {}).items():
            if v.repr:
                out[k] = getattr(self, k)
        return out


#: prepared roads (:meth:`Excitation.prepared`) kept: this many (input, horizon), each
#: at most this many bytes of segments (an ISO 8608 road of 10 s at 20 m/s: 0.6 MB)
PREPARED_KEPT = 32
PREPARED_MAX_BYTES = 8_000_000
_PREPARED: OrderedDict = OrderedDict()
_PREPARED_LOCK = threading.Lock()


class PreparedRoad(NamedTuple):
    """An input's segments up to a horizon and what the integrators read from them."""

    #: the segment table (C-contiguous float64; shared, not to be written)
    segments: np.ndarray
    #: X1 [m] just before t = 0
    initial_road: float
    #: X1' [m/s] just before t = 0
    initial_velocity: float
    #: every segment linear in t (no sine, no cubic)
    piecewise_linear: bool
    #: the smallest road jump [m] taken as a step (:data:`ROAD_JUMP_RTOL` x
    #: :func:`road_scale`)
    jump_tolerance: float
    #: the smallest road velocity jump [m/s] taken as a jump: 1e-9 of the road's
    #: largest speed (segment rates and sine amplitudes), inf on a road at rest
    velocity_jump_tolerance: float
    #: where the road displacement jumps before the horizon (:func:`road_steps`)
    steps: tuple
    #: a digest of the segments' content (the key of what is built from them)
    key: bytes


def _prepare(excitation: Excitation, horizon: float) -> PreparedRoad:
    segs = np.ascontiguousarray(excitation.segments(horizon), dtype=float)
    sine_rate = np.where(segs[:, 2] == 1.0, np.abs(segs[:, 5] * segs[:, 6]), 0.0)
    speed = float(np.max(np.abs(segs[:, 4]) + sine_rate))
    x1 = float(excitation.initial_road(horizon))
    return PreparedRoad(
        segments=segs,
        initial_road=x1,
        initial_velocity=float(excitation.initial_road_velocity(horizon)),
        piecewise_linear=bool(np.all(segs[:, 2] == 0.0)),
        jump_tolerance=ROAD_JUMP_RTOL * road_scale(segs),
        velocity_jump_tolerance=1e-9 * speed if speed > 0.0 else math.inf,
        # (the cubic pieces of a measured drive are continuous: no steps)
        steps=tuple(road_steps(segs, x1, horizon)) if segs.shape[1] == 8 else (),
        key=hashlib.blake2b(segs.tobytes(), digest_size=16).digest() + str(segs.shape).encode(),
    )


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
        Which masses start displaced; the thesis does not say, docs/model.md §5 fixes both.
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
    edge : {"step", "ramp", "half-cosine"}
        Edges of the rectangular pulse: true steps (the road jumps; with an inerter
        between wheel and body the body velocity jumps too and the body acceleration
        holds a Dirac impulse), or smoothed over ``edge_width`` by a straight ramp or a
        half cosine. The smoothed pulse rises on [start, start + edge_width], holds to
        start + duration and falls on [start + duration, start + duration + edge_width],
        so its area is height x duration for every width; as the width goes to zero
        every finite metric tends to that of the step pulse.
    edge_width : float
        Width of each smoothed edge [s], 0 < edge_width <= duration (only with a
        smoothed ``edge``).
    """

    height: float = 0.05
    duration: float = 0.01
    shape: str = "rectangular"
    start: float = 0.0
    edge: str = "step"
    edge_width: float = 0.0
    name = "bump"

    def __post_init__(self) -> None:
        check_finite("height", self.height)
        check_positive("duration", self.duration, "s")
        check_choice("shape", self.shape, ("rectangular", "1-cos"))
        if check_finite("start", self.start) < 0:
            raise ParameterError("start", self.start, "a time >= 0 s")
        check_choice("edge", self.edge, BUMP_EDGES)
        w = check_finite("edge_width", self.edge_width)
        if self.edge == "step":
            if w != 0.0:
                raise ParameterError(
                    "edge_width", self.edge_width, "0 with edge='step' (choose 'ramp' or 'half-cosine')"
                )
        else:
            if self.shape != "rectangular":
                raise ParameterError("edge", self.edge, "'step' for the smooth 1-cos pulse")
            if not 0.0 < w <= float(self.duration):
                raise ParameterError(
                    "edge_width", self.edge_width, f"a width in (0, duration = {self.duration:g}] s"
                )

    def _edge_rows(self, ta: float, lo: float, hi: float) -> list[float]:
        """The road on one smoothed edge [ta, ta + width] going from ``lo`` to ``hi`` [m]."""
        e = float(self.edge_width)
        if self.edge == "ramp":
            return [ta, ta + e, 0.0, lo, (hi - lo) / e, 0.0, 0.0, 0.0]
        # half cosine: lo + (hi - lo)(1 - cos(pi (t - ta)/e))/2, written as a + A sin(w t + phi)
        w = math.pi / e
        return [ta, ta + e, 1.0, 0.5 * (lo + hi), 0.0, -0.5 * (hi - lo), w, 0.5 * math.pi - w * ta]

    def segments(self, horizon: float) -> np.ndarray:
        h, d, t0 = float(self.height), float(self.duration), float(self.start)
        rows = []
        if t0 > 0:
            rows.append(_flat(0.0, t0, 0.0))
        if self.shape == "rectangular" and self.edge != "step":
            e = float(self.edge_width)
            rows.append(self._edge_rows(t0, 0.0, h))
            if d > e:
                rows.append(_flat(t0 + e, t0 + d, h))
            rows.append(self._edge_rows(t0 + d, h, 0.0))
            rows.append(_flat(t0 + d + e, max(horizon, t0 + d + e), 0.0))
            return _clip(np.array(rows), horizon)
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

    def end_time(self) -> float:
        return float(self.time[-1])

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


@dataclass(frozen=True, kw_only=True)
class DriveSeries(Excitation):
    """A measured drive: displacement, velocity and acceleration samples.

    The drive of a rig test (the relative motion across a device) or of a shaker, as
    the identification reads it: x and v follow the cubic Hermite through the
    displacement and velocity samples (x and v continuous, so no impulse anywhere) and
    the acceleration, which the inertances read, is interpolated linearly between the
    acceleration samples. Each sample interval is a segment (kind 2, see the module
    notes). Before the first sample the drive moves at the first velocity (it was
    moving when the record started: no velocity jump at t = 0), after the last at the
    last velocity. Only the core systems take it (``rig(...).simulate(drive, ...)``).

    Parameters
    ----------
    time : array
        Sample times [s], strictly increasing, >= 0.
    displacement, velocity, acceleration : arrays
        x [m], v [m/s] and a [m/s^2] at those times, finite.
    label : str
        Where the data came from.
    """

    time: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    label: str = "drive"
    name = "drive"
    is_road = False

    def __post_init__(self) -> None:
        arrays = {}
        for key in ("time", "displacement", "velocity", "acceleration"):
            a = np.array(getattr(self, key), dtype=float)
            if a.ndim != 1 or a.size < 2:
                raise ParameterError(key, f"array of shape {a.shape}", "a 1-D array of >= 2 samples")
            if not np.all(np.isfinite(a)):
                raise ParameterError(key, "non-finite values", "finite numbers")
            arrays[key] = a
        n = arrays["time"].size
        for key, a in arrays.items():
            if a.size != n:
                raise ParameterError(key, f"{a.size} samples", f"{n} samples, as many as time")
        t = arrays["time"]
        if t[0] < 0 or np.any(np.diff(t) <= 0):
            raise ParameterError("time", "unordered samples", "times >= 0, strictly increasing")
        for key, a in arrays.items():
            a.setflags(write=False)
            object.__setattr__(self, key, a)

    def _at_zero(self) -> tuple[float, float]:
        t0, x0, v0 = float(self.time[0]), float(self.displacement[0]), float(self.velocity[0])
        return x0 - v0 * t0, v0

    def initial_road(self, horizon: float) -> float:
        return self._at_zero()[0]

    def initial_road_velocity(self, horizon: float) -> float:
        return self._at_zero()[1]

    def end_time(self) -> float:
        return float(self.time[-1])

    def check_horizon(self, horizon: float, *, stacklevel: int = 2) -> bool:
        end = self.end_time()
        if end >= horizon * (1 - 1e-12):
            return True
        warnings.warn(
            f"the drive {self.label} ends at {end:g} s, before the horizon {horizon:g} s; "
            "it goes on at its last velocity from there",
            RoadTooShortWarning,
            stacklevel=stacklevel + 1,
        )
        return False

    def describe(self) -> dict:
        return {
            "input": "drive",
            "label": self.label,
            "samples": int(self.time.size),
            "duration": float(self.time[-1] - self.time[0]),
        }

    def segments(self, horizon: float) -> np.ndarray:
        t, x, v, a = self.time, self.displacement, self.velocity, self.acceleration
        h = np.diff(t)
        dx = np.diff(x)
        seg = np.zeros((t.size - 1, 9))
        seg[:, 0], seg[:, 1], seg[:, 2] = t[:-1], t[1:], 2.0
        seg[:, 3], seg[:, 4] = x[:-1], v[:-1]
        seg[:, 5] = (3.0 * dx / h - 2.0 * v[:-1] - v[1:]) / h
        seg[:, 6] = (v[:-1] + v[1:] - 2.0 * dx / h) / (h * h)
        seg[:, 7], seg[:, 8] = a[:-1], a[1:]
        parts = []
        if t[0] > 0:
            x_0, v_0 = self._at_zero()
            parts.append(np.array([[0.0, t[0], 0.0, x_0, v_0, 0.0, 0.0, 0.0, 0.0]]))
        parts.append(seg)
        if t[-1] < horizon:
            parts.append(np.array([[t[-1], horizon, 0.0, x[-1], v[-1], 0.0, 0.0, 0.0, 0.0]]))
        return _clip(np.vstack(parts), horizon)


def _clip(seg: np.ndarray, horizon: float) -> np.ndarray:
    """Keep the segments inside [0, horizon], cutting the last one at the horizon."""
    keep = seg[:, 0] < horizon
    seg = seg[keep].copy()
    seg[-1, 1] = min(seg[-1, 1], horizon)
    return seg


def iso8608_psd(n, road_class: str = "C"):
    """ISO 8608 displacement PSD Gd(n) = Gd(n0) (n/n0)^-2 [m^3] (docs/model.md §9).

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
    """Random road of ISO 8608 class ``road_class`` driven at ``speed`` (docs/model.md §9).

    Method: random-phase sum of sinusoids on the FFT grid of the road length L,
    spatial frequencies n_k = k/L inside 0.01-10 cycle/m, amplitudes
    sqrt(2 Gd(n_k) / L) (the periodogram of the profile equals Gd at every n_k), phases
    uniform from ``numpy.random.default_rng(seed)``; summed by an inverse FFT on a grid
    of ``spatial_step``. The car sees X1(t) = z(speed t), linear between samples,
    which slightly attenuates the top of the band: linear interpolation multiplies each
    harmonic's amplitude by sinc^2(pi n dx), so the PSD by sinc^4(pi n dx), 23 % at 10
    cycle/m with dx = 0.02 m. The profile is periodic with period L.

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

        # the profile, its spectrum (complex), phases and the road segments built from it;
        # the option blamed is the one that set the length: length, else the horizon
        # (speed alone is within its range: the product is too long)
        if self.length is not None:
            parameter, value = "length", self.length
        elif horizon is not None:
            parameter, value = "horizon", horizon
        else:
            parameter, value = "speed", self.speed
        check_memory(
            float(length) / float(self.spatial_step) * 16,
            what="ISO 8608 road profile (speed x horizon / spatial_step points)",
            parameter=parameter,
            value=value,
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

    def end_time(self) -> float:
        return math.inf if self.length is None else float(self.length) / float(self.speed)

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
    return _road_on(segments[idx], t)


#: road jumps up to this size relative to the road's largest level are round-off
#: between segments (a ramp's end, a sampled road), not steps; the integrators use it
ROAD_JUMP_RTOL = 1e-12


#: below this many segments the road helpers loop in Python: numpy's per-call cost on
#: arrays of one to a few rows was most of a sweep point's overhead (docs/decisions.md)
_SMALL = 16


def road_scale(segments: np.ndarray) -> float:
    """A bound on |X1| over the segments [m]: the scale a road jump is measured against."""
    s = np.asarray(segments, dtype=float)
    if s.shape[1] > 8:  # a measured drive: bound each cubic piece by its coefficients
        d = s[:, 1] - s[:, 0]
        cubic = s[:, 2] == 2
        c2 = np.where(cubic, np.abs(s[:, 5]) * d * d + np.abs(s[:, 6]) * d**3, np.abs(s[:, 5]))
        return float(np.max(np.abs(s[:, 3]) + np.abs(s[:, 4]) * d + c2))
    if s.shape[0] <= _SMALL:  # the same operations, element by element
        return float(max(abs(r[3]) + abs(r[5]) + abs(r[4]) * (r[1] - r[0]) for r in s.tolist()))
    return float(np.max(np.abs(s[:, 3]) + np.abs(s[:, 5]) + np.abs(s[:, 4]) * (s[:, 1] - s[:, 0])))


def road_steps(segments: np.ndarray, initial_road: float, horizon: float) -> list:
    """Where the road displacement jumps: ``[(time [s], jump [m]), ...]`` before ``horizon``.

    A jump is the start value of a segment minus the end value of the one before (the
    first segment against ``initial_road``); differences at round-off level
    (:data:`ROAD_JUMP_RTOL` of :func:`road_scale`) are not steps.

    >>> road_steps(bump().segments(1.0), 0.0, 1.0)
    [(0.0, 0.05), (0.01, -0.05)]
    """
    segs = np.asarray(segments, dtype=float)
    tol = ROAD_JUMP_RTOL * road_scale(segs)
    if segs.shape[0] <= _SMALL and segs.shape[1] == 8:
        # a few segments (drop, bumps, sine): plain floats, the arithmetic of _road_on
        out, prev = [], float(initial_road)
        for r in segs.tolist():
            if r[2] == 0:
                start = r[3]
                end = r[3] + r[4] * (r[1] - r[0])
            else:
                start = r[3] + r[5] * math.sin(r[6] * r[0] + r[7])
                end = r[3] + r[5] * math.sin(r[6] * r[1] + r[7])
            jump = start - prev
            if abs(jump) > tol and r[0] < horizon:
                out.append((r[0], jump))
            prev = end
        return out
    start, _ = _road_on(segs, segs[:, 0])
    end, _ = _road_on(segs, segs[:, 1])
    prev = np.concatenate([[float(initial_road)], end[:-1]])
    jump = start - prev
    hit = np.flatnonzero((np.abs(jump) > tol) & (segs[:, 0] < horizon))
    return [(float(segs[i, 0]), float(jump[i])) for i in hit]


def _road_on(s: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """X1 and X1' of each segment row of ``s`` at its own time ``t``."""
    lin = s[:, 2] == 0
    x = np.where(
        lin, s[:, 3] + s[:, 4] * (t - s[:, 0]), s[:, 3] + s[:, 5] * np.sin(s[:, 6] * t + s[:, 7])
    )
    v = np.where(lin, s[:, 4], s[:, 5] * s[:, 6] * np.cos(s[:, 6] * t + s[:, 7]))
    cubic = s[:, 2] == 2
    if np.any(cubic):  # a measured drive's Hermite pieces (nine columns)
        c = s[cubic]
        u = (t - s[:, 0])[cubic]
        x[cubic] = c[:, 3] + u * (c[:, 4] + u * (c[:, 5] + u * c[:, 6]))
        v[cubic] = c[:, 4] + u * (2.0 * c[:, 5] + 3.0 * u * c[:, 6])
    return x, v


# -- factories ---------------------------------------------------------------------
def drop(height: float = 0.05, *, displaced: str = "both") -> Drop:
    """Masses released from ``height`` [m] above equilibrium on a flat road (thesis "zero input").

    >>> drop().initial_displacements
    (0.05, 0.05)
    """
    return Drop(height=height, displaced=displaced)


def bump(
    height: float = 0.05,
    *,
    duration: float = 0.01,
    shape: str = "rectangular",
    start: float = 0.0,
    edge: str = "step",
    edge_width: float = 0.0,
) -> Bump:
    """Road pulse of ``height`` [m] lasting ``duration`` [s] (thesis "impulse input").

    ``edge`` ("step", "ramp", "half-cosine") and ``edge_width`` [s] smooth the edges of
    the rectangular pulse (see :class:`Bump`).

    >>> bump().segments(1.0)[:, :2].tolist()
    [[0.0, 0.01], [0.01, 1.0]]
    >>> bump(edge="ramp", edge_width=0.002).segments(1.0)[:, :2].tolist()
    [[0.0, 0.002], [0.002, 0.01], [0.01, 0.012], [0.012, 1.0]]
    """
    return Bump(
        height=height, duration=duration, shape=shape, start=start, edge=edge, edge_width=edge_width
    )


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
    """ISO 8608 random road of class ``road_class`` at ``speed`` [m/s] (docs/model.md §9)."""
    return ISO8608Road(
        road_class=road_class, speed=speed, seed=seed, length=length, spatial_step=spatial_step
    )


def road_series(time, displacement, *, label: str = "series") -> RoadSeries:
    """A user road: displacement [m] at ``time`` [s], linear in between."""
    return RoadSeries(
        time=np.asarray(time, float), displacement=np.asarray(displacement, float), label=label
    )


def drive_series(time, displacement, velocity, acceleration=None, *, label: str = "drive"):
    """A measured drive (:class:`DriveSeries`) from x [m] and v [m/s] at ``time`` [s].

    Without ``acceleration`` [m/s^2] it is taken from the velocity samples alone, as the
    identification does (five-point differences, docs/model.md): a difference of the
    displacement would turn displacement sensor noise into acceleration noise of order
    noise / h^2.

    >>> d = drive_series([0.0, 0.1, 0.2], [0.0, 0.001, 0.0], [0.02, 0.0, -0.02])
    >>> d.segments(0.2).shape
    (2, 9)
    """
    if acceleration is None:
        from .devices.motion import _node_acceleration

        t = np.asarray(time, dtype=float)
        v = np.asarray(velocity, dtype=float)
        if t.shape != v.shape:
            raise ParameterError("velocity", f"shape {v.shape}", f"shape {t.shape}, as time")
        acceleration = _node_acceleration(t, np.asarray(displacement, float), v)
    return DriveSeries(
        time=time, displacement=displacement, velocity=velocity, acceleration=acceleration,
        label=label,
    )  # fmt: skip


#: header spellings of the road file's columns
ROAD_COLUMNS = {
    "time": "time",
    "t": "time",
    "distance": "distance",
    "position": "distance",
    "x": "distance",
    "displacement": "displacement",
    "height": "displacement",
    "elevation": "displacement",
    "z": "displacement",
}


def read_road_csv(path, *, speed: float | None = None, units: dict | None = None) -> RoadSeries:
    """Read a road profile file: time or distance, and the road height, with units.

    The header names the columns and their units (``time [s]``, ``distance [m]``,
    ``displacement [mm]``; also ``name (unit)`` or ``name_unit``; ``height`` and
    ``elevation`` are read as the displacement). Time in s or ms; distance in m, cm, mm
    or km, turned into time with the vehicle ``speed`` [m/s] (the car passes the first
    sample at t = 0); height in m, cm or mm. A column without a unit, and a file
    without a header (two columns, time and displacement), are read in SI units (s, m).

    An unknown unit or column, a bad row, a non-finite value or a time (distance) that
    does not increase raises :class:`DataFileError` naming the file and line.

    Parameters
    ----------
    path : path-like
    speed : float, optional
        Vehicle speed [m/s]; required for a profile over distance, refused for one
        over time.
    units : dict, optional
        Units of columns the header leaves without one, e.g. ``{"displacement": "mm"}``.
    """

    p = Path(path)
    tab = read_columns(
        p,
        ROAD_COLUMNS,
        units=units,
        default_units={"time": "s", "distance": "m", "displacement": "m"},
        headerless=("time", "displacement"),
        increasing=("time", "distance"),
        min_rows=2,
        what="road",
    )
    hl = (tab.header_line or 0) + 1
    if "displacement" not in tab:
        raise DataFileError(p, "missing column 'displacement' (the road height)", hl)
    has_t, has_x = "time" in tab, "distance" in tab
    if has_t == has_x:
        raise DataFileError(
            p, "needs exactly one of the columns 'time' and 'distance'" + (
                "" if has_t else " (found neither)"), hl
        )
    if len(tab.columns) != 2:
        raise DataFileError(p, "expected two columns: time or distance, and displacement", hl)
    if has_x:
        if speed is None:
            raise DataFileError(
                p,
                "the road is given over distance; pass the vehicle speed "
                "(speed=..., --speed) to turn it into time",
                hl,
            )
        v = check_positive("speed", speed, "m/s")
        t = (tab["distance"] - tab["distance"][0]) / v
    else:
        if speed is not None:
            raise ParameterError(
                "speed", speed, "no speed for a road given over time (it has a time column)"
            )
        t = tab["time"]
        if t[0] < 0:
            raise DataFileError(p, f"negative time {t[0]!r}", tab.first_data_line)
    return RoadSeries(time=t, displacement=tab["displacement"], label=p.name)
