"""Systems of bodies and two-terminal networks, compiled into one right-hand side.

Build one with :func:`rig` (prescribed displacement across a network or device),
:func:`base_excited` (a body on a network over a moving base, thesis ch. 7) or
:func:`quarter_car` (sprung and unsprung masses, tyre spring and damper to the road; a
named suspension of the thesis or any network), or :func:`half_car` / :func:`full_car`
(a body with bounce, pitch and roll on any network at each corner, tyres that lift off;
:mod:`inerterlab.systems.vehicle`).
:func:`equilibrium` solves the static balance under gravity (a nonlinear spring carrying
the weight) and gives the system about that rest.
Every element of :mod:`inerterlab.elements` may sit anywhere in a network.

Node formulation (docs/model.md §11): every network node has a displacement. Nodes with
a mass or an inertance attached (ideal inerter, adaptive flywheel) carry displacement
and velocity states; their accelerations solve M(x) a = f, with the inertances stamped
into M like masses between two nodes. Massless nodes with no inertance are algebraic:
with a damper attached the velocity follows from the node's force balance (a monotone
equation, solved to round-off), with springs only the displacement follows from the
spring balance. No small artificial masses are added. Ill-posed networks raise
:class:`~inerterlab.networks.NetworkError` naming the sub-network.

Interface (stable; the harmonic balance and vehicle models build on it). A
:class:`System` is frozen and has:

``n_states``, ``state_names``
    State vector layout: ``<node>.x``, ``<node>.v`` per dynamic node, ``<node>.x`` per
    velocity node, then element states (``<element>.slider_radius``, ...).
``rhs(t, x, road, itab, ftab, out) -> bool``
    numba dispatcher: ``out[:] = dx/dt``; ``road`` = (displacement [m], velocity [m/s],
    acceleration [m/s^2]) of the road node (the driven terminal of a rig, the base of a
    base-excited body); False if a force balance failed. Pass ``*system.tables``.
``outputs(t, x, road, itab, ftab, out) -> bool``
    numba dispatcher: ``out`` (length ``len(output_names)``) = node displacements,
    velocities, accelerations (NaN at massless nodes) and element forces.
``tables``
    ``(itab, ftab)``: int64 and float64 arrays (read only), layout in
    :mod:`inerterlab.systems._kernel`.
``initial_state()``, ``linear_state_space()``
    Rest state; (A, B, C, D) with input (road displacement, velocity, acceleration) and
    the outputs as y, for all-linear networks (NetworkError otherwise).
``simulate(excitation, horizon, rtol=..., method="auto")``
    Adaptive Dormand-Prince 5(4) or exact matrix-exponential steps -> :class:`CoreResult`.

Example
-------
>>> from inerterlab.systems import quarter_car
>>> from inerterlab.excitation import bump
>>> car = quarter_car("k | (c - b)", {"k": 90e3, "c": 5e3, "b": 200})
>>> res = car.simulate(bump(edge="ramp", edge_width=0.002), horizon=1.0)
>>> res.method, round(res.metrics["peak_deflection"], 4) > 0
('exact', True)
"""

from __future__ import annotations

from .core import (
    CoreResult,
    DriveRuns,
    RoadVelocityJumpWarning,
    System,
    base_excited,
    device_network,
    rig,
)
from .equilibrium import Equilibrium, equilibrium
from .quarter_car import QUARTER_CAR_PRESETS, SUSPENSIONS, quarter_car
from .vehicle import full_car, half_car

__all__ = [
    "System",
    "CoreResult",
    "DriveRuns",
    "rig",
    "base_excited",
    "device_network",
    "quarter_car",
    "half_car",
    "full_car",
    "QUARTER_CAR_PRESETS",
    "SUSPENSIONS",
    "RoadVelocityJumpWarning",
    "Equilibrium",
    "equilibrium",
]
