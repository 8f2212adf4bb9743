"""Ride metrics: their keys and units, the Wk weighting of a sampled acceleration, the
metrics of sampled series, H2 indices.

The simulations compute the metrics on the fly (observer states);
:func:`series_metrics` recomputes them from sampled output, for user data and
cross-checks, with the sampled-signal statistics of :mod:`inerterlab.iso2631`.

ISO 2631-1 Wk (docs/model.md §9, parameters of ISO 8041-1), with w_i = 2 pi f_i:

    Hh = 1/(1 + sqrt2 w1/s + (w1/s)^2)              high pass, f1 = 0.4 Hz
    Hl = 1/(1 + sqrt2 s/w2 + (s/w2)^2)              low pass, f2 = 100 Hz
    Ht = (1 + s/w3)/(1 + s/(Q4 w4) + (s/w4)^2)      f3 = f4 = 12.5 Hz, Q4 = 0.63
    Hs = (w5/w6)^2 (1 + s/(Q5 w5) + (s/w5)^2)/(1 + s/(Q6 w6) + (s/w6)^2)
                                                    f5 = 2.37, f6 = 3.35 Hz, Q = 0.91
    Wk = Hh Hl Ht Hs

The (w5/w6)^2 factor is kept and the peak is not normalised to 1.

H2 indices (thesis (4.12), (4.17), (4.22); docs/model.md §9): for a linear quarter car driven by
unit white road velocity, ||H||_2^2 = C P C^T with A P + P A^T + B B^T = 0. On an
ISO 8608 road of class Gd(n0) at speed V, rms = pi n0 sqrt(2 Gd(n0) V) ||H||_2.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from .errors import ParameterError, check_choice, check_positive

__all__ = [
    "wk_weighting",
    "wk_state_space",
    "weighted_acceleration",
    "h2_norms_state_space",
    "series_metrics",
    "H2Norms",
    "h2_norms",
    "METRIC_KEYS",
    "METRIC_UNITS",
]

METRIC_KEYS = (
    "rms_body_acc",
    "rms_tyre_grip",
    "rms_deflection",
    "rms_body_acc_wk",
    "vdv",
    "crest_factor",
    "peak_body_acc",
    "peak_body_acc_wk",
    "peak_deflection",
    "min_tyre_force",
    "tyre_lift_off",
)

#: unit of each metric of :data:`METRIC_KEYS` ("1" for a ratio, "" for a flag)
METRIC_UNITS = {
    "rms_body_acc": "m/s^2",
    "rms_tyre_grip": "1",
    "rms_deflection": "m",
    "rms_body_acc_wk": "m/s^2",
    "vdv": "m/s^1.75",
    "crest_factor": "1",
    "peak_body_acc": "m/s^2",
    "peak_body_acc_wk": "m/s^2",
    "peak_deflection": "m",
    "min_tyre_force": "N",
    "tyre_lift_off": "",
}


def wk_weighting(freq_hz):
    """Complex Wk weighting at frequency ``freq_hz`` [Hz]: the ISO 2631-1 formula of
    :data:`inerterlab.iso2631.WEIGHTINGS` ``["Wk"]`` (its one definition).

    Examples
    --------
    >>> [round(float(abs(wk_weighting(f))), 3) for f in (0.5, 1.0)]
    [0.418, 0.482]
    """
    from .iso2631 import WEIGHTINGS

    return WEIGHTINGS["Wk"].response(freq_hz)


def wk_state_space():
    """Wk as x' = A x + B a, a_w = C x + D a (8 states, D = 0): the cascade of
    :meth:`inerterlab.iso2631.Weighting.state_space` (high pass, low pass, a-v
    transition, upward step; each section's states of the size of its input, which
    keeps absolute tolerances meaningful), with B and C as vectors."""
    A, B, C, D = _wk_state_space()
    return A.copy(), B.copy(), C.copy(), D


@functools.lru_cache(maxsize=1)
def _wk_state_space():
    """:func:`wk_state_space`, built once (every quarter-car run reads it)."""
    from .iso2631 import WEIGHTINGS

    A, B, C, D = WEIGHTINGS["Wk"].state_space()
    b, c = np.ravel(B).astype(float), np.ravel(C).astype(float)
    return np.asarray(A, float), b, c, float(D[0, 0])


def _uniform_step(time, samples) -> float:
    """The step [s] of the evenly spaced ``time``, one per sample of ``samples``;
    ParameterError otherwise (to 1e-9 of the step)."""
    t = np.asarray(time, float)
    a = np.asarray(samples, float)
    if t.ndim != 1 or a.shape != t.shape or t.size < 2:
        raise ParameterError("time", f"shape {t.shape} for {a.shape} samples",
                             "one time per sample, at least two")  # fmt: skip
    dt = float(t[1] - t[0])
    if not dt > 0.0 or np.max(np.abs(np.diff(t) - dt)) > 1e-9 * dt:
        raise ParameterError("time", "uneven or decreasing samples", "evenly spaced times")
    return dt


def weighted_acceleration(time, acceleration):
    """Wk-weighted acceleration a_w [m/s^2] of a signal sampled at the uniform
    ``time`` [s], the filter at rest at the first sample and the signal linear between
    samples (first-order hold: the exact discretisation, so it converges to the
    continuous filter): :meth:`inerterlab.iso2631.Weighting.hold_response` of Wk.
    ParameterError where the samples are not evenly spaced (to 1e-9 of the step)."""
    from .iso2631 import WEIGHTINGS

    dt = _uniform_step(time, acceleration)
    return WEIGHTINGS["Wk"].hold_response(np.asarray(acceleration, float), dt)


def series_metrics(
    time, body_acc, tyre_grip, deflection, tyre_force=None, weighted_acc=None
) -> dict:
    """The metrics of :data:`METRIC_KEYS` from series sampled at the evenly spaced
    ``time`` [s], by the sampled-signal statistics of :mod:`inerterlab.iso2631`
    (:func:`~inerterlab.iso2631.rms`, :func:`~inerterlab.iso2631.vibration_dose_value`,
    :func:`~inerterlab.iso2631.crest_factor`: the trapezoidal rule over the span).

    Less accurate than the on-the-fly integrals of the simulation (sampling error);
    meant for user data and cross-checks.
    """
    from . import iso2631

    dt = _uniform_step(time, body_acc)
    for name, x in (("tyre_grip", tyre_grip), ("deflection", deflection),
                    ("weighted_acc", weighted_acc), ("tyre_force", tyre_force)):  # fmt: skip
        if x is not None and np.shape(x) != np.shape(time):
            raise ParameterError(name, f"shape {np.shape(x)}", f"one value per time {np.shape(time)}")
    if weighted_acc is None:  # the times checked above: filter at once
        aw = iso2631.WEIGHTINGS["Wk"].hold_response(np.asarray(body_acc, float), dt)
    else:
        aw = np.asarray(weighted_acc, float)
    out = {
        "rms_body_acc": iso2631.rms(body_acc),
        "rms_tyre_grip": iso2631.rms(tyre_grip),
        "rms_deflection": iso2631.rms(deflection),
        "rms_body_acc_wk": iso2631.rms(aw),
        "vdv": iso2631.vibration_dose_value(aw, 1.0 / dt),
        "crest_factor": iso2631.crest_factor(aw),
        "peak_body_acc": float(np.max(np.abs(body_acc))),
        "peak_body_acc_wk": float(np.max(np.abs(aw))),
        "peak_deflection": float(np.max(np.abs(deflection))),
    }
    if tyre_force is not None:
        out["min_tyre_force"] = float(np.min(tyre_force))
        out["tyre_lift_off"] = bool(out["min_tyre_force"] <= 0.0)
    return out


# -- H2 indices ------------------------------------------------------------------------
H2_OUTPUTS = ("body_acc", "tyre_deflection", "suspension_deflection", "tyre_grip", "body_acc_wk")


@dataclass(frozen=True, kw_only=True)
class H2Norms:
    """H2 norms from unit white road velocity (two-sided unit spectral density).

    Attributes
    ----------
    norms : dict
        Output name -> ||H||_2, or ``None`` where the norm is infinite.
    infinite : dict
        Output name -> why the norm is infinite (direct feed-through from the road
        velocity).
    """

    norms: dict
    infinite: dict = field(default_factory=dict)

    def __getitem__(self, key: str):
        return self.norms[key]

    def ride_indices(self, road_class: str = "C", speed: float = 20.0) -> dict:
        """RMS values on an ISO 8608 road: pi n0 sqrt(2 Gd(n0) V) ||H||_2 (docs/model.md §9).

        Outputs with an infinite norm map to ``None``.
        """
        from .excitation import ISO8608_CLASSES, ISO8608_N0

        check_choice("road_class", road_class, tuple(ISO8608_CLASSES))
        v = check_positive("speed", speed, "m/s")
        scale = math.pi * ISO8608_N0 * math.sqrt(2.0 * ISO8608_CLASSES[road_class] * v)
        return {k: (None if n is None else scale * n) for k, n in self.norms.items()}

    #: unit of each norm per unit white road velocity
    UNITS = {
        "body_acc": "m/s^2",
        "body_acc_wk": "m/s^2",
        "tyre_deflection": "m",
        "suspension_deflection": "m",
        "tyre_grip": "1",
    }

    def __repr__(self) -> str:
        parts = [
            f"{k}={'inf' if v is None else format(v, '.4g')}" for k, v in self.norms.items()
        ]
        return "<H2Norms per unit white road velocity: " + ", ".join(parts) + ">"

    def _repr_html_(self) -> str:
        from ._display import fmt, html_table

        rows = [
            (f"{k} [{self.UNITS.get(k, '')}]", "infinite" if v is None else fmt(v))
            for k, v in self.norms.items()
        ]
        return html_table("H2 norms per unit white road velocity", rows)

    def to_xarray(self):
        """The norms as an xarray Dataset (infinite ones NaN, with the reason)."""
        import xarray as xr

        data = {}
        for k, v in self.norms.items():
            attrs = {"units": self.UNITS.get(k, "")}
            if k in self.infinite:
                attrs["infinite"] = self.infinite[k]
            data[k] = ((), math.nan if v is None else float(v), attrs)
        return xr.Dataset(data, attrs={"input": "unit white road velocity"})

    def to_dict(self) -> dict:
        """Norms as a dict; infinite ones as None plus an ``infinite`` entry saying why."""
        out = dict(self.norms)
        if self.infinite:
            out["infinite"] = dict(self.infinite)
        return out


def h2_norms(model) -> H2Norms:
    """H2 norms of a linear quarter car (``traditional`` or ``cfw``) by Lyapunov equations.

    Outputs: ``body_acc`` [m/s^2], ``tyre_deflection`` and ``suspension_deflection``
    [m], ``tyre_grip`` [-] and ``body_acc_wk`` (Wk-weighted acceleration) per unit
    white road velocity. Where the road velocity feeds straight through to an output
    (body acceleration of ``cfw`` with tyre damping: the impulse C_t w reaches the body
    through the inerter) the norm is infinite: ``None`` in ``norms`` and the reason in
    ``infinite``.

    Examples
    --------
    >>> from inerterlab import quarter_car
    >>> car = quarter_car("traditional", sprung_mass=250, unsprung_mass=35,
    ...                   tyre_stiffness=150e3, tyre_damping=0.0)
    >>> n = h2_norms(car)
    >>> round(n["suspension_deflection"] ** 2, 6) == round((250 + 35) / (2 * 5000), 6)
    True
    """
    from .errors import ConvergenceError
    from .suspension.linear import linear_quarter_car
    from .suspension.model import model_of

    model = model_of(model)
    try:
        with np.errstate(all="ignore"):
            lin = linear_quarter_car(model)
    except np.linalg.LinAlgError as exc:
        raise ConvergenceError(
            f"H2 norms: the mass matrix is singular to machine precision ({exc}); the "
            "inertance and the masses are too far apart in scale"
        ) from None
    return h2_norms_state_space(lin, label=model.suspension)


def h2_norms_state_space(lin, *, label: str = "model") -> H2Norms:
    """H2 norms of any stable linear quarter car given as x' = A x + B w with outputs
    ``C[name] x + D[name] w`` for the names of :data:`H2_OUTPUTS` but ``body_acc_wk``
    (which is formed here with the Wk filter); ``lin`` is a
    :class:`~inerterlab.suspension.linear.LinearQuarterCar` or any object with ``A``,
    ``B``, ``C``, ``D``. ``label`` names the model in errors."""
    from .h2 import gramian

    A, B = lin.A, lin.B
    # augment with the Wk filter driven by the body acceleration
    wa, wb, wc, _ = wk_state_space()
    n, m = A.shape[0], wa.shape[0]
    Aa = np.zeros((n + m, n + m))
    Aa[:n, :n] = A
    Aa[n:, :n] = np.outer(wb, lin.C["body_acc"])
    Aa[n:, n:] = wa
    Ba = np.concatenate([B, wb * lin.D["body_acc"]])
    P = gramian(Aa, Ba, what="H2 norms")
    norms, infinite = {}, {}
    outputs = {k: (np.concatenate([c, np.zeros(m)]), lin.D[k]) for k, c in lin.C.items()}
    outputs["body_acc_wk"] = (np.concatenate([np.zeros(n), wc]), 0.0)
    for k in H2_OUTPUTS:
        c, d = outputs[k]
        if abs(d) > 1e-12 * (1.0 + float(np.max(np.abs(c)))):
            norms[k] = None
            infinite[k] = (
                f"infinite: the road velocity feeds straight through to {k} "
                f"(gain {d:.4g}; tyre damping acting through the inertance)"
            )
            continue
        val = float(c @ P @ c)
        if val < 0:
            raise ParameterError("model", label, "an asymptotically stable quarter car")
        norms[k] = math.sqrt(val)
    return H2Norms(norms=norms, infinite=infinite)
