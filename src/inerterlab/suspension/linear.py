"""A quarter car's linear state space driven by the road velocity, from the model core.

Input: the road velocity w = X1' [m/s] (unit white noise for H2 norms). The matrices
are the core system's own (:meth:`inerterlab.systems.System.linear_state_space`, or a
linearisation of it), whose inputs are the road's height X1, velocity and
acceleration. With X1 = w / s the height moves into the states: the states are the
core's (``wheel.x``, ``wheel.v``, ``body.x``, ``body.v`` and the internal nodes of the
suspension's network) with the positions first, the wheel's relative to the road and
every other relative to the wheel's (so the deflections are states, not differences of
large motions), then the velocities: the system is asymptotically stable and a
Lyapunov equation has a unique solution. One set of equations describes the car, the
core's; nothing here writes them again.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from .model import QuarterCar, model_of

__all__ = ["LinearQuarterCar", "linear_quarter_car", "road_relative", "road_velocity_form"]

@dataclass(frozen=True)
class LinearQuarterCar:
    """x' = A x + B w; each output y = C[name] x + D[name] w.

    Outputs: ``body_acc`` [m/s^2], ``tyre_deflection`` X2 - X1 [m],
    ``suspension_deflection`` X3 - X2 [m], ``tyre_grip`` (K_t (X2 - X1)/((M + M_t) g),
    (4.20)) [-]. ``state_names``: the states (the wheel's position relative to the
    road, the others relative to the wheel, the velocities absolute). ``info``: how it
    was made (for a statistical linearisation, the equivalents;
    :func:`inerterlab.identify.linearised_car`).
    """

    A: np.ndarray
    B: np.ndarray
    C: dict
    D: dict
    state_names: tuple = ()
    info: dict = field(default_factory=dict)


def _order(st) -> list:
    """The core's states in the order of :func:`road_relative`: the positions, then the
    velocities and the other states (each group in the core's order)."""
    return [i for i, n in enumerate(st) if n.endswith(".x")] + [
        i for i, n in enumerate(st) if not n.endswith(".x")
    ]


def road_relative(system, ss):
    """(A, B, Ti): the state space ``ss`` = (A, B, C, D) of the core quarter car
    ``system`` (road height, velocity, acceleration as inputs) driven by the road
    velocity alone, in the states x' of the module docstring (x = Ti x'): the positions
    first, the wheel's relative to the road and every other relative to the wheel's,
    then the velocities (absolute) and any other state. An output row c of the core's
    states reads c @ Ti. The road's height enters only through the positions relative
    to it: a car that the road carries along (shifting every position by the road's
    leaves every force as it is: A e + B_z = 0, e the positions' indicator), checked to
    1e-9. ParameterError where an inertance touches the road (its acceleration drives
    the car) or a force depends on an absolute position."""
    A, B = (np.asarray(m, dtype=float) for m in ss[:2])
    scale = 1.0 + float(np.max(np.abs(B)))
    if np.max(np.abs(B[:, 2])) > 1e-12 * scale:
        raise ParameterError("tyre", "inertance at the road", "no inertance touching the road")
    st = list(system.state_names)
    pos = np.array([n.endswith(".x") for n in st], dtype=float)
    if np.max(np.abs(A @ pos + B[:, 0])) > 1e-9 * scale * (1.0 + float(np.max(np.abs(A)))):
        raise ParameterError(
            "car", "a force on an absolute position",
            "a car its road carries along (a stationary response to white road velocity)",
        )  # fmt: skip
    order = _order(st)
    w = st.index("wheel.x")
    Ti = np.zeros((len(st), len(st)))  # x = Ti x'
    for j, i in enumerate(order):
        Ti[i, j] = 1.0
        if st[i].endswith(".x") and i != w:
            Ti[i, order.index(w)] = 1.0
    T = np.linalg.inv(Ti)  # exact: its entries are 0 and +-1
    # x - e z (positions relative to the road) moves as A (x - e z) + (B_v - e) u
    return T @ A @ Ti, T @ (B[:, 1] - pos), Ti


def road_velocity_form(system, ss, info: dict | None = None) -> LinearQuarterCar:
    """The :class:`LinearQuarterCar` of the core quarter car ``system`` (a named
    suspension's, with its description in ``info["model"]``) from its state space
    ``ss`` = (A, B, C, D) in the core's layout (:func:`road_relative`)."""
    model = model_of(system)
    A, Bw, Ti = road_relative(system, ss)
    C, D = (np.asarray(m, dtype=float) for m in ss[2:])
    names = list(system.output_names)

    def row(name):
        j = names.index(name)
        return C[j], D[j, 1]

    (ba, bad), (cw, dw), (cr, dr), (cb, db) = (
        row(n) for n in ("body.a", "wheel.x", "road.x", "body.x")
    )
    grip = model.parameters.tyre_stiffness / model.parameters.static_tyre_load
    rows = {
        "body_acc": (ba, bad),
        "tyre_deflection": (cw - cr, dw - dr),
        "suspension_deflection": (cb - cw, db - dw),
    }
    rows["tyre_grip"] = (grip * rows["tyre_deflection"][0], grip * rows["tyre_deflection"][1])
    st = list(system.state_names)
    names_new = tuple(st[i] if (not st[i].endswith(".x") or st[i] == "wheel.x")
                      else f"{st[i]} - wheel.x" for i in _order(st))  # fmt: skip
    return LinearQuarterCar(
        A=A, B=Bw, C={k: v[0] @ Ti for k, v in rows.items()},
        D={k: float(v[1]) for k, v in rows.items()},
        state_names=names_new, info=dict(info or {}),
    )  # fmt: skip


def linear_quarter_car(model: QuarterCar) -> LinearQuarterCar:
    """The linear system of a ``traditional`` or ``cfw`` quarter car (the system
    :func:`inerterlab.quarter_car` builds, or its description), driven by the road
    velocity: the core system's exact state space (:func:`road_velocity_form`)."""
    from ..systems.quarter_car import system_of

    model = model_of(model)
    if not model.is_linear:
        raise ParameterError(
            "suspension",
            model.suspension + (" with tyre lift-off" if model.tyre_lift_off else ""),
            "a linear suspension: 'traditional' or 'cfw' without tyre lift-off",
        )
    system = system_of(model)
    return road_velocity_form(system, system.linear_state_space())
