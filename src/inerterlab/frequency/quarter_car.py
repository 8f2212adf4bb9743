"""The quarter car as a first-order system for the harmonic balance.

The balance evaluates the right-hand side the time simulation integrates,
:func:`inerterlab.suspension._kernels._rhs_road` with the packed parameters of
:attr:`QuarterCar.kernel_parameters` (docs/model.md §5): no second copy of the physics.
The states in the balance are the physical ones (``QuarterCar.state_names``); the metric
states that follow them in the simulation (integrals and the Wk filter, which do not
feed back) are held at zero and their derivatives ignored. Outputs are computed from the
periodic states afterwards:

``body_displacement`` [m]      X3
``body_acceleration`` [m/s^2]  X3'' = f_V3
``suspension_deflection`` [m]  X3 - X2
``tyre_force`` [N]             K_t (X2 - X1) + C_t (V2 - X1'), as in the simulation's peaks

The road is X1 = A sin(Omega t).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ..errors import ParameterError
from ..suspension._kernels import _rhs_road
from ..suspension.model import N_METRIC_STATES, P_CT, P_KT, QuarterCar
from .first_order import RHS_SIGNATURE

__all__ = [
    "FirstOrderSystem",
    "quarter_car_system",
    "from_core_system",
    "QUARTER_CAR_OUTPUTS",
    "SMOOTH_SUSPENSIONS",
]

#: output name -> unit
QUARTER_CAR_OUTPUTS = {
    "body_displacement": "m",
    "body_acceleration": "m/s^2",
    "suspension_deflection": "m",
    "tyre_force": "N",
}
SMOOTH_SUSPENSIONS = ("traditional", "cfw", "afw")
# The Wk filter is outside the balance: its coefficients are held at zero (a compiled
# constant, so the right-hand side allocates nothing)
_WK_ZERO = np.zeros((4, 5))


@dataclass(frozen=True, kw_only=True, eq=False)
class FirstOrderSystem:
    """A system x' = f(t, x, u(t)) for :func:`inerterlab.frequency.frequency_response`.

    Parameters
    ----------
    n_states : int
        States in the balance.
    rhs : numba dispatcher
        Compiled for :data:`inerterlab.frequency.first_order.RHS_SIGNATURE`:
        ``rhs(t, x, road, int_table, float_table, out)``, road = [X1, X1', X1''].
    int_table, float_table : ndarray
        Its parameters (int64, float64).
    work_size : int
        Length of the arrays ``rhs`` is called with (>= n_states).
    state_scales : ndarray
        Typical size of each state (finite-difference steps, settling test).
    rest_state : ndarray, optional
        Cold start of Newton and start of the brute force.
    output_samples : callable, optional
        ``output_samples(xs, fs, road) -> {name: samples}`` with xs, fs of shape
        (P, n, K) (states and their derivatives at K phases) and road of shape (P, 3, K).
    compiled_outputs : numba dispatcher, optional
        Instead of ``output_samples``: ``compiled_outputs(t, x, road, int_table,
        float_table, out) -> bool`` (the signature of ``rhs``) filling ``n_outputs``
        values, and ``combine_outputs(O) -> {name: samples}`` with O of shape
        (P, n_outputs, K).
    output_units : dict
        Unit of each output.
    response_state : int
        The state whose half peak-to-peak is ``amplitude_m`` when there are no outputs.
    nonlinearity_degree : int
        For the aliasing rule (samples per period).
    label : str
    """

    n_states: int
    rhs: object
    int_table: np.ndarray
    float_table: np.ndarray
    work_size: int = 0
    state_scales: np.ndarray | None = None
    rest_state: np.ndarray | None = None
    jacobian: object = None
    output_samples: object = None
    compiled_outputs: object = None
    n_outputs: int = 0
    combine_outputs: object = None
    output_units: dict = field(default_factory=dict)
    response_state: int = 0
    nonlinearity_degree: int = 3
    label: str = "first-order system"

    def __post_init__(self) -> None:
        if not isinstance(self.n_states, int | np.integer) or self.n_states < 1:
            raise ParameterError("n_states", self.n_states, "an integer >= 1")
        if self.work_size == 0:
            object.__setattr__(self, "work_size", int(self.n_states))
        if self.work_size < self.n_states:
            raise ParameterError("work_size", self.work_size, f">= n_states = {self.n_states}")
        if not 0 <= self.response_state < self.n_states:
            raise ParameterError("response_state", self.response_state, f"0 .. {self.n_states - 1}")

    @property
    def displacement_scale(self) -> float:
        return 1.0

    def __repr__(self) -> str:
        return f"<FirstOrderSystem {self.label}: {self.n_states} states>"


def _quarter_car_rhs_py(t, x, road, itab, ftab, out):
    _rhs_road(road[0], road[1], x, out, ftab, _WK_ZERO, False)
    return True


_RHS_CACHE: list = []


def quarter_car_rhs():
    """The quarter car's right-hand side in the first-order signature (compiled once)."""
    if not _RHS_CACHE:
        _RHS_CACHE.append(njit(RHS_SIGNATURE, cache=True)(_quarter_car_rhs_py))
    return _RHS_CACHE[0]


def quarter_car_system(car: QuarterCar) -> FirstOrderSystem:
    """The first-order system of ``car`` (smooth suspensions only, see below).

    ``device`` and ``device-afw`` carry the friction of the real device,
    F_fh tanh(u / v_eps) with v_eps of order 1e-3 m/s, a near-switch that needs hundreds
    of harmonics; they are refused with a pointer to the time simulation.
    """
    if not isinstance(car, QuarterCar):
        raise ParameterError("system", car, "a QuarterCar (inerterlab.quarter_car)")
    if car.suspension not in SMOOTH_SUSPENSIONS:
        raise ParameterError(
            "suspension",
            car.suspension,
            "traditional, cfw or afw for the harmonic balance (the real device's friction "
            "tanh(u/v_eps) switches within millimetres per second, beyond a truncated "
            "Fourier series; use `inerterlab simulate` with a sine road for it)",
        )
    n = car.n_states
    p = np.asarray(car.kernel_parameters, dtype=float)
    ftab = np.array(p, dtype=float)  # a writable copy
    kt, ct = float(p[P_KT]), float(p[P_CT])

    def output_samples(xs, fs, road):
        return {
            "body_displacement": xs[:, 2],
            "body_acceleration": fs[:, 3],
            "suspension_deflection": xs[:, 2] - xs[:, 0],
            "tyre_force": kt * (xs[:, 0] - road[:, 0]) + ct * (xs[:, 1] - road[:, 1]),
        }

    return FirstOrderSystem(
        n_states=n,
        rhs=quarter_car_rhs(),
        int_table=np.zeros(1, dtype=np.int64),
        float_table=ftab,
        work_size=n + N_METRIC_STATES,
        state_scales=np.asarray(car.state_scales[:n], dtype=float),
        rest_state=car.initial_state(),
        output_samples=output_samples,
        output_units=dict(QUARTER_CAR_OUTPUTS),
        response_state=2,
        nonlinearity_degree=3,
        label=f"quarter car, {car.suspension}",
    )


def from_core_system(system) -> FirstOrderSystem:
    """A system of the model core (``inerterlab.systems``: ``n_states``, ``rhs``,
    ``tables``, compiled ``outputs`` and ``output_names``) as a first-order system.

    A quarter car (nodes ``body``, ``wheel`` and the tyre elements ``tyre_k``,
    ``tyre_c``) reports the four quarter-car outputs; any other system reports every
    node displacement, velocity, acceleration and element force by its name.
    """
    names = tuple(system.output_names)
    index = {name: i for i, name in enumerate(names)}
    itab, ftab = system.tables
    quarter = all(k in index for k in ("body.x", "wheel.x", "body.a", "tyre_k.force"))

    if quarter:
        tyre = [index["tyre_k.force"]] + (
            [index["tyre_c.force"]] if "tyre_c.force" in index else []
        )

        def combine(O):
            return {
                "body_displacement": O[:, index["body.x"]],
                "body_acceleration": O[:, index["body.a"]],
                "suspension_deflection": O[:, index["body.x"]] - O[:, index["wheel.x"]],
                "tyre_force": np.sum(O[:, tyre], axis=1),
            }

        units = dict(QUARTER_CAR_OUTPUTS)
        response = system.state_names.index("body.x") if "body.x" in system.state_names else 0
    else:

        def combine(O):
            return {n: O[:, i] for i, n in enumerate(names) if np.all(np.isfinite(O[:, i]))}

        suffix = {"x": "m", "v": "m/s", "a": "m/s^2", "force": "N"}
        units = {n: suffix.get(n.rsplit(".", 1)[-1], "") for n in names}
        response = 0
    return FirstOrderSystem(
        n_states=int(system.n_states),
        rhs=system.rhs,
        int_table=np.array(itab, dtype=np.int64),
        float_table=np.array(ftab, dtype=float),
        state_scales=np.asarray(system.state_scales, dtype=float),
        rest_state=np.asarray(system.initial_state(), dtype=float),
        compiled_outputs=system.outputs,
        n_outputs=len(names),
        combine_outputs=combine,
        output_units=units,
        response_state=response,
        label=str(getattr(system, "description", "model-core system")),
    )
