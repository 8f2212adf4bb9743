"""The linear vehicle: the core half or full car linearised about its static equilibrium.

The vehicle's system of the model core (:func:`inerterlab.systems.vehicle.vehicle`,
tyres always in contact) rests where Newton's method on the whole nonlinear balance with
gravity puts it (:func:`inerterlab.systems.equilibrium.equilibrium`); its state space
about that rest is the one every linear analysis of a vehicle uses (the frequency
response, the spectral method, Lyapunov H2 norms, modes, the design helpers and the
statistical linearisation). A car of springs, dampers, inerters and linear networks is
linear: its state space comes from the right-hand side at unit vectors, exact. A car
whose gas springs or bump stops carry load is linearised about the equilibrium
(central differences, :func:`inerterlab.systems.equilibrium.linearise`), each such
element at its stiffness at rest, and says so (``linearised``). A corner with an
element whose response depends on the amplitude (adaptive inerter, friction, backlash,
a one-way clutch) has no linear model and is refused, naming it.

State space, in the vehicle's road layout: x' = A x + Br r + Bd r', y = Cy[name] x +
Dr[name] r + Dd[name] r' with r the road heights under the wheels (front, rear; or
front_left, front_right, rear_left, rear_right). Outputs: ``bounce_acc`` [m/s^2],
``pitch_acc``, ``roll_acc`` [rad/s^2], ``seat_acc`` [m/s^2], ``<station>_deflection``
[m] (strut extension), ``<station>_tyre_load`` [N] (increase of the contact force), and
the body's displacements ``heave`` [m], ``pitch`` and ``roll`` [rad] (in
:attr:`LinearVehicle.displacements`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..h2 import resolvent_solve
from ..systems._kernel import DYN as _DYN  # a node with mass

__all__ = ["LinearVehicle", "linear_vehicle", "from_state_space", "OUTPUT_UNITS"]

OUTPUT_UNITS = {
    "bounce_acc": "m/s^2",
    "pitch_acc": "rad/s^2",
    "roll_acc": "rad/s^2",
    "seat_acc": "m/s^2",
    "deflection": "m",
    "tyre_load": "N",
    "heave": "m",
    "pitch": "rad",
    "roll": "rad",
}


@dataclass(frozen=True)
class Output:
    """An output's unit (the rows live in the state space)."""

    unit: str


@dataclass(frozen=True, eq=False)
class LinearVehicle:
    """A vehicle's state space about its static equilibrium (see the module).

    Attributes
    ----------
    parameters : HalfCar or FullCar
    system : System
        The core vehicle about its rest (tyres always in contact).
    linearised : bool
        True where nonlinear springs carry load (their stiffness at rest is used).
    """

    parameters: object
    system: object
    linearised: bool
    _ss: tuple
    outputs: dict
    displacements: dict

    @property
    def kind(self) -> str:
        return "full" if len(self.system.info["body"]) == 3 else "half"

    @property
    def corners(self) -> tuple:
        return tuple(self.system.info["stations"])

    inputs = corners

    @property
    def equilibrium(self):
        return self.system.info["equilibrium"]

    def state_space(self, displacements: bool = False):
        """(A, Br, Bd, Cy, Dr, Dd), ``Cy`` etc. dicts keyed by output name (module):
        :attr:`outputs`, and the body's :attr:`displacements` too if asked.

        States that nothing reads (no state's rate and no output depends on them: the
        position of an internal node between a damper and an inerter, whose free drift
        is a zero eigenvalue) are left out, so the system is Hurwitz where the car is
        stable and its norms and static gains exist."""
        A, Br, Bd, Cy, Dr, Dd = self._ss
        read = np.ones(A.shape[0], bool)
        while True:
            used = np.any(A[np.ix_(read, read)] != 0.0, axis=0)
            used |= np.any([c[read] != 0.0 for c in Cy.values()], axis=0)
            if used.all():
                break
            read[np.flatnonzero(read)[~used]] = False
        keep = list(self.outputs) + (list(self.displacements) if displacements else [])
        A, Br, Bd = A[np.ix_(read, read)], Br[read], Bd[read]
        Cy = {k: c[read] for k, c in Cy.items()}
        return (A, Br, Bd, *({k: d[k] for k in keep} for d in (Cy, Dr, Dd)))

    def frequency_response(self, freq_hz, outputs=None) -> dict:
        """Transfer functions from the road heights to each output at ``freq_hz`` [Hz]:
        name -> complex array (n_freq, n_inputs)."""
        A, Br, Bd, Cy, Dr, Dd = self._ss
        f = np.atleast_1d(np.asarray(freq_hz, dtype=float))
        names = list(outputs or self.outputs)
        s = 2j * math.pi * f
        X = resolvent_solve(A, s, Br[None] + s[:, None, None] * Bd[None])
        out = {}
        for k in names:
            out[k] = np.einsum("j,fjm->fm", Cy[k], X) + Dr[k][None] + s[:, None] * Dd[k][None]
        return out

    @property
    def plain(self) -> bool:
        """True where every state is a position or velocity of a body with mass (no
        internal nodes): the car has an undamped mass-spring model."""
        from ..systems.equilibrium import _structure

        sys = self.system
        masses = _structure(sys)[4]
        dyn = [n for n, t in enumerate(sys.node_types) if t == _DYN]
        return sys.n_states == 2 * len(dyn) and all(masses[n] > 0 for n in dyn)

    def mass_stiffness(self):
        """(M, K, names): the mass and (tangent) stiffness matrices over the bodies'
        coordinates ``names`` of a :attr:`plain` car. M^-1 column by column from the
        core's impulse flow (a unit impulse on one coordinate), K = -M A_vx from the
        state matrix."""
        from ..systems import _kernel

        sys = self.system
        if not self.plain:
            from ..systems.equilibrium import _structure

            masses = _structure(sys)[4]
            heavy = {sys.node_names[n] for n, t in enumerate(sys.node_types)
                     if t == _DYN and masses[n] > 0}  # fmt: skip
            inner = next(s.rpartition(".")[0] for s in sys.state_names
                         if s.rpartition(".")[0] not in heavy)  # fmt: skip
            raise ParameterError(
                "struts", f"the internal node {inner}",
                "a car without internal nodes (no undamped model)",
            )  # fmt: skip
        itab, ftab = sys.tables
        no = int(itab[_kernel.I_NODE])
        dyn = [n for n, t in enumerate(sys.node_types) if t == _DYN]
        names = [sys.node_names[n] for n in dyn]
        order = [int(itab[no + _kernel.NODE_W * n + 3]) for n in dyn]  # impulse slots
        vs = [sys.state_names.index(f"{nm}.v") for nm in names]
        xs = [sys.state_names.index(f"{nm}.x") for nm in names]
        nd = len(dyn)
        W = np.empty(_kernel.work_size(itab))
        dx = np.empty(sys.n_states)
        road = np.zeros(_kernel.road_layout_of(itab)[1])
        Minv = np.empty((nd, nd))
        for j, d in enumerate(order):
            imp = np.zeros(nd)
            imp[d] = 1.0
            _kernel.evaluate(0.0, np.zeros(sys.n_states), road, itab, ftab, W, dx, imp)
            Minv[:, j] = dx[vs]
        M = np.linalg.inv(Minv)
        M = 0.5 * (M + M.T)
        K = -M @ self._ss[0][np.ix_(vs, xs)]
        return M, 0.5 * (K + K.T), names

    def natural_frequencies(self, rigid_tyres: bool = True) -> np.ndarray:
        """Undamped natural frequencies [Hz], ascending (a :attr:`plain` car):
        ``rigid_tyres`` holds the wheels (the body, and seat, on the struts' springs and
        inerters alone); otherwise the whole undamped car."""
        from scipy.linalg import eigh

        M, K, names = self.mass_stiffness()
        keep = [i for i, n in enumerate(names) if not (rigid_tyres and n.startswith("wheel_"))]
        w2 = eigh(K[np.ix_(keep, keep)], M[np.ix_(keep, keep)], eigvals_only=True)
        return np.sqrt(np.maximum(w2, 0.0)) / (2 * math.pi)

    def static_tyre_loads(self) -> dict:
        """Static contact force of each wheel station [N] from the equilibrium."""
        return dict(self.system.info["static_tyre_loads"])


def linear_vehicle(parameters, networks: dict | None = None) -> LinearVehicle:
    """The :class:`LinearVehicle` of a :class:`~inerterlab.vehicles.parameters.HalfCar`
    or :class:`~inerterlab.vehicles.parameters.FullCar` (``networks`` as in
    :func:`inerterlab.systems.vehicle.vehicle`).

    >>> from inerterlab.vehicles import example_vehicle_path, load_vehicle
    >>> car = linear_vehicle(load_vehicle(example_vehicle_path()))
    >>> car.inputs, car.linearised
    (('front_left', 'front_right', 'rear_left', 'rear_right'), False)
    """
    from ..systems.equilibrium import linearise
    from ..systems.vehicle import vehicle

    sys = vehicle(parameters, networks=networks, lift_off=False)
    if sys.linear:
        A, B, C, D = sys.linear_state_space()
        lin = False
    else:
        bad = [n for n, e in zip(sys.element_names, sys.elements, strict=True)
               if not e.is_linear and not hasattr(e, "tangent")]  # fmt: skip
        if bad:
            el = sys.elements[sys.element_names.index(bad[0])]
            raise ParameterError(
                bad[0], el.description,
                "an element with a linear model about rest for the linear analyses (its "
                "response depends on the amplitude: the time simulation, vehicle simulate, "
                "the frequency response by harmonic balance and the statistical "
                "linearisation take it)",
            )  # fmt: skip
        A, B, C, D = linearise(sys)
        lin = True
    return from_state_space(sys, (A, B, C, D), lin)


def from_state_space(sys, ss, linearised: bool) -> LinearVehicle:
    """The :class:`LinearVehicle` of the core vehicle ``sys`` (tyres always in contact)
    with the state space ``ss`` = (A, B, C, D) in the core's layout
    (:meth:`~inerterlab.systems.System.linear_state_space`): the rows of the vehicle's
    outputs picked from the core's. ``linearised``: whether ``ss`` is a linearisation
    (said in every result)."""
    A, B, C, D = ss
    m = sys.info["roads"]
    acc = B[:, 2 : 3 * m : 3]
    if np.any(np.abs(acc) > 1e-12 * (1.0 + np.abs(B).max())):
        raise ParameterError("tyre", "inertance at the road", "no inertance touching the road")
    Br, Bd = B[:, 0 : 3 * m : 3], B[:, 1 : 3 * m : 3]
    names = list(sys.output_names)

    def row(name, sign=1.0):
        j = names.index(name)
        return sign * C[j], sign * D[j, 0 : 3 * m : 3], sign * D[j, 1 : 3 * m : 3]

    rows = {"bounce_acc": row("bounce.a"), "pitch_acc": row("pitch.a")}
    if "roll.a" in names:
        rows["roll_acc"] = row("roll.a")
    if "seat.a" in names:
        rows["seat_acc"] = row("seat.a")
    units = {k: Output(OUTPUT_UNITS[k]) for k in rows}
    for st in sys.info["stations"]:
        cb, rb, db = row(f"body_{st}.x")
        cw, rw, dw = row(f"wheel_{st}.x")
        rows[f"{st}_deflection"] = (cb - cw, rb - rw, db - dw)
        units[f"{st}_deflection"] = Output(OUTPUT_UNITS["deflection"])
        rows[f"{st}_tyre_load"] = row(f"{st}_tyre.force", -1.0)
        units[f"{st}_tyre_load"] = Output(OUTPUT_UNITS["tyre_load"])
    disp = {"heave": "bounce.x", "pitch": "pitch.x", "roll": "roll.x"}
    disp = {k: v for k, v in disp.items() if v in names}
    for k, v in disp.items():
        rows[k] = row(v)
    Cy = {k: r[0] for k, r in rows.items()}
    Dr = {k: r[1] for k, r in rows.items()}
    Dd = {k: r[2] for k, r in rows.items()}
    return LinearVehicle(
        parameters=sys.info["parameters"], system=sys, linearised=linearised,
        _ss=(A, Br, Bd, Cy, Dr, Dd), outputs=units,
        displacements={k: Output(OUTPUT_UNITS[k]) for k in disp},
    )  # fmt: skip
