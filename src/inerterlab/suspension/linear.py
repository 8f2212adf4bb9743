"""State-space form of the linear quarter cars (traditional, cfw) for H2 norms.

Input: the road velocity w = X1' [m/s]. States: tyre deflection z1 = X2 - X1,
suspension deflection z2 = X3 - X2, V2, V3 (relative coordinates, so the system is
asymptotically stable and a Lyapunov equation has a unique solution). Equations (4.1)
and (4.4) with the inertance b = r^2 I between the masses:

    [M_t + b, -b; -b, M + b] [a2; a3] = [-K_t z1 - C_t (V2 - w) + K z2 + C (V3 - V2);
                                         -K z2 - C (V3 - V2)]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .model import QuarterCar, model_of

__all__ = ["LinearQuarterCar", "linear_quarter_car"]


@dataclass(frozen=True)
class LinearQuarterCar:
    """x' = A x + B w; each output y = C[name] x + D[name] w.

    Outputs: ``body_acc`` [m/s^2], ``tyre_deflection`` [m], ``suspension_deflection``
    [m], ``tyre_grip`` (K_t (X2 - X1)/((M + M_t) g), (4.20)) [-].
    """

    A: np.ndarray
    B: np.ndarray
    C: dict
    D: dict


def linear_quarter_car(model: QuarterCar) -> LinearQuarterCar:
    """The linear system of a ``traditional`` or ``cfw`` quarter car (the system
    :func:`inerterlab.quarter_car` builds, or its description)."""
    model = model_of(model)
    if not model.is_linear:
        raise ParameterError(
            "suspension",
            model.suspension + (" with tyre lift-off" if model.tyre_lift_off else ""),
            "a linear suspension: 'traditional' or 'cfw' without tyre lift-off",
        )
    q = model.parameters
    b = model.inertance or 0.0
    m = np.array([[q.unsprung_mass + b, -b], [-b, q.sprung_mass + b]])
    # forces on [unsprung, sprung] as rows of (state coefficients | input coefficient)
    kt, ct, k, c = q.tyre_stiffness, q.tyre_damping, q.stiffness, q.damping
    fx = np.array([[-kt, k, -ct - c, c], [0.0, -k, c, -c]])
    fw = np.array([ct, 0.0])
    minv = np.linalg.inv(m)
    ax, aw = minv @ fx, minv @ fw
    A = np.zeros((4, 4))
    A[0, 2] = 1.0  # z1' = V2 - w
    A[1, 2], A[1, 3] = -1.0, 1.0  # z2' = V3 - V2
    A[2:, :] = ax
    B = np.array([-1.0, 0.0, aw[0], aw[1]])
    grip = kt / q.static_tyre_load
    C = {
        "body_acc": ax[1].copy(),
        "tyre_deflection": np.array([1.0, 0, 0, 0]),
        "suspension_deflection": np.array([0, 1.0, 0, 0]),
        "tyre_grip": np.array([grip, 0, 0, 0]),
    }
    D = {
        "body_acc": float(aw[1]),
        "tyre_deflection": 0.0,
        "suspension_deflection": 0.0,
        "tyre_grip": 0.0,
    }
    return LinearQuarterCar(A=A, B=B, C=C, D=D)
