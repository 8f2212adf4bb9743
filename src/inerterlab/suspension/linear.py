"""A quarter car's linear state space driven by the road velocity, from the model core.

Input: the road velocity w = X1' [m/s] (unit white noise for H2 norms). The matrices
are the core system's own (:meth:`inerterlab.systems.System.linear_state_space`, or a
linearisation of it), whose inputs are the road's height X1, velocity and
acceleration. With X1 = w / s the height's column moves into the states
(:func:`inerterlab.h2.white_velocity_input`): the states are the core's
(``wheel.x``, ``wheel.v``, ``body.x``, ``body.v`` and the internal nodes of the
suspension's network, in the order of its ``state_names``) with every position taken
relative to the road, so the system is asymptotically stable and a Lyapunov equation
has a unique solution. One set of equations describes the car, the core's; nothing
here writes them again.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ConvergenceError, ParameterError
from .model import QuarterCar, model_of

__all__ = ["LinearQuarterCar", "linear_quarter_car", "road_velocity_form"]

#: the outputs of a :class:`LinearQuarterCar`
OUTPUTS = ("body_acc", "tyre_deflection", "suspension_deflection", "tyre_grip")


@dataclass(frozen=True)
class LinearQuarterCar:
    """x' = A x + B w; each output y = C[name] x + D[name] w.

    Outputs: ``body_acc`` [m/s^2], ``tyre_deflection`` X2 - X1 [m],
    ``suspension_deflection`` X3 - X2 [m], ``tyre_grip`` (K_t (X2 - X1)/((M + M_t) g),
    (4.20)) [-]. ``state_names``: the core system's states (positions relative to the
    road). ``info``: how it was made (for a statistical linearisation, the
    equivalents; :func:`inerterlab.identify.linearised_car`).
    """

    A: np.ndarray
    B: np.ndarray
    C: dict
    D: dict
    state_names: tuple = ()
    info: dict = field(default_factory=dict)


def road_velocity_form(system, ss, info: dict | None = None) -> LinearQuarterCar:
    """The :class:`LinearQuarterCar` of the core quarter car ``system`` (a named
    suspension's, with its description in ``info["model"]``) from its state space
    ``ss`` = (A, B, C, D) in the core's layout (road height, velocity, acceleration as
    inputs). ParameterError where an inertance touches the road (the road's
    acceleration drives the car: no finite response to white velocity)."""
    from ..h2 import white_velocity_input

    model = model_of(system)
    A, B, C, D = (np.asarray(m, dtype=float) for m in ss)
    scale = 1.0 + float(np.max(np.abs(B)))
    if np.max(np.abs(B[:, 2])) > 1e-12 * scale:
        raise ParameterError("tyre", "inertance at the road", "no inertance touching the road")
    Bx, Bv = B[:, 0], B[:, 1]
    Bw = white_velocity_input(A, Bx, Bv)
    names = list(system.output_names)

    def row(name):
        j = names.index(name)
        return C[j], D[j, 0], D[j, 1]

    (ba, _, bad), (cw, rw, dw), (cr, rr, dr), (cb, rb, db) = (
        row(n) for n in ("body.a", "wheel.x", "road.x", "body.x")
    )
    grip = model.parameters.tyre_stiffness / model.parameters.static_tyre_load
    rows = {
        "body_acc": (ba, bad),
        "tyre_deflection": (cw - cr, dw - dr),
        "suspension_deflection": (cb - cw, db - dw),
    }
    rows["tyre_grip"] = (grip * rows["tyre_deflection"][0], grip * rows["tyre_deflection"][1])
    static = {
        "body_acc": row("body.a")[1],  # D's road-height column: Dz
        "tyre_deflection": rw - rr,
        "suspension_deflection": rb - rw,
    }
    xr = np.linalg.solve(A, Bx)
    for k, dz in static.items():  # Dz - C A^-1 Bx: zero for a car the road carries along
        c = rows[k][0]
        if abs(dz - float(c @ xr)) > 1e-9 * (1.0 + abs(dz) + float(np.abs(c).max())):
            raise ConvergenceError(
                f"the quarter car's {k} does not return to rest after a step of the road "
                f"(static part {dz - float(c @ xr):.3g}): it has no finite variance under "
                "white road velocity"
            )
    return LinearQuarterCar(
        A=A, B=Bw, C={k: np.array(v[0]) for k, v in rows.items()},
        D={k: float(v[1]) for k, v in rows.items()},
        state_names=tuple(system.state_names), info=dict(info or {}),
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
