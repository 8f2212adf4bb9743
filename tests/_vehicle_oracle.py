"""An independent oracle for the tests: linear half-car and full-car models whose mass,
damping and stiffness matrices are assembled by hand from connections (the package's
vehicle is the model core's system, :mod:`inerterlab.systems.vehicle`, and its
linearisation, :mod:`inerterlab.vehicles.linear`; this module is not part of it).

Coordinates q are displacements from static equilibrium: the body's bounce, pitch
(and roll), each unsprung mass, then the seat. Road inputs r are the road heights
under the wheels, ordered front, rear (half car) or front_left, front_right,
rear_left, rear_right (full car).

Every force element is a *connection* with extension delta = u . q - v . r and a
force law (:class:`~inerterlab.vehicles.parameters.Strut`,
:class:`~inerterlab.vehicles.parameters.NetworkStrut`,
:class:`~inerterlab.vehicles.parameters.Tyre`, or a bare rate for anti-roll bars).
Its generalised force on q is -u Z(s) delta, Z the law's dynamic stiffness, so

    [sum_j u_j u_j^T Z_j(s) + s^2 M] q = [sum_j u_j v_j^T Z_j(s)] r.

The frequency response uses this form with each law's :func:`dynamic_stiffness` (a
network strut's evaluated on its tree); the state space uses each law's (b, c, k) and,
for a network strut, the :func:`realisation` of the rest of its Z(s).

Outputs y = P q + V q' + G q'' + R r + S r' (G for accelerations, S for the tyre
damper's share of a tyre load). Units: m/s^2 for accelerations, rad/s^2 for pitch
and roll accelerations, m for suspension deflections (extension positive), N for
dynamic tyre loads (increase of the contact force, positive pressing the tyre down).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from inerterlab.errors import NetworkError, ParameterError
from inerterlab.vehicles.linear import OUTPUT_UNITS
from inerterlab.vehicles.parameters import Corner, FullCar, HalfCar, NetworkStrut

__all__ = [
    "Connection", "Output", "LinearVehicle", "build", "OUTPUT_UNITS",
    "dynamic_stiffness", "internal_states", "realisation", "nonlinear_device",
]  # fmt: skip


# -- force laws --------------------------------------------------------------------------
def dynamic_stiffness(law, s):
    """Z(s) [N/m] of ``law`` at complex frequency ``s`` [rad/s]: s Y(s) on a network
    strut's tree (no polynomials), else k + c s + b s^2 from its (b, c, k)."""
    if isinstance(law, NetworkStrut):
        from inerterlab.networks import admittance_at

        s = np.asarray(s, dtype=complex)
        return s * admittance_at(law.network, law.parameters, s)
    b, c, k = law.mck()
    return k + c * s + b * s * s


def internal_states(law) -> int:
    """Extra states ``law`` needs in a state space (0: Z(s) a polynomial)."""
    return int(law._split()[4].size - 1) if isinstance(law, NetworkStrut) else 0


def realisation(law):
    """(A, B, C) of a network strut's rest R(s) = N(s)/D(s) = C (sI - A)^-1 B in
    controllable canonical form: z' = A z + B x, force C z."""
    _, _, _, r, d = law._split()
    n = d.size - 1
    A = np.zeros((n, n), dtype=d.dtype)  # complex for a complex step
    if n:
        A[:-1, 1:] = np.eye(n - 1)
        A[-1, :] = -d[1:][::-1]
    B = np.zeros(n)
    if n:
        B[-1] = 1.0
    C = r[::-1].copy() if n else np.zeros(0)
    return A, B, C


def nonlinear_device(law):
    """The strut's device if it has parts beyond the springs, linear dampers and
    inerters straight across it and its adaptive inerter (internal nodes, friction,
    nonlinear springs: what these matrices cannot take), else None."""
    dev = getattr(law, "device", None)
    if dev is None:
        return None
    for _, el, t, b in dev.edges:
        if not ({t, b} == {0, 1} and (el.is_linear or el is dev.adaptive)):
            return dev
    return None



@dataclass(frozen=True)
class _Rate:
    """A bare spring rate (anti-roll bar) with the force-law interface."""

    stiffness: float

    def mck(self):
        return (0.0, 0.0, float(self.stiffness))

    def static_stiffness(self) -> float:
        return float(self.stiffness)


@dataclass(frozen=True)
class Connection:
    """Force element with extension u . q - v . r and force law ``law``."""

    name: str
    u: np.ndarray
    v: np.ndarray
    law: object


@dataclass(frozen=True)
class Output:
    """y = P q + V q' + G q'' + R r + S r' with its unit."""

    P: np.ndarray
    V: np.ndarray
    G: np.ndarray
    R: np.ndarray
    S: np.ndarray
    unit: str


@dataclass(frozen=True)
class LinearVehicle:
    """A linear vehicle: masses, connections and outputs (build with :func:`build`).

    Attributes
    ----------
    parameters : HalfCar or FullCar
    dofs : tuple of str
        Names of the coordinates q.
    inputs : tuple of str
        Names of the road inputs (wheel positions).
    corners : tuple of str
        Names of the wheel stations (same order as ``inputs``).
    axle_x : dict
        x position of each input's wheel [m] (a for front, -b for rear).
    mass : ndarray
        Mass matrix of the bodies alone (inerters come from the connections).
    connections : tuple of Connection
    outputs : dict of Output
    gravity_force : ndarray
        Generalised weight forces on q [N, N m].
    static_state : ndarray or None
        The static equilibrium q0 from the force-free configuration where nonlinear
        springs carry load (:func:`~inerterlab.vehicles.statics.rest_on_springs`), else
        None (K0 q0 = weights).
    """

    parameters: object
    dofs: tuple
    inputs: tuple
    corners: tuple
    axle_x: dict
    mass: np.ndarray
    connections: tuple
    outputs: dict = field(default_factory=dict)
    gravity_force: np.ndarray | None = None
    static_state: np.ndarray | None = None

    @property
    def kind(self) -> str:
        return "half" if isinstance(self.parameters, HalfCar) else "full"

    # -- matrices ------------------------------------------------------------------------
    def matrices(self, internal: bool = False):
        """(M, C, K, Kr, Cr): M q'' + C q' + K q = Kr r + Cr r'.

        A network strut with internal states contributes only the polynomial part of
        its dynamic stiffness here; that is the whole model only with ``internal=True``
        and the states of :meth:`internal_realisation` (used by :meth:`state_space`).
        Without it such a strut is refused, naming it.
        """
        n, m = len(self.dofs), len(self.inputs)
        mck = [con.law.mck() for con in self.connections]
        # b, c, k of each connection (complex where a law carries a complex step)
        law = np.zeros((len(self.connections), 3), dtype=np.result_type(float, *(x for t in mck for x in t)))
        for j, con in enumerate(self.connections):
            if internal_states(con.law) and not internal:
                raise ParameterError(
                    con.name,
                    getattr(con.law, "network", con.law),
                    "a strut without internal states here (mass, damping and stiffness "
                    "matrices alone); a network with internal nodes works in the state "
                    "space, the frequency response, the spectral method and the linear "
                    "and nonlinear time simulations",
                )
            b, c, k = law[j] = mck[j]
            if b and np.any(con.v):
                raise ParameterError(con.name, b, "no inertance on an element touching the road")
        U = np.array([con.u for con in self.connections]).reshape(-1, n)
        V = np.array([con.v for con in self.connections]).reshape(-1, m)
        b, c, k = law.T
        M = self.mass + (U.T * b) @ U
        C, K = (U.T * c) @ U, (U.T * k) @ U
        Kr, Cr = (U.T * k) @ V, (U.T * c) @ V
        return M, C, K, Kr, Cr

    def internal_realisation(self):
        """The internal states of every network strut, stacked: z' = Az z + Zq q - Zr r
        and generalised force -Fz z on q. Returns (Az, Zq, Zr, Fz) (nz = 0: empty)."""
        n, m = len(self.dofs), len(self.inputs)
        blocks = []
        for con in self.connections:
            if internal_states(con.law):
                blocks.append((con, *realisation(con.law)))
        nz = sum(b[1].shape[0] for b in blocks)
        dt = np.result_type(float, *(x for b in blocks for x in b[1:]))  # complex: a step
        Az, Zq, Zr, Fz = (np.zeros(shape, dtype=dt) for shape in ((nz, nz), (nz, n), (nz, m), (n, nz)))
        i = 0
        for con, A, B, Cc in blocks:
            k = A.shape[0]
            Az[i : i + k, i : i + k] = A
            Zq[i : i + k] = np.outer(B, con.u)
            Zr[i : i + k] = np.outer(B, con.v)
            Fz[:, i : i + k] = np.outer(con.u, Cc)
            i += k
        return Az, Zq, Zr, Fz

    def nonlinear_devices(self) -> list:
        """(connection, device) of every strut whose device only the nonlinear model
        integrates (:func:`nonlinear_device`), in connection order."""
        out = []
        for con in self.connections:
            dev = nonlinear_device(con.law)
            if dev is not None:
                out.append((con, dev))
        return out

    def require_linear(self, what: str) -> None:
        """ParameterError naming the first strut whose device is nonlinear (``what``:
        the analysis that cannot take it)."""
        devices = self.nonlinear_devices()
        if devices:
            con, dev = devices[0]
            raise ParameterError(
                con.name,
                dev.source,
                f"a linear strut for {what}: this device has internal nodes, "
                "friction or a nonlinear spring, which only the model core's vehicle "
                "(vehicle simulate, vehicle monte-carlo, vehicles.linear) takes",
            )

    def state_space(self):
        """x = (q, q', z): x' = A x + Br r + Bd r', y = Cy[name] x + Dr[name] r + Dd[name] r'.

        z are the internal states of network struts (none for struts of springs,
        dampers and inerters in parallel). Returns (A, Br, Bd, Cy, Dr, Dd) with Cy, Dr,
        Dd dicts keyed by output name. A strut with a nonlinear device is refused.
        """
        self.require_linear("the state space")
        M, C, K, Kr, Cr = self.matrices(internal=True)
        Az, Zq, Zr, Fz = self.internal_realisation()
        n, nz = len(self.dofs), Az.shape[0]
        Minv = np.linalg.inv(M)
        A = np.zeros((2 * n + nz, 2 * n + nz), dtype=np.result_type(M, C, K, Fz, Az))
        A[:n, n : 2 * n] = np.eye(n)
        A[n : 2 * n, :n] = -Minv @ K
        A[n : 2 * n, n : 2 * n] = -Minv @ C
        A[n : 2 * n, 2 * n :] = -Minv @ Fz
        A[2 * n :, :n] = Zq
        A[2 * n :, 2 * n :] = Az
        Br = np.vstack([np.zeros_like(Kr), Minv @ Kr, -Zr])
        Bd = np.vstack([np.zeros_like(Cr), Minv @ Cr, np.zeros_like(Zr)])
        Cy, Dr, Dd = {}, {}, {}
        for name, o in self.outputs.items():
            Cy[name] = np.concatenate(
                [o.P - o.G @ Minv @ K, o.V - o.G @ Minv @ C, -o.G @ Minv @ Fz]
            )
            Dr[name] = o.R + o.G @ Minv @ Kr
            Dd[name] = o.S + o.G @ Minv @ Cr
        return A, Br, Bd, Cy, Dr, Dd

    # -- frequency response --------------------------------------------------------------
    def frequency_response(self, freq_hz, outputs=None) -> dict:
        """Transfer functions from the road heights to each output at ``freq_hz`` [Hz].

        Returns name -> complex array (n_freq, n_inputs).
        """
        self.require_linear("the frequency response")
        f = np.atleast_1d(np.asarray(freq_hz, dtype=float))
        s = 2j * math.pi * f
        n, m = len(self.dofs), len(self.inputs)
        Z = np.zeros((f.size, n, n), complex)
        F = np.zeros((f.size, n, m), complex)
        Z -= (2 * math.pi * f)[:, None, None] ** 2 * self.mass
        for con in self.connections:
            z = np.asarray(dynamic_stiffness(con.law, s))[:, None, None]
            Z += z * np.outer(con.u, con.u)
            F += z * np.outer(con.u, con.v)
        Q = np.linalg.solve(Z, F)
        out = {}
        for name in outputs or self.outputs:
            o = self.outputs[name]
            w = (o.P + s[:, None] * o.V + (s * s)[:, None] * o.G)[:, None, :]
            out[name] = (w @ Q)[:, 0, :] + o.R + s[:, None] * o.S
        return out

    # -- statics and modes ---------------------------------------------------------------
    def static_stiffness_matrix(self) -> np.ndarray:
        """K0 = sum_j Z_j(0) u_j u_j^T: the stiffness the car rests on (network struts
        with their static stiffness, not the polynomial part of Z)."""
        n = len(self.dofs)
        K0 = np.zeros((n, n))
        for con in self.connections:
            K0 += con.law.static_stiffness() * np.outer(con.u, con.u)
        return K0

    def static_tyre_loads(self) -> dict:
        """Static contact force of each wheel station [N], from K0 q0 = weights, K0
        assembled from each law's static stiffness Z(0)."""
        K0 = self.static_stiffness_matrix()
        try:
            if self.static_state is not None:  # resting on nonlinear springs
                q0 = self.static_state
            elif np.linalg.cond(K0) > 1e12:
                raise np.linalg.LinAlgError
            else:
                q0 = np.linalg.solve(K0, self.gravity_force)
        except np.linalg.LinAlgError:
            raise ParameterError(
                "struts",
                "no static stiffness",
                "a suspension that carries the car at rest "
                "(a network whose springs all sit in series with a damper has Z(0) = 0)",
            ) from None
        out = {}
        for con in self.connections:
            if con.name.endswith("_tyre"):
                k = con.law.static_stiffness()
                out[con.name[: -len("_tyre")]] = float(-k * con.u @ q0)
        return out

    def natural_frequencies(self, rigid_tyres: bool = True) -> np.ndarray:
        """Undamped natural frequencies [Hz], ascending.

        ``rigid_tyres=True``: the wheels are held (the body, and seat, on the struts'
        springs and inerters alone); otherwise the whole undamped system.
        """
        self.require_linear("natural frequencies")
        M, _, K, _, _ = self.matrices()
        keep = [i for i, d in enumerate(self.dofs) if not (rigid_tyres and d.startswith("wheel_"))]
        from scipy.linalg import eigh

        w2 = eigh(K[np.ix_(keep, keep)], M[np.ix_(keep, keep)], eigvals_only=True)
        return np.sqrt(np.maximum(w2, 0.0)) / (2 * math.pi)


def _unit(n, i):
    e = np.zeros(n)
    e[i] = 1.0
    return e


def build(parameters: HalfCar | FullCar) -> LinearVehicle:
    """The :class:`LinearVehicle` of a :class:`HalfCar` or :class:`FullCar`.

    Examples
    --------
    >>> from inerterlab.vehicles import example_vehicle_path, load_vehicle
    >>> car = build(load_vehicle(example_vehicle_path()))
    >>> car.inputs
    ('front_left', 'front_right', 'rear_left', 'rear_right')
    >>> [round(float(f), 1) for f in car.natural_frequencies(rigid_tyres=True)]
    [1.4, 1.6, 2.3, 4.2]
    """
    p = parameters
    if isinstance(p, HalfCar):
        body = ["bounce", "pitch"]
        a, b = p.cg_to_front, p.cg_to_rear
        stations = [("front", a, 0.0, p.front), ("rear", -b, 0.0, p.rear)]
    elif isinstance(p, FullCar):
        body = ["bounce", "pitch", "roll"]
        a, b = p.cg_to_front, p.cg_to_rear
        tf, tr = 0.5 * p.front_track, 0.5 * p.rear_track
        stations = [
            ("front_left", a, tf, p.front),
            ("front_right", a, -tf, p.front),
            ("rear_left", -b, tr, p.rear),
            ("rear_right", -b, -tr, p.rear),
        ]
    else:
        raise ParameterError("vehicle", type(p).__name__, "a HalfCar or a FullCar")
    names = [s[0] for s in stations]
    dofs = body + [f"wheel_{c}" for c in names] + (["seat"] if p.seat is not None else [])
    n, m = len(dofs), len(stations)
    nb = len(body)

    def body_point(x, y):
        u = np.zeros(n)
        u[0], u[1] = 1.0, -x
        if nb == 3:
            u[2] = y
        return u

    mass = np.zeros((n, n))
    mass[0, 0], mass[1, 1] = p.sprung_mass, p.pitch_inertia
    if nb == 3:
        mass[2, 2] = p.roll_inertia
    gravity = np.zeros(n)
    gravity[0] = -p.sprung_mass * p.gravity
    cons = []
    strut_u = {}
    outputs = {}
    zero_n, zero_m = np.zeros(n), np.zeros(m)
    for j, (name, x, y, corner) in enumerate(stations):
        assert isinstance(corner, Corner)
        iw = nb + j
        mass[iw, iw] = corner.unsprung_mass
        gravity[iw] = -corner.unsprung_mass * p.gravity
        u_s = body_point(x, y) - _unit(n, iw)  # strut extension
        strut_u[name] = u_s
        cons.append(Connection(f"{name}_strut", u_s, zero_m.copy(), corner.strut))
        u_t, v_t = _unit(n, iw), _unit(m, j)  # tyre extension: wheel - road
        cons.append(Connection(f"{name}_tyre", u_t, v_t, corner.tyre))
        kt, ct = corner.tyre.stiffness, corner.tyre.damping
        outputs[f"{name}_deflection"] = Output(
            u_s, zero_n, zero_n, zero_m, zero_m, OUTPUT_UNITS["deflection"]
        )
        outputs[f"{name}_tyre_load"] = Output(
            -kt * u_t, -ct * u_t, zero_n, kt * v_t, ct * v_t, OUTPUT_UNITS["tyre_load"]
        )
    if isinstance(p, FullCar):
        for axle, rate in (("front", p.front_anti_roll), ("rear", p.rear_anti_roll)):
            if rate > 0:
                u = strut_u[f"{axle}_left"] - strut_u[f"{axle}_right"]
                cons.append(Connection(f"{axle}_anti_roll", u, zero_m.copy(), _Rate(rate)))
    if p.seat is not None:
        s = p.seat
        isx = n - 1
        mass[isx, isx] = s.mass
        gravity[isx] = -s.mass * p.gravity
        from inerterlab.vehicles.parameters import Strut

        cushion = Strut(stiffness=s.stiffness, damping=s.damping)
        cons.append(Connection("seat", body_point(s.x, s.y) - _unit(n, isx), zero_m, cushion))
    accel = {"bounce_acc": 0, "pitch_acc": 1, "roll_acc": 2, "seat_acc": n - 1}
    acc_out = {}
    for name, i in accel.items():
        if name == "roll_acc" and nb < 3 or name == "seat_acc" and p.seat is None:
            continue
        acc_out[name] = Output(zero_n, zero_n, _unit(n, i), zero_m, zero_m, OUTPUT_UNITS[name])
    acc_out.update(outputs)
    return rest_on_springs(LinearVehicle(
        parameters=p,
        dofs=tuple(dofs),
        inputs=tuple(names),
        corners=tuple(names),
        axle_x={c[0]: c[1] for c in stations},
        mass=mass,
        connections=tuple(cons),
        outputs=acc_out,
        gravity_force=gravity,
    ))


# -- statics: nonlinear springs across a device carrying the car ------------------------


def _carriers(law) -> list:
    """(edge index, element, sign) of the nonlinear springs straight across a strut's
    device (sign: +1 if the element's extension is the strut's)."""
    dev = getattr(law, "device", None)
    if dev is None:
        return []
    return [
        (i, el, 1.0 if t == 0 else -1.0)
        for i, (_, el, t, b) in enumerate(dev.edges)
        if {t, b} == {0, 1} and hasattr(el, "at_operating_point")
    ]


def _tension(carriers, e: float, rebased: bool) -> float:
    """Tension [N] of the springs at strut extension ``e`` [m] (from the force-free
    lengths, or about their operating points if ``rebased``)."""
    out = 0.0
    for _, el, sign in carriers:
        y = sign * e
        if rebased:
            out += sign * (el.force(el.operating_point + y) - el.force(el.operating_point))
        else:
            out += sign * el.force(y)
    return out


def rest_on_springs(vehicle):
    """``vehicle`` (a :class:`LinearVehicle` of this module) at its static
    equilibrium: unchanged if no nonlinear spring carries load; otherwise with each such
    spring about its static extension and ``static_state`` the equilibrium q0 [m, rad]
    from the force-free configuration."""
    from inerterlab.systems.equilibrium import newton
    from inerterlab.vehicles.parameters import _split

    carriers = [(j, _carriers(con.law)) for j, con in enumerate(vehicle.connections)]
    carriers = [(j, c) for j, c in carriers if c]
    if not carriers:
        return vehicle
    K0 = vehicle.static_stiffness_matrix()
    fg = vehicle.gravity_force
    U = [vehicle.connections[j].u for j, _ in carriers]

    def residual(q):
        r = fg - K0 @ q
        for u, (_, c) in zip(U, carriers, strict=True):
            r -= u * _tension(c, float(u @ q), rebased=False)
        return r

    def singular(J):
        raise NetworkError(
            "vehicle: no static equilibrium: the static stiffness is singular (a body or "
            "wheel coordinate is held by no spring)"
        )

    weight = float(np.abs(fg).sum())
    q0, _ = newton(residual, len(fg), 1e-12 * max(weight, 1.0), "vehicle", singular)
    cons = list(vehicle.connections)
    for j, c in carriers:
        con = cons[j]
        e = float(con.u @ q0)
        dev = con.law.device
        edges = list(dev.edges)
        for i, el, sign in c:
            lo, hi, what = el.static_range()
            y = sign * e
            if not lo <= y <= hi:
                raise NetworkError(
                    f"vehicle: no static equilibrium within the elements' ranges: at "
                    f"{con.name} the {el.description} ({edges[i][0]}) would take {-y:.6g} m "
                    f"of compression carrying {-el.force(y):.6g} N, beyond {what}"
                )
            name, _, t, b = edges[i]
            edges[i] = (name, el.at_operating_point(y), t, b)
        law = dataclasses.replace(con.law, device=_split(dev.source, dev.nodes, tuple(edges)))
        cons[j] = dataclasses.replace(con, law=law)
    return dataclasses.replace(vehicle, connections=tuple(cons), static_state=q0)
