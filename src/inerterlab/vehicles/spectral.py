"""Stochastic response of a linear vehicle: spectral method, H2 norms, time simulation.

Spectral method. The tracks (left, right) have the one-sided spectral matrix
G(f) [[1, rho], [rho, 1]] with G(f) = Gd(f/V)/V and rho the left/right ratio of
:class:`~inerterlab.vehicles.roads.RoadSpectrum`; the rear wheels see the front track
delayed by tau = (a + b)/V, so the wheel inputs are r(f) = T(f) t(f) with
T = [[1, 0], [0, 1], [e^-j w tau, 0], [0, e^-j w tau]] (half car: one track, [1, e^-j w tau]).
Factoring G [[1, rho], [rho, 1]] = L L^H, each output's PSD is
S_y(f) = || H_y(f) T(f) L(f) ||^2 with H_y the transfer row from the wheel heights, and
its mean square the integral of S_y over the band (trapezoidal rule in ln f on a
logarithmic grid). No time simulation is involved.

Lift-off: with a Gaussian dynamic tyre load of standard deviation sigma, the
probability that the contact force F0 + F_dyn is negative (the tyre would leave the
road) is P(F_dyn < -F0) = erfc(F0 / (sigma sqrt2)) / 2, one-sided: a load above 2 F0
presses harder, it lifts nothing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, check_positive
from ..iso2631 import vibration_total_value, weighting
from .linear import LinearVehicle
from .roads import RoadSpectrum

__all__ = [
    "SpectralResult",
    "lift_off_probability",
    "spectral_response",
    "output_psd",
    "white_velocity_h2",
    "white_velocity_h2_gradient",
    "WhiteVelocityH2",
    "simulate",
    "road_inputs",
    "generated_road",
    "Mode",
    "modes",
]


@dataclass(frozen=True)
class SpectralResult:
    """PSDs [unit^2/Hz] on ``freq`` [Hz], RMS values, units and lift-off probabilities."""

    freq: np.ndarray
    psd: dict
    rms: dict
    units: dict
    static_load: dict
    lift_off: dict
    speed: float

    def to_dict(self) -> dict:
        return {
            "speed": self.speed,
            "rms": dict(self.rms),
            "units": dict(self.units),
            "static_tyre_load": dict(self.static_load),
            "lift_off_probability": dict(self.lift_off),
        }


def _track_width(vehicle: LinearVehicle) -> float:
    p = vehicle.parameters
    return 0.5 * (p.front_track + p.rear_track)


def input_factor(vehicle: LinearVehicle, road: RoadSpectrum, speed: float, freq):
    """(n_freq, n_inputs, n_tracks) factor F with wheel-input spectral matrix F F^H."""
    f = np.asarray(freq, dtype=float)
    g = road.temporal_psd(f, speed)
    tau = vehicle.parameters.wheelbase / speed
    delay = np.exp(-2j * math.pi * f * tau)
    sq = np.sqrt(g)
    if vehicle.kind == "half":
        F = np.zeros((f.size, 2, 1), complex)
        F[:, 0, 0] = sq
        F[:, 1, 0] = sq * delay
        return F
    rho = road.rho(f / speed, _track_width(vehicle))
    L = np.zeros((f.size, 2, 2))
    L[:, 0, 0] = sq
    L[:, 1, 0] = sq * rho
    L[:, 1, 1] = sq * np.sqrt(np.clip(1.0 - rho * rho, 0.0, None))
    T = np.zeros((f.size, 4, 2), complex)
    T[:, 0, 0] = T[:, 1, 1] = 1.0
    T[:, 2, 0] = T[:, 3, 1] = delay
    return T @ L


def output_psd(vehicle: LinearVehicle, freq, factor, outputs=None, weighted=None) -> dict:
    """One-sided PSD of each output given the wheel-input factor (see :func:`input_factor`).

    ``weighted`` maps new names to (output, weighting name), e.g.
    {"seat_acc_wk": ("seat_acc", "Wk")}: the PSD of the ISO 2631 weighted signal.
    """
    H = vehicle.frequency_response(freq, outputs)
    out = {k: np.sum(np.abs(h[:, None, :] @ factor) ** 2, axis=(1, 2)) for k, h in H.items()}
    for name, (src, w) in (weighted or {}).items():
        out[name] = out[src] * weighting(w).magnitude(freq) ** 2
    return out


def _mean_square(freq, psd) -> float:
    f = np.asarray(freq)
    return float(np.trapezoid(psd * f, np.log(f)))


def spectral_response(
    vehicle: LinearVehicle,
    road: RoadSpectrum,
    speed: float,
    *,
    points: int = 4000,
    freq=None,
) -> SpectralResult:
    """Response PSDs and RMS values of ``vehicle`` on ``road`` at ``speed`` [m/s].

    The frequency grid is ``points`` values spaced logarithmically over the road band
    seen at this speed, or ``freq`` [Hz]. Adds the Wk-weighted seat (or, without a
    seat, bounce) acceleration as ``seat_acc_wk`` (``bounce_acc_wk``), the We-weighted
    pitch and roll accelerations (``pitch_acc_we``, ``roll_acc_we``) and, with a seat,
    ``seat_total_value``: ISO 2631-1's comfort total value on the seat surface from the
    axes the model has, sqrt(a_wz^2 + (0.40 a_w,pitch)^2 + (0.63 a_w,roll)^2) [m/s^2]
    (the seat's fore-aft and lateral motions are not modelled, so they are missing).
    """
    v = check_positive("speed", speed, "m/s")
    if freq is None:
        lo, hi = road.band
        freq = np.geomspace(lo * v, hi * v, int(points))
    freq = np.asarray(freq, dtype=float)
    if freq.ndim != 1 or freq.size < 3 or np.any(freq <= 0) or np.any(np.diff(freq) <= 0):
        raise ParameterError("freq", "grid", "an increasing grid of > 2 positive frequencies")
    fac = input_factor(vehicle, road, v, freq)
    acc = "seat_acc" if "seat_acc" in vehicle.outputs else "bounce_acc"
    weighted = {f"{acc}_wk": (acc, "Wk")}
    rot = {"ry": "pitch_acc", "rx": "roll_acc"}
    rot = {axis: out for axis, out in rot.items() if out in vehicle.outputs}
    for out in rot.values():
        weighted[f"{out}_we"] = (out, "We")
    psd = output_psd(vehicle, freq, fac, weighted=weighted)
    rms = {k: math.sqrt(_mean_square(freq, s)) for k, s in psd.items()}
    units = {k: vehicle.outputs[k].unit for k in vehicle.outputs}
    units[f"{acc}_wk"] = "m/s^2"
    for out in rot.values():
        units[f"{out}_we"] = "rad/s^2"
    if acc == "seat_acc":
        parts = {"z": rms["seat_acc_wk"], **{a: rms[f"{o}_we"] for a, o in rot.items()}}
        rms["seat_total_value"] = vibration_total_value(parts, "comfort-seat")
        units["seat_total_value"] = "m/s^2"
    static = vehicle.static_tyre_loads()
    lift = {c: lift_off_probability(static[c], rms[f"{c}_tyre_load"]) for c in vehicle.corners}
    return SpectralResult(
        freq=freq, psd=psd, rms=rms, units=units, static_load=static, lift_off=lift, speed=v
    )


@dataclass(frozen=True)
class Mode:
    """One eigenvalue lambda [1/s] of the linear vehicle's state matrix (an oscillatory
    mode is the one of its conjugate pair with Im lambda > 0).

    ``damped_hz`` = Im lambda / 2 pi, the frequency the free motion oscillates at;
    ``natural_hz`` = |lambda| / 2 pi, the undamped natural frequency of the equivalent
    1-DOF oscillator; ``damping_ratio`` = -Re lambda / |lambda|. A real (overdamped)
    mode has no frequency: its ``decay_rate`` = -lambda [1/s] and ``time_constant`` =
    -1/lambda [s]."""

    eigenvalue: complex

    @property
    def oscillatory(self) -> bool:
        return self.eigenvalue.imag > 0.0

    @property
    def damped_hz(self) -> float:
        return float(self.eigenvalue.imag / (2 * math.pi))

    @property
    def natural_hz(self) -> float:
        return float(abs(self.eigenvalue) / (2 * math.pi))

    @property
    def damping_ratio(self) -> float:
        return float(-self.eigenvalue.real / abs(self.eigenvalue))

    @property
    def decay_rate(self) -> float:
        return float(-self.eigenvalue.real)

    @property
    def time_constant(self) -> float:
        return math.inf if self.eigenvalue.real == 0.0 else float(-1.0 / self.eigenvalue.real)

    def to_dict(self) -> dict:
        if self.oscillatory:
            return {
                "damped_frequency_hz": self.damped_hz,
                "damping_ratio": self.damping_ratio,
                "natural_frequency_hz": self.natural_hz,
            }
        return {"decay_rate_per_s": self.decay_rate, "time_constant_s": self.time_constant}


def modes(vehicle: LinearVehicle) -> tuple[list[Mode], list[Mode]]:
    """(oscillatory modes by ascending damped frequency, real modes by ascending decay
    rate) of the linear vehicle, from the eigenvalues of its state matrix (network
    struts' internal states included). An eigenvalue is real where
    |Im lambda| <= 1e-9 max(1, max |lambda|) (a conjugate pair of an exactly
    overdamped mode comes out of the eigensolver as two real values)."""
    lam = np.linalg.eigvals(vehicle.state_space()[0])
    tol = 1e-9 * max(1.0, float(np.abs(lam).max(initial=0.0)))
    osc = sorted((complex(x) for x in lam if x.imag > tol), key=lambda z: z.imag)
    real = sorted(
        (complex(x.real, 0.0) for x in lam if abs(x.imag) <= tol and abs(x) > tol),
        key=lambda z: -z.real,
    )
    return [Mode(z) for z in osc], [Mode(z) for z in real]


def lift_off_probability(static_load: float, sigma: float, mean: float = 0.0) -> float:
    """P(F0 + F_dyn < 0) [-] for a Gaussian dynamic tyre load F_dyn of mean ``mean`` and
    standard deviation ``sigma`` [N] on the static load ``static_load`` F0 [N]:
    erfc((F0 + mean) / (sigma sqrt 2)) / 2 (the fraction of time the linear tyre would
    pull, that is, a one-sided tyre would be off the road)."""
    if sigma <= 0.0:
        return 0.0 if static_load + mean > 0.0 else 1.0
    return 0.5 * math.erfc((static_load + mean) / (sigma * math.sqrt(2.0)))


class WhiteVelocityH2(dict):
    """Output name -> H2 norm per unit white road velocity [output unit per m/s of road
    velocity, two-sided density 1], ``math.inf`` where infinite; ``reasons`` says in one
    line why each infinite norm is infinite and which finite quantity to use instead."""

    def __init__(self, values: dict, reasons: dict, road: str):
        super().__init__(values)
        self.reasons = dict(reasons)
        self.road = road


def _band_alternative() -> str:
    return (
        "the road band-limited to ISO 8608's 0.01-10 cycle/m (spectral_response gives its "
        "RMS value over that band)"
    )


def white_velocity_h2(
    vehicle: LinearVehicle, *, speed: float | None = None, weighted: dict | None = None,
    outputs=None,
) -> WhiteVelocityH2:  # fmt: skip
    """H2 norm of outputs under white road velocity, by Lyapunov equations.

    Road model: without ``speed``, each wheel's road velocity is independent unit
    white noise (two-sided spectral density 1). With ``speed`` [m/s] the road is
    tracks (half car: one; full car: left and right, independent of each other), each
    of unit white velocity, and the rear wheels see their track delayed by
    tau = wheelbase / speed: an ISO 8608 road of waviness 2 without band limits, per
    unit of its velocity density. The delay is exact: with P the gramian of all wheel
    inputs and X the solution of A X + X A^T + B_front B_rear^T = 0, the variance of
    y = C x is C P C^T + 2 C e^(A tau) X C^T.

    ``weighted`` maps new names to (acceleration output, weighting name), e.g.
    {"seat_acc_wk": ("seat_acc", "Wk")}: the weighting filter of ISO 2631-1
    (:meth:`inerterlab.iso2631.Weighting.state_space`, no feed-through) is cascaded
    after the output as further states, so the norm is exact and finite even when the
    output has a feed-through of road velocity.

    With r = u/s the transfer from u is G_r(0)/s + Cy (sI - A)^-1 (A^-1 Br + Bd) + Dd;
    an unweighted norm is finite when G_r(0) = 0 (summed over a track's wheels with a
    delay: the output returns to 0 after a step of the road) and Dd = 0 (no direct
    feed-through of road velocity). An infinite norm is ``math.inf`` and
    ``result.reasons[name]`` says why and what to use instead.
    """
    from ..h2 import variance_gradient

    A, Br, Bd, Cy, Dr, Dd = vehicle.state_space()
    names = list(Cy) if outputs is None else list(outputs)
    for k in names:
        if k not in Cy:
            raise ParameterError("output", k, "one of " + ", ".join(Cy))
    weighted = dict(weighted or {})
    delay, road = _road(vehicle, speed)

    def norm(Aa, Ba, Ca):
        val = variance_gradient(Aa, Ba, Ca, delay=delay, gradient=False, what="vehicle H2 norms")[0]
        return math.sqrt(max(val, 0.0))

    vals, why = {}, {}
    for k in names:
        why_k = _infinite(vehicle, (A, Br, Bd, Cy, Dr, Dd), k, delay)
        if why_k:
            vals[k], why[k] = math.inf, why_k
        else:
            vals[k] = norm(*_h2_system((A, Br, Bd, Cy, Dr, Dd), k, None))
    for new, (src, wname) in weighted.items():
        if src not in Cy:
            raise ParameterError("weighted", src, "an output of " + ", ".join(Cy))
        vals[new] = norm(*_h2_system((A, Br, Bd, Cy, Dr, Dd), src, wname, delay))
    return WhiteVelocityH2(vals, why, road)


def _road(vehicle, speed):
    """(delay, description) of the white-velocity road: delay (tau, front, rear) of
    :func:`inerterlab.h2.variance_gradient` (None without a speed)."""
    if speed is None:
        return None, "independent unit white road velocity at each wheel"
    v = check_positive("speed", speed, "m/s")
    tau = vehicle.parameters.wheelbase / v
    front, rear = ([0], [1]) if vehicle.kind == "half" else ([0, 1], [2, 3])
    return (tau, front, rear), (
        f"unit white road velocity on each track, the rear wheels delayed by {tau:.4g} s "
        f"({v:g} m/s)"
    )


def _step_response(ss, k, delay):
    """The static change of output k after a unit step of each track's height. A
    linearised core car may carry the free drift of an internal node (a zero eigenvalue
    no output sees): the least-squares solve leaves that direction out."""
    A, Br, Bd, Cy, Dr, Dd = ss
    dc = np.atleast_2d(Dr[k] - Cy[k] @ np.linalg.lstsq(A, Br, rcond=None)[0])
    if delay is None:
        return dc
    _, front, rear = delay
    return dc[:, front] + dc[:, rear]


def _infinite(vehicle, ss, k, delay) -> str:
    """'' if the unweighted H2 norm of output k is finite, else why not (one line)."""
    A, Br, Bd, Cy, Dr, Dd = ss
    scale = 1.0 + float(np.max(np.abs(Cy[k])))
    if np.max(np.abs(Dd[k])) > 1e-12 * scale:
        return (
            f"{k} is infinite under white road velocity: the tyre damper passes the road "
            "velocity straight to it (direct feed-through); use a weighted acceleration, "
            f"zero tyre damping, or {_band_alternative()}"
        )
    if np.max(np.abs(_step_response(ss, k, delay))) > 1e-9 * scale:
        return (
            f"{k} is infinite under white road velocity: a step of the road leaves a "
            "static change of it (white velocity makes the heights a random walk; e.g. "
            "the warp of a full car on tracks of different widths); use "
            + _band_alternative()
        )
    return ""


def _h2_system(ss, src, wname, delay=None):
    """(A, B, c) driven by white road velocity whose output c x is ``src`` (through the
    weighting ``wname``'s states, or alone for None). With r = u/s the road velocity
    u enters as B = A^-1 Br + Bd (the static part G_r(0)/s must vanish, checked by the
    caller). Any dtype: a state space carrying a complex step gives its derivative."""
    from ..iso2631 import WEIGHTINGS

    A, Br, Bd, Cy, Dr, Dd = ss
    Bv = np.linalg.solve(A, Br) + Bd
    if wname is None:
        return A, Bv, Cy[src]
    if np.max(np.abs(_step_response(ss, src, delay))) > 1e-9 * (
        1.0 + float(np.max(np.abs(Cy[src])))
    ):
        raise ParameterError("weighted", src, "an acceleration (no static response)")
    fA, fB, fC, _ = WEIGHTINGS[wname].state_space()
    fB, fC = np.ravel(fB), np.ravel(fC)
    n, nf = A.shape[0], fA.shape[0]
    Aa = np.zeros((n + nf, n + nf), dtype=A.dtype)
    Aa[:n, :n] = A
    Aa[n:, :n] = np.outer(fB, Cy[src])
    Aa[n:, n:] = fA
    Ba = np.vstack([Bv, np.outer(fB, Dd[src])])
    Ca = np.concatenate([np.zeros(n), fC])
    return Aa, Ba, Ca


def white_velocity_h2_gradient(vehicle, output: str, steps, *, speed=None, weighting=None):
    """The H2 norm of :func:`white_velocity_h2` of one ``output`` (through the weighting
    named ``weighting``, e.g. "Wk") and its derivatives, by the adjoint equations
    (:func:`inerterlab.h2.variance_gradient`).

    ``steps``: (vehicle, h) pairs, each the same :class:`LinearVehicle` whose state
    space carries h x its derivative in one parameter as the imaginary part
    (:func:`inerterlab.vehicles.design.stepped_vehicles`); the augmented system is taken
    through the same complex arithmetic, so its imaginary parts over h are the
    derivatives of its matrices. Returns (norm, list of
    d norm / d parameter); (inf, None) where the norm is infinite."""
    from ..h2 import variance_gradient

    ss = vehicle.state_space()
    delay, _ = _road(vehicle, speed)
    if weighting is None and _infinite(vehicle, ss, output, delay):
        return math.inf, None
    Aa, Ba, Ca = _h2_system(ss, output, weighting, delay)
    J, gA, gB, gc = variance_gradient(Aa, Ba, Ca, delay=delay, what="vehicle H2 norms")
    if J <= 0.0:
        return 0.0, [0.0] * len(steps)
    val = math.sqrt(J)
    out = []
    for veh, h in steps:
        A2, B2, c2 = _h2_system(veh.state_space(), output, weighting, delay)
        dJ = (np.sum(gA * A2.imag) + np.sum(gB * B2.imag) + float(gc @ c2.imag)) / h
        out.append(float(dJ) / (2.0 * val))
    return val, out


def road_inputs(
    vehicle: LinearVehicle, x, z_left, z_right, speed: float, dt: float, periodic: bool = True
):
    """Wheel heights (n_t, n_inputs) sampled every ``dt`` [s] at ``speed`` [m/s].

    The front wheels start one wheelbase along the profiles (x [m], evenly spaced),
    the rear wheels at the start, and the run ends when the front wheels reach the end.
    ``periodic``: the profiles repeat with period x[-1] + dx (generated roads), so the
    last interval joins the end to the start; otherwise (measured roads) they end at x[-1].
    """
    v = check_positive("speed", speed, "m/s")
    x = np.asarray(x, dtype=float) - float(x[0])
    wb = vehicle.parameters.wheelbase
    end = x[-1] + (x[1] - x[0]) if periodic else x[-1]
    if end <= wb:
        raise ParameterError("profile length", end, f"longer than the wheelbase {wb:g} m")
    nt = int(math.floor((end - wb) / (v * dt))) + (0 if periodic else 1)
    s = v * dt * np.arange(nt)

    def at(z, pos):
        z = np.asarray(z, dtype=float)
        if periodic:
            return np.interp(pos, np.append(x, end), np.append(z, z[0]))
        return np.interp(pos, x, z)

    if vehicle.kind == "half":
        return np.column_stack([at(z_left, s + wb), at(z_left, s)])
    return np.column_stack([at(z_left, s + wb), at(z_right, s + wb), at(z_left, s), at(z_right, s)])


def generated_road(
    vehicle,
    spectrum: RoadSpectrum,
    *,
    length: float,
    speed: float,
    dt: float,
    track: float,
    seed: int | None = 0,
) -> np.ndarray:
    """Wheel heights (n_t, stations) [m] every ``dt`` [s] of a generated ISO 8608 road
    (:func:`~.roads.track_coefficients`, sample spacing speed x dt, left/right
    ``track`` [m] apart) under ``vehicle`` (a car's parameters, or a vehicle with them).

    The road is the trigonometric series of its Fourier coefficients, so each wheel's
    heights are the series evaluated where that wheel is: a wheel a distance d ahead of
    the rear axle sees the coefficients times exp(2 pi i n_k d) (the series shifted), so
    the front wheels, which sit between the road's samples, are not interpolated. The
    simulation joins these samples by straight lines (a first-order hold), which takes
    a little power out of the top of the band (docs/decisions.md, "The vehicle's time
    domain on the core"). The rear wheels start at x = 0, the front wheels a wheelbase
    ahead, and the run ends when the front wheels reach the end of the period, as in
    :func:`road_inputs`.
    """
    from .parameters import FullCar
    from .roads import track_coefficients

    p = getattr(vehicle, "parameters", vehicle)
    v = check_positive("speed", speed, "m/s")
    h = check_positive("dt", dt, "s")
    dx, n, zl, zr = track_coefficients(spectrum, length=length, step=v * h, track=track, seed=seed)
    count = 2 * (n.size - 1)
    wb = p.wheelbase
    end = count * dx
    if end <= wb:
        raise ParameterError("length", end, f"longer than the wheelbase {wb:g} m")
    nt = int(math.floor((end - wb) / dx))
    if nt < 2:
        raise ParameterError("length", end, f"at least two samples beyond the wheelbase {wb:g} m")
    if isinstance(p, FullCar):
        wheels = [(zl, wb), (zr, wb), (zl, 0.0), (zr, 0.0)]
    else:
        wheels = [(zl, wb), (zl, 0.0)]
    heights = np.empty((nt, len(wheels)))
    for i, (z, ahead) in enumerate(wheels):
        heights[:, i] = np.fft.irfft(z * np.exp(2j * math.pi * n * ahead), n=count)[:nt]
    return heights


def simulate(vehicle: LinearVehicle, r, dt: float, outputs=None) -> dict:
    """Outputs of ``vehicle`` for wheel heights ``r`` (n_t, n_inputs) linear between
    samples ``dt`` [s] apart, starting at rest in equilibrium (exact discretisation).

    With xi = x - Bd r the road velocity leaves the state equation:
    xi' = A xi + (Br + A Bd) r, y = Cy xi + (Cy Bd + Dr) r + Dd r' (r' the slope of
    the current sample interval).
    """
    from .roads import _foh_matrices

    dt = check_positive("dt", dt, "s")
    r = np.asarray(r, dtype=float)
    A, Br, Bd, Cy, Dr, Dd = vehicle.state_space()
    phi, g0, g1 = _foh_matrices(A, Br + A @ Bd, dt)
    du = np.diff(r, axis=0)
    x0 = -np.linalg.solve(A, Br @ r[0])  # static equilibrium on the first road heights
    xi = _propagate(phi, g0 @ r[:-1].T, g1 @ du.T, x0 - Bd @ r[0])
    rdot = np.vstack([du / dt, du[-1:] / dt])
    out = {}
    for k in outputs or Cy:
        out[k] = Cy[k] @ xi + (Cy[k] @ Bd + Dr[k]) @ r.T + Dd[k] @ rdot.T
    return out


def _propagate(phi, a, b, x0):
    """Columns x_{k+1} = phi x_k + a_k + b_k, x_0 = x0 (compiled loop)."""
    from numba import njit

    global _prop_kernel
    if _prop_kernel is None:

        @njit(cache=False)
        def kern(phi, f, x0):
            n, m = f.shape
            x = np.empty((n, m + 1))
            x[:, 0] = x0
            for k in range(m):
                for i in range(n):
                    acc = f[i, k]
                    for j in range(n):
                        acc += phi[i, j] * x[j, k]
                    x[i, k + 1] = acc
            return x

        _prop_kernel = kern
    return _prop_kernel(np.ascontiguousarray(phi), np.ascontiguousarray(a + b), x0.astype(float))


_prop_kernel = None
