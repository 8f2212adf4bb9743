"""Build a core :class:`System` from bodies and networks; simulate it."""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import MutableMapping
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from .._blas import one_blas_thread
from ..elements import kernel_law
from ..elements._base import NPAR, ElementBase
from ..errors import ConvergenceError, ParameterError, check_positive
from ..h2 import resolvent_solve
from ..networks import NetworkError
from . import _integrate, _kernel, _tables
from ._kernel import DYN, ELEM_W, GROUND, HEADER, LIN, NODE_W, POS, REL, RELV, ROAD, VEL
from ._network import Layout, elements_of
from .options import DEFAULT_OPTIONS, SimulationOptions

_TYPE = {"ground": GROUND, "road": ROAD, "combination": LIN}
#: ``method="auto"`` takes exact steps where they need at most this many distinct step
#: lengths (one matrix exponential each)
EXACT_MAX_STEP_SIZES = 256
#: exact step lengths are rounded to this many seconds per second of horizon
EXACT_STEP_QUANTUM = 1e-13
#: the longest quadrature panel [s] of a system's observers in an exact step: the
#: accuracy of five-point Gauss-Legendre sums over each panel (the error of a component
#: of angular frequency w goes as (w h)^10; 2e-8 of it for Wk's 100 Hz section) is
#: what a step's quadrature keeps; a step as long as m panels takes one Gauss-Legendre
#: rule of as many nodes as that needs (:func:`_gauss_count`: 15 for eight panels)
EXACT_OBSERVER_PANEL = 2.5e-3
#: and at most this many radians of the road's sine or of the system's fastest mode
#: (the base system's largest |eigenvalue|) per panel: the quadrature's error in the
#: square of a component that fast is below (2 x 0.5)^10 x 3.9e-13 of its own integral
#: (the 1 ms half-cosine edges of a smoothed bump, a sine of 3142 rad/s, take 13 panels)
EXACT_OBSERVER_PHASE = 0.5
#: the longest exact step [s] with observers where the break points are further apart
#: (one sample at the horizon: a metrics-only run), and at most this many panels in one
#: step: the peaks' Taylor rows then span at most (fastest rate x step) <= 8 (Wk's
#: 628 rad/s: 6.3), well inside the :data:`TAYLOR_TERMS` terms
EXACT_OBSERVER_LONGEST = 1e-2
EXACT_OBSERVER_PANELS = 16
#: the panel halved where an observer integrates a fourth power (the VDV): its
#: integrand holds twice the frequencies of a square, and at the square's panel its
#: quadrature error was 9.6e-8 of the VDV after a road step (the Wk filter's 100 Hz
#: ringing; docs/decisions.md); at the phase bound the base system's modes leave a
#: fourth power (4 x 0.5)^10 x 3.9e-13 = 4e-10 of their share
EXACT_FOURTH_POWER_SHARE = 0.5


@dataclass(frozen=True, eq=False)
class CoreResult:
    """A time simulation of a core system.

    Attributes
    ----------
    time : ndarray
        Sample times [s].
    states : ndarray
        States at the samples, columns ``system.state_names``.
    outputs : mapping
        Sampled outputs by name (computed when first read): ``<node>.x``, ``<node>.v``, ``<node>.a`` [m, m/s, m/s^2]
        (acceleration NaN at massless nodes), ``<element>.force`` [N]; for a quarter car
        also ``body_acc``, ``deflection``, ``tyre_force`` (dynamic), ``tyre_grip``; for a
        rig ``force`` (the force the rig applies).
    metrics : dict or None
        Quarter car: the ride metrics (:func:`.observers.ride_metrics`), integrated as
        observer states (:func:`.observers.ride`), not from the samples.
    method : str
        ``adaptive`` or ``exact``.
    stats : dict
    road_steps : tuple
        ((time [s], road jump [m]), ...).
    """

    system: System
    time: np.ndarray
    states: np.ndarray
    outputs: MutableMapping
    metrics: dict | None
    method: str
    stats: dict
    road_steps: tuple = ()
    not_finite: dict = field(default_factory=dict)
    observed: dict = field(default_factory=dict)

    def __repr__(self) -> str:
        t = self.time
        span = f"{t.size} samples over {t[-1] - t[0]:g} s" if t.size else "no samples"
        shown = ""
        if self.metrics:
            keys = ("rms_body_acc", "rms_body_acc_wk", "rms_deflection", "rms_tyre_grip")
            shown = ", " + ", ".join(
                f"{k}={'not finite' if self.metrics[k] is None else format(self.metrics[k], '.4g')}"
                for k in keys
            )
        return f"<CoreResult {self.system.description}: {span}, {self.method} steps{shown}>"

    def plot(self, outputs=None, **kwargs):
        """Figure of sampled outputs against time, one panel each (``outputs``: names of
        :attr:`outputs`; by default body acceleration, deflection and tyre force for a
        quarter car, the force and drive displacement for a rig, the body's displacement
        and acceleration otherwise). Keywords go to :func:`.plot.plot_result`."""
        from .plot import plot_result

        return plot_result(self, outputs, **kwargs)


@dataclass(frozen=True, eq=False)
class System:
    """A compiled system: bodies, networks and the road (see :mod:`inerterlab.systems`)."""

    kind: str
    description: str
    node_names: tuple
    node_types: tuple
    element_names: tuple
    elements: tuple
    state_names: tuple
    itab: np.ndarray
    ftab: np.ndarray
    x0_template: np.ndarray
    state_scales: np.ndarray
    linear: bool
    imp_unit: np.ndarray
    jump_ok: bool
    info: dict = field(default_factory=dict)

    rhs = staticmethod(_kernel.rhs)
    outputs = staticmethod(_kernel.outputs)

    def with_observers(self, observers) -> System:
        """This system with observer states (:mod:`inerterlab.systems.observers`)
        appended: integrals of signals, of their squares, fourth powers and products,
        running peaks; their final values in :attr:`CoreResult.observed`."""
        from .observers import with_observers

        return with_observers(self, observers)

    @property
    def observers(self) -> tuple:
        """The observers this system carries (``with_observers``)."""
        return tuple(self.info.get("observers", ()))

    def __repr__(self) -> str:
        law = "linear" if self.linear else "nonlinear"
        return (
            f"<System {self.description}: {self.n_states} states, "
            f"{len(self.elements)} elements, {law}>"
        )

    @property
    def n_states(self) -> int:
        return len(self.state_names)

    @property
    def tables(self) -> tuple[np.ndarray, np.ndarray]:
        return self.itab, self.ftab

    @property
    def output_names(self) -> tuple[str, ...]:
        n = self.node_names
        return (
            tuple(f"{x}.x" for x in n)
            + tuple(f"{x}.v" for x in n)
            + tuple(f"{x}.a" for x in n)
            + tuple(f"{e}.force" for e in self.element_names)
        )

    def initial_state(self, **node_displacements: float) -> np.ndarray:
        """State at rest; ``node_displacements`` (e.g. ``body=0.05``) move bodies, the
        internal nodes take the spring equilibrium between them."""
        return _initial(self, node_displacements, 0.0)

    # -- linear analysis ------------------------------------------------------------------
    def linear_state_space(self):
        """(A, B, C, D) of x' = A x + B u, y = C x + D u with u = (road displacement,
        velocity, acceleration), three per road where the system has several (a vehicle),
        and y the outputs (:attr:`output_names`).

        Columns come from the right-hand side at unit vectors, exact for a linear system.
        NetworkError if an element is not linear."""
        if "base" in self.info:  # the observers are not part of the linear dynamics
            return self.info["base"].linear_state_space()
        if not self.linear:
            bad = [
                n for n, e in zip(self.element_names, self.elements, strict=True) if _nonlinear(e)
            ]
            raise NetworkError(
                f"{self.description}: not linear ({', '.join(bad)}); linear analysis needs "
                "springs, linear dampers and ideal inerters"
            )
        return tuple(a.copy() for a in _linear_ss(self))

    def transfer(self, omega, output: str):
        """H(j omega) from road velocity to ``output`` (linear systems): any name of
        :attr:`output_names`; for a quarter car also ``body_acc``,
        ``suspension_deflection`` and ``tyre_deflection``; for a rig ``force``, the force
        at the drive per unit drive velocity (the network's admittance Y(j omega))."""
        A, B, C, D = self.linear_state_space()
        i = self.output_names.index(output) if output in self.output_names else None
        c, d = _derived_row(self, output, C, D) if i is None else (C[i], D[i])
        s = 1j * np.atleast_1d(np.asarray(omega, float))
        u = np.stack([1.0 / s, np.ones_like(s), s], axis=1)  # road height, velocity, acceleration
        x = resolvent_solve(A, s, u @ B.T)
        return x @ c + u @ d

    # -- time simulation --------------------------------------------------------------
    def simulate(
        self,
        excitation,
        horizon: float = 10.0,
        *,
        options: SimulationOptions = DEFAULT_OPTIONS,
        x0: np.ndarray | None = None,
        times=None,
        metrics_only: bool = False,
        **option_values,
    ) -> CoreResult:
        """Simulate on a road input of :mod:`inerterlab.excitation` from 0 to ``horizon``.

        ``options`` (:class:`~inerterlab.systems.options.SimulationOptions`): tolerances,
        method, sampling, step control; keywords named as its fields (``rtol=1e-10``)
        replace those of ``options``. Samples at ``times`` [s] (increasing, in [0,
        horizon]) when given, else every 1/``sample_rate`` from 0; ``x0``: the initial
        state (default: at rest, the input's initial displacements). A quarter car
        started at rest carries its ride observers (:func:`.observers.ride`) and
        returns their metrics.

        ``method``: ``adaptive`` (Dormand-Prince 5(4)), ``exact`` (matrix exponential,
        linear systems on piecewise-linear roads: drop, bumps with ramp or step edges,
        ISO 8608 and file roads; first-order hold, exact to round-off) or ``auto``
        (exact for a linear system on a piecewise-linear road whose edges and samples
        need at most :data:`EXACT_MAX_STEP_SIZES` distinct step lengths and whose
        observers read what the exact steps give, adaptive otherwise, with exact steps
        while every nonlinear element sits in its linear regime; observers ride both
        kinds of exact steps, docs/model.md §11).

        ``metrics_only`` (a quarter car started at rest): one sample, at the horizon;
        the ride metrics are the same observers' (a study that needs only the metrics
        skips sampling the outputs every 1/``sample_rate``)."""
        options = _options(options, option_values)
        options.warn_ignored("System.simulate (rk4 runs in systems.vehicle.simulate)",
                             "fixed_method")  # fmt: skip
        if metrics_only and (self.kind != "quarter_car" or times is not None or x0 is not None):
            raise ParameterError(
                "metrics_only", metrics_only, "False here: a quarter car started at rest "
                "(no times=, no x0=) integrates its ride metrics",
            )  # fmt: skip
        return _simulate(self, excitation, horizon, options, x0, times, metrics_only=metrics_only)


def _options(options, values: dict) -> SimulationOptions:
    """``options`` with the fields named in ``values`` replaced."""
    if not isinstance(options, SimulationOptions):
        raise ParameterError("options", options, "a SimulationOptions")
    if values:
        bad = sorted(set(values) - _OPTION_FIELDS)
        if bad:
            raise ParameterError(bad[0], values[bad[0]], "a field of SimulationOptions")
        items = tuple((k, type(v), v) for k, v in sorted(values.items()))  # 1 is not True
        try:
            options = _replaced(options, items)
        except TypeError:  # a value that is not hashable: the options' own check
            options = dataclasses.replace(options, **values)
    return options


_OPTION_FIELDS = frozenset(f.name for f in dataclasses.fields(SimulationOptions))


@lru_cache(maxsize=64)
def _replaced(options: SimulationOptions, items: tuple) -> SimulationOptions:
    """``options`` with the fields ``items`` ((name, type, value), ...) replaced, kept for
    the last few: a study that passes the same keywords to every run checks them once."""
    return dataclasses.replace(options, **{k: v for k, _, v in items})


def _memo(sys) -> dict:
    """What the simulations of ``sys`` build from its tables alone (its state space, its
    rest states, the plans of exact steps by road and samples), kept on it and tied to
    the identity of its (read-only) tables: a system derived with new tables
    (``dataclasses.replace``) shares its ``info`` dict but not this store."""
    got = sys.info.get("memo")
    if got is None or got[0] is not sys.itab or got[1] is not sys.ftab:
        got = (sys.itab, sys.ftab, {})
        sys.info["memo"] = got
    return got[2]


def _linear_ss(sys):
    """(A, B, C, D) of a linear system (:meth:`System.linear_state_space`), computed
    once per system; shared arrays, read only."""
    if "base" in sys.info:
        return _linear_ss(sys.info["base"])
    memo = _memo(sys)
    got = memo.get("state_space")
    if got is None:
        if not sys.linear:
            sys.linear_state_space()  # its error
        got = memo["state_space"] = _state_space(sys, sys.itab, sys.ftab)
    return got


def _state_space(sys, itab, ftab):
    """(A, B, C, D) of the system's right-hand side and outputs on the tables (itab,
    ftab), from unit vectors: exact where they hold linear elements only. The inputs are
    each road's displacement, velocity and acceleration (3 per road, in the order of
    :func:`._kernel.road_layout`)."""
    n = sys.n_states
    no = len(sys.output_names)
    nu = _kernel.road_layout_of(itab)[1]  # the free slot follows the roads
    A = np.zeros((n, n))
    B = np.zeros((n, nu))
    C = np.zeros((no, n))
    D = np.zeros((no, nu))
    z = np.zeros(n)
    r0 = np.zeros(nu)
    col = np.empty(n)  # contiguous: the compiled code's one signature (not a column view)
    for k in range(n):
        e = np.zeros(n)
        e[k] = 1.0
        _kernel.rhs(0.0, e, r0, itab, ftab, col)
        A[:, k] = col
        out = np.empty(no)
        _kernel.outputs(0.0, e, r0, itab, ftab, out)
        C[:, k] = out
    for k in range(nu):
        u = np.zeros(nu)
        u[k] = 1.0
        _kernel.rhs(0.0, z, u, itab, ftab, col)
        B[:, k] = col
        out = np.empty(no)
        _kernel.outputs(0.0, z, u, itab, ftab, out)
        D[:, k] = out
    return A, B, np.nan_to_num(C), np.nan_to_num(D)


def _nonlinear(e: ElementBase) -> bool:
    return not e.is_linear


def _drive_elements(sys) -> list[str]:
    """Names of a rig's elements with their top end at the drive (node 0): their forces
    add up to the force at the drive."""
    return [
        n for n, (_, _, t, _) in zip(sys.element_names, sys.info["edges"], strict=True) if t == 0
    ]


def _derived_row(sys, output, C, D):
    names = list(sys.output_names)
    if sys.kind == "quarter_car":

        def row(n):
            j = names.index(n)
            return C[j], D[j]

        if output == "body_acc":
            return row("body.a")
        if output == "suspension_deflection":
            cb, db = row("body.x")
            cw, dw = row("wheel.x")
            return cb - cw, db - dw
        if output == "tyre_deflection":
            cw, dw = row("wheel.x")
            cr, dr = row("road.x")
            return cw - cr, dw - dr
    if sys.kind == "rig" and output == "force":  # the force at the drive (its admittance)
        rows = [names.index(f"{n}.force") for n in _drive_elements(sys)]
        return C[rows].sum(axis=0), D[rows].sum(axis=0)
    extra = {"quarter_car": ", body_acc, suspension_deflection, tyre_deflection", "rig": ", force"}
    raise ParameterError("output", output, f"one of the output names{extra.get(sys.kind, '')}")


# ---------------------------------------------------------------------------------------
# building


class _Unarranged(NetworkError):
    """A massless node the classification cannot integrate in the order written (an
    inertance or a damper between massless nodes); laying the series chains out again
    (:class:`~inerterlab.systems._network.Layout` ``arrange``) may remove it."""


def _laid_out(kind: str, description: str, make, info: dict) -> tuple[System, Layout]:
    """Build from ``make(arrange)`` (a filled Layout): in the order written, and if that
    leaves an inertance or damper between massless nodes, with the series chains
    arranged (the same network seen from its terminals); the first error if both fail."""
    lay = make(False)
    try:
        return build(kind, description, lay, info), lay
    except _Unarranged as first:
        lay = make(True)
        try:
            sys = build(kind, description, lay, info)
        except _Unarranged:
            pass
        else:
            sys.info["arranged"] = True
            return sys, lay
        # last: floating inertance components, their common motion a massless node
        # (in the arranged order, which also repairs damper chains, then as written)
        for arrange in (True, False):
            lay = make(arrange)
            try:
                sys = build(kind, description, lay, info, floating=True)
            except _Unarranged:
                continue
            if arrange:
                sys.info["arranged"] = True
            return sys, lay
        raise NetworkError(str(first)) from None


def _check_singular(
    Mat: np.ndarray, nodes: list, lay: Layout, what: str, hint: str, error=NetworkError
) -> None:
    if Mat.shape[0] == 0:
        return
    w, v = np.linalg.eigh(0.5 * (Mat + Mat.T))
    scale = max(np.max(np.abs(np.diag(Mat))), 1e-300)
    bad = np.flatnonzero(np.abs(w) <= 1e-12 * scale)
    if bad.size:
        vec = v[:, bad[0]]
        idx = [nodes[i] for i in np.flatnonzero(np.abs(vec) > 1e-8)]
        where = "; ".join(sorted({lay.nodes[i]["origin"] or lay.nodes[i]["name"] for i in idx}))
        raise error(f"ill-posed network: {what} at {where}. {hint}")


def _unheld_components(lay: Layout, attached: list, inside, joins, holds) -> list[list[int]]:
    """Connected sets of the nodes with ``inside(i)``, joined by the elements with
    ``joins(el)``, that nothing holds: no such element leaves the set, no element with
    ``holds(el)`` touches it and no node of it has a mass."""
    edges = lay.edges
    seen: set[int] = set()
    comps = []
    for start in range(len(lay.nodes)):
        if not inside(start) or start in seen:
            continue
        comp, stack, held = [], [start], False
        seen.add(start)
        while stack:
            i = stack.pop()
            comp.append(i)
            held |= lay.nodes[i]["mass"] > 0
            for e in attached[i]:
                _, el, t, b = edges[e]
                held |= holds(el)
                if not joins(el):
                    continue
                j = b if t == i else t
                if not inside(j):
                    held = True
                elif j not in seen:
                    seen.add(j)
                    stack.append(j)
        if not held:
            comps.append(sorted(comp))
    return comps


def _floating_components(lay: Layout, types: list, attached: list) -> list[list[int]]:
    """Node sets joined by inertances to each other only: no mass, no inertance to a
    terminal (their nominal mass matrix is singular along their common motion)."""
    return _unheld_components(
        lay, attached, lambda i: types[i] == DYN, lambda el: kernel_law(el).inertial,
        lambda el: False,
    )  # fmt: skip


def _floating_damper_components(lay: Layout, types: list, ref: list, attached: list):
    """Velocity nodes joined by dampers to each other only (no damper to any other node,
    no friction at them, which would need the common motion): the springs alone set
    their common motion."""
    return [
        c
        for c in _unheld_components(
            lay, attached, lambda i: types[i] == VEL and ref[i] < 0,
            lambda el: kernel_law(el).holds_velocity, lambda el: kernel_law(el).bounded,
        )  # fmt: skip
        if len(c) > 1
    ]


def build(kind: str, description: str, lay: Layout, info: dict, floating: bool = False) -> System:
    """Classify the nodes, check the network is well posed and pack the tables. With
    ``floating``, node sets joined by inertances (or by dampers) that nothing else holds
    get their common motion from their summed force balance (a reference node of
    velocity or spring-only type, the others relative to it) instead of being refused."""
    nn = len(lay.nodes)
    edges = lay.edges
    attached: list[list[int]] = [[] for _ in range(nn)]
    for e, (_, _, t, b) in enumerate(edges):
        attached[t].append(e)
        attached[b].append(e)
    types = []
    for i, nd in enumerate(lay.nodes):
        if nd["kind"] in _TYPE:
            types.append(_TYPE[nd["kind"]])
            continue
        laws = {kernel_law(edges[e][1]) for e in attached[i]}
        if nd["mass"] > 0 or any(law.inertial for law in laws):
            types.append(DYN)
        elif any(law.holds_velocity for law in laws):
            types.append(VEL)
        elif any(law.bounded for law in laws):
            raise NetworkError(
                f"ill-posed network: friction with no damper or inertance beside it at "
                f"{nd['origin'] or nd['name']}: a massless node held by friction and "
                "springs has no solution once the springs pull harder than the friction "
                "force. Add a damper in parallel with the friction (or a mass)"
            )
        else:
            played = [edges[e][0] for e in attached[i] if _nonlinear(edges[e][1])]
            if played:
                gap = any(
                    edges[e][0] == played[0] and kernel_law(edges[e][1]).free_play(edges[e][1].row())
                    for e in attached[i]
                )  # fmt: skip
                why = (
                    "inside the free play its position is not determined" if gap else
                    "its position would follow from a nonlinear spring balance, which the "
                    "core does not solve"
                )  # fmt: skip
                raise NetworkError(
                    f"ill-posed network: {'backlash' if gap else 'a nonlinear spring'} "
                    f"({played[0]}) at {nd['origin'] or nd['name']}, a massless node held "
                    f"only by springs: {why}. Add a damper beside it, or a mass or an "
                    "inerter at the node"
                )
            types.append(POS)
    ref = [-1] * nn  # the reference node of each node's floating component
    if floating:
        comps = _floating_components(lay, types, attached)
        for comp in comps:
            cs = set(comp)
            r = comp[0]
            outside = [
                edges[e][1] for i in comp for e in attached[i] if not {edges[e][2], edges[e][3]} <= cs
            ]
            laws = {kernel_law(el) for el in outside}
            where = lay.nodes[r]["origin"] or lay.nodes[r]["name"]
            if any(law.holds_velocity for law in laws):
                types[r] = VEL
            elif any(law.bounded for law in laws):
                raise NetworkError(
                    f"ill-posed network: friction with no damper beside it at {where}, a "
                    "chain of inerters between massless nodes held by friction and springs. "
                    "Add a damper in parallel with the friction (or a mass)"
                )
            elif any(_nonlinear(el) for el in outside):
                raise NetworkError(
                    f"ill-posed network: backlash at {where}, a chain of inerters between "
                    "massless nodes held only by springs: inside the free play its position "
                    "is not determined. Add a damper beside it, or a mass"
                )
            else:
                types[r] = POS
            for i in comp:
                ref[i] = r
                if i != r:
                    types[i] = REL
        dcomps = _floating_damper_components(lay, types, ref, attached)
        if not comps and not dcomps:
            raise _Unarranged("no floating component")
        for comp in dcomps:
            r = comp[0]
            types[r] = POS
            for i in comp:
                ref[i] = r
                if i != r:
                    types[i] = RELV
    _check_combinations(lay, types, edges)
    dyn = [i for i in range(nn) if types[i] in (DYN, REL)]
    vel = [i for i in range(nn) if types[i] in (VEL, RELV)]
    pos = [i for i in range(nn) if types[i] == POS]
    cls = {}
    for lst in (dyn, vel, pos):
        for j, i in enumerate(lst):
            cls[i] = j
    # nominal mass matrix of the dynamic nodes
    Md = np.zeros((len(dyn), len(dyn)))
    for i in dyn:
        Md[cls[i], cls[i]] += lay.nodes[i]["mass"]
    Dv = np.zeros((len(vel), len(vel)))

    def slot(i):  # the velocity unknown whose balance node i is part of
        if types[i] in (VEL, RELV):
            return cls[i]
        if types[i] == REL and types[ref[i]] == VEL:
            return cls[ref[i]]
        return -1

    L = np.zeros((nn, nn))  # spring Laplacian
    for _, el, t, b in edges:
        law = kernel_law(el)
        if law.elastic:
            k = el.row()[0]  # the kernel row: any element on the spring's law
            L[t, t] += k
            L[b, b] += k
            L[t, b] -= k
            L[b, t] -= k
        if law.inertial and LIN in (types[t], types[b]):
            me = law.nominal_inertance(el)
            g = _end_vector(lay, types, cls, t) - _end_vector(lay, types, cls, b)
            Md += me * np.outer(g, g)
        elif law.inertial:
            me = law.nominal_inertance(el)
            for a_, c_ in ((t, b), (b, t)):
                if types[a_] in (DYN, REL):
                    Md[cls[a_], cls[a_]] += me
                    if types[c_] in (DYN, REL):
                        Md[cls[a_], cls[c_]] -= me
        if law.holds_velocity:
            w = 1.0
            for a_, c_ in ((t, b), (b, t)):
                sa, sc = slot(a_), slot(c_)
                if sa >= 0:
                    Dv[sa, sa] += w
                    if sc >= 0:
                        Dv[sa, sc] -= w
    _check_singular(
        Md,
        dyn,
        lay,
        "the inertances form a free sub-network (no mass or terminal fixes its motion, "
        "even with the series elements rearranged)",
        "Attach a mass, or combine the springs around the inerter into one",
        _Unarranged,
    )
    _check_singular(
        Dv,
        vel,
        lay,
        "massless nodes joined only through dampers whose common motion only "
        "springs hold (a differential-algebraic loop)",
        "Write the springs in series next to each other (e.g. 'k1 - k2 - c' for 'k1 - c - k2')",
        _Unarranged,
    )
    # spring-only nodes from the others: X_p = R X
    R = np.zeros((len(pos), nn))
    if pos and not any(r >= 0 for r in ref):
        Lpp = L[np.ix_(pos, pos)]
        others = [i for i in range(nn) if types[i] != POS]
        _check_singular(Lpp, pos, lay, "spring-only nodes not held", "")
        R[:, others] = -np.linalg.solve(Lpp, L[np.ix_(pos, others)])
    elif pos:
        R = _spring_map(L, types, ref, pos, lay)
    # states
    names: list[str] = []
    xs = [-1] * nn
    vs = [-1] * nn
    scales = []
    # the node states by type: displacement, velocity (None: from a balance)
    suffix = {DYN: (".x", ".v"), VEL: (".x", None), REL: (".x_rel", ".v_rel"), RELV: (".x_rel", None)}
    for i in range(nn):
        if types[i] not in suffix:
            continue
        nm = lay.nodes[i]["name"]
        sx, sv = suffix[types[i]]
        xs[i] = len(names)
        names.append(nm + sx)
        scales.append(1e-2)
        if sv:
            vs[i] = len(names)
            names.append(nm + sv)
            scales.append(1e-1)
    n_node_states = len(names)
    so = []
    x0 = []
    for name, el, _, _ in edges:
        st = el.internal_states
        so.append(len(names) if st else -1)
        for s in st:
            names.append(f"{name}.{s}")
        x0 += list(el.initial_internal_state())
        scales += [1e-3, 1e-2][: len(st)]
    x0_template = np.concatenate([np.zeros(n_node_states), np.array(x0, float)])
    # tables
    ne = len(edges)
    no = HEADER
    eo = no + NODE_W * nn
    lo = eo + ELEM_W * ne
    itab = np.zeros(lo + nn, dtype=np.int64)
    itab[_kernel.I_NN] = nn
    itab[_kernel.I_NE] = ne
    itab[_kernel.I_ND] = len(dyn)
    itab[_kernel.I_NV] = len(vel)
    itab[_kernel.I_NP] = len(pos)
    itab[_kernel.I_NS] = len(names)
    itab[_kernel.I_NI] = len(names) - n_node_states
    itab[_kernel.I_NR] = sum(1 for t in types if t in (REL, RELV))
    itab[_kernel.I_NODE] = no
    itab[_kernel.I_ELEM] = eo
    itab[_kernel.I_DYN] = lo
    itab[_kernel.I_VEL] = lo + len(dyn)
    itab[_kernel.I_POS] = lo + len(dyn) + len(vel)
    itab[lo : lo + len(dyn) + len(vel) + len(pos)] = dyn + vel + pos
    fmass = 0
    fr = nn
    fe = fr + len(pos) * nn
    ftab = np.zeros(fe + NPAR * ne)
    itab, ftab, combo = _combination_tables(lay, types, itab, ftab)
    itab[_kernel.I_NL] = len(combo)
    itab[_kernel.I_NRD] = 1 + max((nd.get("road", 0) for nd in lay.nodes), default=0)
    itab[_kernel.I_FMASS] = fmass
    itab[_kernel.I_FR] = fr
    for i in range(nn):
        itab[no + NODE_W * i : no + NODE_W * (i + 1)] = (
            types[i], xs[i], vs[i], cls.get(i, -1), ref[i]
        )  # fmt: skip
        if types[i] == ROAD:  # the index of its road
            itab[no + NODE_W * i + 3] = lay.nodes[i].get("road", 0)
        elif types[i] == LIN:  # member list, count, coefficients
            itab[no + NODE_W * i : no + NODE_W * (i + 1)] = (LIN, *combo[i], -1)
        ftab[fmass + i] = lay.nodes[i]["mass"]
    ftab[fr:fe] = R.ravel()
    for e, (_, el, t, b) in enumerate(edges):
        ti = cls[t] if types[t] in (DYN, REL) else -1  # rows in the mass matrix, or -1
        bi = cls[b] if types[b] in (DYN, REL) else -1
        if LIN in (types[t], types[b]):  # -2: an end at a combination node
            ti = bi = -2
        itab[eo + ELEM_W * e : eo + ELEM_W * (e + 1)] = (
            el.code, t, b, fe + NPAR * e, so[e], ti, bi
        )  # fmt: skip
        ftab[fe + NPAR * e : fe + NPAR * (e + 1)] = el.row()
    # impulse of a unit road step
    imp = np.zeros(len(dyn))
    jump_ok = True
    blockers = []  # the elements on the road that a step has no finite response through
    for name, el, t, b in edges:
        ends = (t, b)
        if not any(types[x] == ROAD for x in ends):
            continue
        other = b if types[t] == ROAD else t
        law = kernel_law(el)
        if law.inertial or law.contact or types[other] == LIN:
            jump_ok = False
            if law.inertial:
                why = "an inertance"
            elif law.contact:
                why = "a contact that can open"
            else:
                why = "an end at a combination node"
            blockers.append(f"{name!r} ({why})")
        elif law.holds_velocity:
            c_lin, c_quad = el.row()[:2]  # the kernel row: any element on the damper's law
            if c_quad > 0 or not el.is_linear or types[other] != DYN:
                jump_ok = False
                blockers.append(f"{name!r} (a damper that is not linear or not on a mass)")
            else:
                imp[cls[other]] += c_lin
    linear = all(not _nonlinear(el) for _, el, _, _ in edges)
    # inertances with an end on the road: a road velocity jump would pass them an
    # impulse, which the integration does not apply (_simulate warns)
    road_inertances = tuple(
        name
        for name, el, t, b in edges
        if kernel_law(el).inertial and ROAD in (types[t], types[b])
    )
    # velocity jump of each dynamic node per unit road step (nominal inertances; only
    # whether it is zero is used: a body whose velocity jumps has a Dirac acceleration)
    dv_unit = np.linalg.solve(Md, imp) if len(dyn) and jump_ok else np.zeros(len(dyn))
    node_jump = {lay.nodes[i]["name"]: float(dv_unit[cls[i]]) for i in dyn}
    itab.setflags(write=False)
    ftab.setflags(write=False)
    return System(
        kind=kind,
        description=description,
        node_names=tuple(nd["name"] for nd in lay.nodes),
        node_types=tuple(types),
        element_names=tuple(e[0] for e in edges),
        elements=tuple(e[1] for e in edges),
        state_names=tuple(names),
        itab=itab,
        ftab=ftab,
        x0_template=x0_template,
        state_scales=np.array(scales, float),
        linear=linear,
        imp_unit=imp,
        jump_ok=jump_ok,
        info=dict(
            info,
            spring_laplacian=L,
            types=types,
            references=ref,
            velocity_jump_per_step=node_jump,
            road_inertances=road_inertances,
            road_step_blockers=tuple(blockers),
        ),
    )


def _check_combinations(lay: Layout, types: list, edges: list) -> None:
    """A combination node's members must be dynamic nodes (masses), a tyre must join a
    dynamic node to the road."""
    for i, nd in enumerate(lay.nodes):
        if types[i] == LIN:
            for m, _ in nd["members"]:
                if types[m] != DYN:
                    raise NetworkError(
                        f"the attachment point {nd['name']} combines "
                        f"{lay.nodes[m]['name']}, which is not a body coordinate"
                    )
    for name, el, t, b in edges:
        if kernel_law(el).contact and not (types[t] == DYN and types[b] == ROAD):
            raise NetworkError(f"the tyre {name} must join a wheel (a mass) to the road")


def _end_vector(lay: Layout, types: list, cls: dict, n: int) -> np.ndarray:
    """The mass-matrix rows of element end n as a vector over the dynamic nodes."""
    g = np.zeros(sum(1 for t in types if t in (DYN, REL)))
    if types[n] == LIN:
        for m, c in lay.nodes[n]["members"]:
            g[cls[m]] += c
    elif types[n] in (DYN, REL):
        g[cls[n]] = 1.0
    return g


def _combination_tables(lay: Layout, types: list, itab: np.ndarray, ftab: np.ndarray):
    """``itab`` and ``ftab`` with every combination node's member list and coefficients
    appended, and {node: (member list offset, count, coefficient offset)}."""
    combo = {}
    ilist, flist = [], []
    for i, nd in enumerate(lay.nodes):
        if types[i] == LIN:
            mem = nd["members"]
            combo[i] = (itab.size + len(ilist), len(mem), ftab.size + len(flist))
            ilist += [m for m, _ in mem]
            flist += [float(c) for _, c in mem]
    if not combo:
        return itab, ftab, combo
    itab = np.concatenate([itab, np.array(ilist, dtype=np.int64)])
    ftab = np.concatenate([ftab, np.array(flist, float)])
    return itab, ftab, combo


def _spring_map(L, types, ref, pos, lay) -> np.ndarray:
    """R with X_u = R X for the spring-only unknowns u (spring-only nodes and the
    references of spring-only floating components), X holding the relative
    displacement at relative nodes. X_abs = T X + U X_u; the rows are each spring-only
    node's balance and each spring-only component's summed balance."""
    nn = len(types)
    col = {p: j for j, p in enumerate(pos)}
    T = np.zeros((nn, nn))
    U = np.zeros((nn, len(pos)))
    for i in range(nn):
        if i in col:
            U[i, col[i]] = 1.0
        elif types[i] in (REL, RELV):
            T[i, i] = 1.0
            if ref[i] in col:
                U[i, col[ref[i]]] = 1.0
            else:
                T[i, ref[i]] = 1.0
        else:
            T[i, i] = 1.0
    S = np.zeros((len(pos), nn))
    for j, p in enumerate(pos):
        if ref[p] == p:
            S[j, [i for i in range(nn) if ref[i] == p]] = 1.0
        else:
            S[j, p] = 1.0
    A = S @ L @ U
    _check_singular(A, pos, lay, "spring-only nodes not held", "")
    return -np.linalg.solve(A, S @ L @ T)


def _initial(sys: System, fixed: dict, road0: float) -> np.ndarray:
    """Rest state: the named nodes at the given displacements (others of the bodies and
    the road at ``road0``), internal nodes at the spring equilibrium between them."""
    names = sys.node_names
    for k in fixed:
        if k not in names or sys.node_types[names.index(k)] == GROUND:
            raise ParameterError(k, fixed[k], f"a body node of the system ({', '.join(names)})")
    kept = _memo(sys).setdefault("rest_states", {})
    key = (tuple(sorted((k, float(v)) for k, v in fixed.items())), float(road0))
    got = kept.get(key)
    if got is None:
        got = _rest_state(sys, fixed, road0)
        if len(kept) >= REST_STATES_KEPT:
            kept.pop(next(iter(kept)))
        kept[key] = got
    return got.copy()


#: the rest states (:func:`_initial`) of this many (displacements, road level) are kept
#: on a system
REST_STATES_KEPT = 8


def _rest_state(sys, fixed: dict, road0: float) -> np.ndarray:
    names = list(sys.node_names)
    L = sys.info["spring_laplacian"]
    nn = len(names)
    masses = sys.ftab[sys.itab[_kernel.I_FMASS] : sys.itab[_kernel.I_FMASS] + nn]
    X = np.zeros(nn)
    term = [i for i in range(nn) if sys.node_types[i] in (GROUND, ROAD) or masses[i] > 0]
    for i in term:
        X[i] = 0.0 if sys.node_types[i] == GROUND else road0
        X[i] += float(fixed.get(names[i], 0.0))
    inner = [i for i in range(nn) if i not in term]
    if inner:
        x_def = float(np.mean(X[term])) if term else road0
        Lii = L[np.ix_(inner, inner)]
        rhs = -L[np.ix_(inner, term)] @ X[term]
        eps = 1e-13 * max(np.max(np.abs(np.diag(L))), 1.0)
        X[inner] = np.linalg.solve(Lii + eps * np.eye(len(inner)), rhs + eps * x_def)
    x = sys.x0_template.copy()
    ref = sys.info.get("references") or [-1] * nn
    for i in range(nn):
        nm = names[i]
        if f"{nm}.x" in sys.state_names:
            x[sys.state_names.index(f"{nm}.x")] = X[i]
        elif f"{nm}.x_rel" in sys.state_names:
            x[sys.state_names.index(f"{nm}.x_rel")] = X[i] - X[ref[i]]
    return x


# ---------------------------------------------------------------------------------------
# simulation


def _sample_times(horizon: float, rate: float) -> np.ndarray:
    n = int(math.floor(horizon * rate + 1e-9))
    return np.arange(n + 1) / rate


class RoadVelocityJumpWarning(UserWarning):
    """Kept for compatibility: road velocity jumps now pass their impulses
    (docs/model.md, "Networks"), and nothing issues this warning."""


def listed_steps(items, unit: str) -> str:
    """Road steps or velocity jumps ((time [s], value), ...) in one line, the first four."""
    text = ", ".join(f"{v:+.4g} {unit} at t = {t:g} s" for t, v in items[:4])
    return text + (f", ... ({len(items)} in all)" if len(items) > 4 else "")


def tyre_dirac_reason(down) -> str:
    """Why the minimum tyre force is not finite: a tyre damper that can pull, at the road's
    steps down ``down`` ((time [s], step [m]), ...). (Lift-off is no remedy to offer: a
    tyre that can lift off is not integrated across a road step.)"""
    return (
        f"not finite: the road steps down ({listed_steps(down, 'm')}) and the tyre damper "
        "would pull the wheel with a Dirac impulse C_t x step; smooth the edges "
        "(bump(edge=...), --edge)"
    )


@one_blas_thread  # its set-up's small matrices: threads only wait (see _blas)
def _simulate(
    sys, excitation, horizon, options, x0=None, times=None, ride=None, metrics_only=False
) -> CoreResult:
    """The run of :meth:`System.simulate`; ``ride``: carry a quarter car's ride observers
    (None: when it starts at rest with uniform samples); ``metrics_only``: one sample,
    at the horizon (with the ride observers)."""
    from ..excitation import Excitation

    if not isinstance(excitation, Excitation):
        raise ParameterError(
            "excitation", excitation, "an Excitation (drop(), bump(), sine(), ...)"
        )
    T = check_positive("horizon", horizon, "s")
    r = options.rtol
    method = options.method
    max_steps = options.max_steps
    excitation.check_horizon(T, stacklevel=3)
    if _kernel.road_layout_of(sys.itab)[1] > 3:
        raise ParameterError(
            "system", sys.description,
            "a system on one road (a vehicle, a road per wheel: systems.vehicle.simulate)",
        )  # fmt: skip
    if times is None and x0 is None:
        from ..simulate import check_sine_steps

        def steps_to(t):  # the same run over the first periods (not measured again)
            res = _simulate(sys, excitation, t, options)
            st = res.stats  # attempts: accepted and rejected steps count against the budget
            return st.get("steps", 0) + st.get("rejected", 0) if res.method == "adaptive" else 0

        check_sine_steps(steps_to, excitation, T, r, int(max_steps))
    road = excitation.prepared(T)  # the segments, built once per input and horizon
    segs = road.segments
    x1 = road.initial_road
    if x0 is None:
        fixed = {}
        du, ds = excitation.initial_displacements
        if sys.kind == "quarter_car":
            fixed = {"wheel": du, "body": ds}
        elif sys.kind == "base_excited":
            fixed = {"body": ds}
        y = _initial(sys, fixed, x1)
    else:
        y = np.array(x0, dtype=float)
        if y.shape != (sys.n_states,):
            raise ParameterError("x0", x0, f"{sys.n_states} states")
    if metrics_only:
        ts = np.array([T])
        ts_key = ("end",)  # what fixes the samples, with the horizon
    elif times is None:
        ts = _sample_times(T, options.sample_rate)
        ts_key = ("rate", float(options.sample_rate))
    else:
        ts = np.array(times, dtype=float)
        if (
            ts.ndim != 1
            or ts.size < 1
            or not np.all(np.isfinite(ts))
            or np.any(np.diff(ts) <= 0)
            or ts[0] < 0
            or ts[-1] > T
        ):
            raise ParameterError(
                "times", "array", f"increasing finite sample times in [0, horizon={T:g}] s"
            )
        ts_key = ("times", ts.tobytes())
    user = sys
    if ride is None:
        ride = sys.kind == "quarter_car" and times is None and x0 is None
    if ride:
        # the ride metrics, integrated as observer states
        sys = sys.info.get("ride_system") or _ride_system(sys)
        y = np.concatenate([y, sys.x0_template[y.size :]])
    piecewise_linear = road.piecewise_linear
    if method == "exact" and not (sys.linear and piecewise_linear):
        raise ParameterError(
            "method",
            "exact",
            "'adaptive' here: exact steps need a linear system and a piecewise-linear road",
        )
    # exact steps pay one matrix exponential per distinct step length: where the road's
    # edges and the samples make many (incommensurate grids) the adaptive steps are faster
    plan = None
    regime = _NO_REGIME
    exact_ok = sys.linear and piecewise_linear
    if sys.observers and exact_ok:
        if "observer_system" not in sys.info:
            sys.info["observer_system"] = _observer_system(sys, _linear_ss(sys))
        exact_ok = sys.info["observer_system"] is not None
        if method == "exact" and not exact_ok:
            raise ParameterError(
                "method", "exact", "'auto' or 'adaptive' here: an observer reads what the "
                "exact steps do not give (an undefined output or a nonlinear observer)",
            )  # fmt: skip
    ts_walk, pick = ts, None  # the break points of exact steps: the samples, and for
    if sys.n_states and exact_ok and method in ("auto", "exact"):  # observers a grid
        walk, pick, plan = _walk_plan(sys, road, T, ts, ts_key)
        if walk is not None:
            ts_walk = walk
        if method == "auto" and plan[0].size > EXACT_MAX_STEP_SIZES:
            plan = None
    elif sys.n_states and method == "auto" and _regime_pays(sys, segs, T):
        regime = _regime_tables_for(sys, segs, T, ts)
    jump_tol = road.jump_tolerance
    jumps = np.zeros(len(segs))
    # road velocity jumps (at t = 0 from rest, where segments meet) pass impulses
    # through the inertances attached to the road
    vjumps = np.zeros(len(segs))
    vjump_tol = road.velocity_jump_tolerance if sys.info.get("road_inertances") else math.inf
    v_before = road.initial_velocity if x0 is None else math.nan
    U = None
    if sys.n_states == 0:  # everything prescribed (a rig with a parallel network)
        Y = np.empty((ts.size, 0))
        stats = {"steps": 0}
        meth = "exact" if method == "exact" else "adaptive"
    elif plan is not None:
        Y, U, stats = _exact(
            sys, _linear_ss(sys), plan, segs, y, x1, T, ts_walk, jumps, jump_tol, v_before,
            vjump_tol, vjumps,
        )  # fmt: skip
        if pick is not None:
            Y, U = Y[pick], U[pick]
        meth = "exact"
    else:
        atol = options.atol_factor * np.maximum(sys.state_scales, 1e-12)
        Y = np.empty((ts.size, sys.n_states))
        st = np.zeros(5, dtype=np.int64)
        XE, XG, keys, thr, idx, cls, *lev = regime
        status, k = _integrate.integrate(
            sys.itab, sys.ftab, segs, y, x1, T, r, atol, sys.imp_unit, sys.jump_ok, jump_tol,
            ts, Y, st, jumps, int(max_steps), v_before, vjump_tol, vjumps, XE, XG, keys, thr,
            idx, cls, EXACT_STEP_QUANTUM * max(T, 1.0), options.step_control,
            lev[0] if lev else None, lev[1] if len(lev) > 1 else None,
        )  # fmt: skip
        if status != _integrate.OK:
            raise _failure(sys, status, max_steps)
        stats = {
            "steps": int(st[0]), "rejected": int(st[1]), "rhs_calls": int(st[2]),
            "events": int(st[3]), "exact_steps": int(st[4]),
        }  # fmt: skip
        meth = "adaptive"
    metrics = None
    not_finite: dict = {}
    hit = np.flatnonzero(jumps)  # the road steps taken
    nb = sys.info["base"].n_states if "base" in sys.info else sys.n_states
    observed = dict(zip((o.name for o in sys.observers), y[nb:].tolist(), strict=True))
    load = None
    if sys.kind == "quarter_car":
        car = sys.info["car"]
        load = (car["sprung_mass"] + car["unsprung_mass"]) * car["gravity"]
    if sys is not user:  # the ride observers: the metrics
        from .observers import ride_metrics

        metrics = ride_metrics(observed, T, load)
        if hit.size:
            jb = sys.info["velocity_jump_per_step"].get("body", 0.0)
            jw = sys.info["velocity_jump_per_step"].get("wheel", 0.0)
            if abs(jb) > 1e-12 * abs(jw):
                why = (
                    "not finite: the body velocity jumps at the road steps (an inertance "
                    "between wheel and body), so the body acceleration has a Dirac part; "
                    "smooth the edges (bump(edge=...), --edge)"
                )
                not_finite.update(rms_body_acc=why, peak_body_acc=why)
            down = [(float(segs[i, 0]), float(jumps[i])) for i in hit if jumps[i] < 0]
            if down and sys.info.get("tyre_pulls", True):
                not_finite["min_tyre_force"] = tyre_dirac_reason(down)
            for k in not_finite:
                metrics[k] = None
            if "min_tyre_force" in not_finite:
                metrics["tyre_lift_off"] = True  # the contact force demanded goes below zero
    steps = tuple((float(segs[i, 0]), float(jumps[i])) for i in hit if segs[i, 0] < T)
    if np.any(vjumps):
        stats["road_velocity_jumps"] = int(np.count_nonzero(vjumps))
    outs = _Outputs(functools.partial(_sampled_outputs, sys, user, ts, Y, U, segs, load))
    return CoreResult(
        system=user, time=ts, states=Y[:, : user.n_states].copy(), outputs=outs,
        metrics=metrics, method=meth, stats=stats, road_steps=steps, not_finite=not_finite,
        observed=observed,
    )  # fmt: skip


class _Outputs(MutableMapping):
    """The sampled outputs of a :class:`CoreResult` by name, computed on first access
    (a study that reads the states or the metrics only does not pay for them); a plain
    dict once copied or pickled."""

    __slots__ = ("_make", "_data")

    def __init__(self, make) -> None:
        self._make = make
        self._data = None

    def _dict(self) -> dict:
        if self._data is None:
            self._data = self._make()
            self._make = None
        return self._data

    def __getitem__(self, name):
        return self._dict()[name]

    def __setitem__(self, name, value) -> None:
        self._dict()[name] = value

    def __delitem__(self, name) -> None:
        del self._dict()[name]

    def __iter__(self):
        return iter(self._dict())

    def __len__(self) -> int:
        return len(self._dict())

    def __repr__(self) -> str:
        return repr(self._dict())

    def __reduce__(self):
        return (dict, (self._dict(),))


def _sampled_outputs(sys, user, ts, Y, U, segs, load) -> dict:
    """The outputs of a run of ``sys`` (``user`` with the ride observers, or itself) at
    the samples ``ts``: states ``Y`` (every state of ``sys``), the road ``U`` (X1, X1',
    X1'') where exact steps gave it (then C x + D u), else from the right-hand side (in
    a linear regime: C x + D u of the regime); for a quarter car the derived outputs,
    for a rig the force at the drive."""
    O = None
    if U is not None:
        ss = _linear_ss(sys)
        O = _linear_outputs(sys, ss, Y[:, : ss[0].shape[0]], U)
    reg = _regime_system(sys) if O is None and sys.n_states else None
    if reg is not None:  # C x + D u where every element sits in its linear regime
        _, _, gx, gu, thr, _, C, D, undefined, aug = reg
        if aug is not None:  # over the base system's states
            C = np.hstack([C, np.zeros((C.shape[0], sys.n_states - C.shape[1]))])
            gx = np.hstack([gx, np.zeros((gx.shape[0], sys.n_states - gx.shape[1]))])
        O = np.empty((len(sys.output_names), ts.size))
        _integrate.regime_outputs(ts, Y, segs, sys.itab, sys.ftab, C, D, undefined, gx, gu,
                                  thr, O)  # fmt: skip
    if O is None:
        O = np.empty((ts.size, len(sys.output_names)))
        _integrate.outputs_many(ts, Y, segs, sys.itab, sys.ftab, O)
        O = np.ascontiguousarray(O.T)
    outs = {n: O[j] for j, n in enumerate(sys.output_names)}
    if sys.kind == "quarter_car":
        car = sys.info["car"]
        outs["body_acc"] = outs["body.a"]
        outs["deflection"] = outs["body.x"] - outs["wheel.x"]
        outs["tyre_force"] = (
            outs["tyre.force"] if "tyre.force" in outs
            else outs["tyre_k.force"] + outs.get("tyre_c.force", 0.0)
        )  # fmt: skip
        outs["tyre_grip"] = car["tyre_stiffness"] * (outs["wheel.x"] - outs["road.x"]) / load
    if sys is not user:  # the Wk-weighted body acceleration, from the filter's states
        from ..metrics import wk_state_space

        _, _, cw, dw = wk_state_space()
        names = sys.state_names
        z = Y[:, [names.index(f"ride.wk.z{i}") for i in range(cw.size)]]
        outs["body_acc_wk"] = z @ cw + float(dw) * outs["body_acc"]
    if sys.kind == "rig":
        outs["force"] = sum(outs[f"{n}.force"] for n in _drive_elements(sys))
    return outs


def _walk_plan(sys, road, T, ts, ts_key):
    """(break points of exact steps, or None where they are the samples ``ts``; the
    rows of the samples among them, or None; the plan of :func:`_exact_plan`), kept on
    the system for the last :data:`WALK_PLANS_KEPT` (road, horizon, samples) by
    content: a run of one road again (a benchmark, a study over seeds of one car) plans
    its steps once."""
    kept = _memo(sys).setdefault("walk_plans", {})
    key = (road.key, float(T), ts_key)
    got = kept.get(key)
    if got is None:
        walk = ts
        if sys.observers:  # panels of the observers' quadrature, several to a step
            step = min(EXACT_OBSERVER_LONGEST, EXACT_OBSERVER_PANELS * _observer_panel(sys))
            walk = _observer_grid(ts, T, step)
        plan = _exact_plan(sys, road.segments, T, walk)
        got = (None, None, plan) if walk is ts else (walk, np.searchsorted(walk, ts), plan)
        if len(kept) >= WALK_PLANS_KEPT:
            kept.pop(next(iter(kept)))
        kept[key] = got
    return got


#: the plans of exact steps (:func:`_walk_plan`) of this many (road, horizon, samples)
#: are kept on a system
WALK_PLANS_KEPT = 8


def _ride_system(sys):
    """The quarter car with its ride observers (:func:`.observers.ride`), kept on it."""
    from .observers import ride, with_observers

    out = with_observers(sys, ride(sys))
    sys.info["ride_system"] = out
    return out


def _blockers(sys) -> str:
    """The elements on the road a road step has no finite response through, in words."""
    names = sys.info["road_step_blockers"]  # not empty where a step is refused (build)
    return "the element" + ("s " if len(names) > 1 else " ") + ", ".join(names) + " on the road"


def _failure(sys, status: int, max_steps: int) -> ConvergenceError:
    """The error of an adaptive integration that stopped with ``status``."""
    why = {
        _integrate.TOO_MANY_STEPS: f"more than max_steps={max_steps} steps",
        _integrate.STEP_TOO_SMALL: "the step size fell below round-off",
        _integrate.NOT_FINITE: "the solution is not finite (unstable parameters?)",
        _integrate.ROAD_STEP: "the road steps, and a step has no finite response "
        f"through {_blockers(sys)}: smooth the edges (bump(edge='ramp', edge_width=...))",
        _integrate.BALANCE_FAILED: "a force balance of the massless nodes could not be solved",
    }[status]
    return ConvergenceError(f"{sys.description}: {why}")


class DriveRuns:
    """Many runs of rigs on one measured drive, as an identification makes them.

    The drive's segments are built once, from its first sample: a run starts there,
    from a state the caller gives (the rig's state at the first sample), and returns
    only the force the rig applies, at the first ``m`` samples. The integration is that
    of :meth:`System.simulate` (adaptive Dormand-Prince, ``atol`` = ``rtol`` x the
    state scales); the drive has no jump (it starts where it is). Used by
    :func:`inerterlab.identify.identify` for every device the rig represents.

    >>> import numpy as np
    >>> from inerterlab.excitation import drive_series
    >>> t = np.linspace(0.0, 1.0, 101)
    >>> runs = DriveRuns(drive_series(t, 0.01 * np.sin(t), 0.01 * np.cos(t)))
    >>> f = runs.force(rig("k | c", {"k": 1e4, "c": 100.0}), np.empty(0))
    >>> bool(abs(f[-1] - (1e4 * 0.01 * np.sin(1.0) + 1.0 * np.cos(1.0))) < 1e-9)
    True
    """

    def __init__(self, drive) -> None:
        from ..excitation import DriveSeries

        if not isinstance(drive, DriveSeries):
            raise ParameterError("drive", drive, "a DriveSeries (excitation.drive_series)")
        t = drive.time
        segs = drive.segments(float(t[-1]))
        self.time = t
        self.segments = np.ascontiguousarray(segs[segs[:, 0] >= t[0]])
        self.start = float(drive.displacement[0])

    def force(self, sys: System, x0, m: int | None = None, *,
              options: SimulationOptions = DEFAULT_OPTIONS, **option_values) -> np.ndarray:  # fmt: skip
        """Force [N] the rig ``sys`` applies at the first ``m`` samples (all by
        default), starting from the state ``x0`` at the first sample. ``options`` as
        :meth:`System.simulate` (its tolerances, step control and ``max_steps``; the
        samples are the drive's)."""
        if sys.kind != "rig":
            raise ParameterError("sys", sys.kind, "a rig (systems.rig)")
        options = _options(options, option_values)
        options.warn_ignored("DriveRuns.force", "method", "sample_rate", "fixed_method")
        rtol = options.rtol
        max_steps = options.max_steps
        n = self.time.size if m is None else int(m)
        if not 1 <= n <= self.time.size:
            raise ParameterError("m", m, f"a sample count in [1, {self.time.size}]")
        ts = self.time[:n]
        segs = self.segments
        Y = np.empty((n, sys.n_states))
        if sys.n_states:
            y = np.array(x0, dtype=float)
            if y.shape != (sys.n_states,):
                raise ParameterError("x0", x0, f"{sys.n_states} states")
            atol = options.atol_factor * np.maximum(sys.state_scales, 1e-12)
            st = np.zeros(5, dtype=np.int64)
            nseg = len(segs)
            status, _ = _integrate.integrate(
                sys.itab, sys.ftab, segs, y, self.start, float(ts[-1]), rtol, atol,
                sys.imp_unit, sys.jump_ok, math.inf, ts, Y, st, np.zeros(nseg),
                int(max_steps), math.nan, math.inf, np.zeros(nseg), *_NO_REGIME, 1.0,
                options.step_control,
            )  # fmt: skip
            if status != _integrate.OK:
                raise _failure(sys, status, max_steps)
        memo = _memo(sys)
        if "drive_force_plan" not in memo:
            memo["drive_force_plan"] = _drive_force_plan(sys)
        idx, direct = memo["drive_force_plan"]
        if direct:
            out = np.empty(n)
            _integrate.drive_forces(ts, Y, segs, sys.itab, sys.ftab, idx, out)
            return out
        O = np.empty((n, len(sys.output_names)))
        _integrate.outputs_many(ts, Y, segs, sys.itab, sys.ftab, O)
        return O[:, 3 * len(sys.node_names) + idx].sum(axis=1)


def _drive_force_plan(sys) -> tuple[np.ndarray, bool]:
    """(indices of a rig's drive elements, whether their forces can be read from the
    states alone: springs, dampers and friction whose ends are the drive, the ground or
    nodes with displacement and velocity states)."""
    names = _drive_elements(sys)
    idx = np.array([sys.element_names.index(e) for e in names], dtype=np.int64)
    direct = True
    for e in idx:
        _, el, t, b = sys.info["edges"][e]
        ends_ok = all(sys.node_types[i] in (GROUND, ROAD, DYN) for i in (t, b))
        law = kernel_law(el)
        direct &= ends_ok and (law.elastic or law.holds_velocity or law.bounded)
    return idx, bool(direct)


def _observer_grid(ts, T, step):
    """The samples ``ts`` with every gap of [0, T] between them longer than ``step``
    cut into equal pieces no longer than that (the break points of exact steps with
    observers; ``ts`` itself where none is longer)."""
    ends = np.r_[0.0, ts, T]
    gaps = np.diff(ends)
    cuts = np.ceil(gaps / step * (1.0 - 1e-12)).astype(np.int64)
    if np.all(cuts <= 1):
        return ts
    extra = [
        ends[i] + gaps[i] * np.arange(1, c) / c for i, c in enumerate(cuts) if c > 1
    ]
    return np.union1d(ts, np.concatenate(extra))


def _observer_share(sys) -> float:
    """The part of the longest panel :data:`EXACT_OBSERVER_PANEL` that ``sys``'s
    observers allow: 1, or :data:`EXACT_FOURTH_POWER_SHARE` with a fourth power among
    them."""
    share = sys.info.get("observer_share")
    if share is None:
        fourth = any(_kernel_kind(o) == _kernel.OBS_FOURTH for o in sys.observers)
        share = sys.info["observer_share"] = EXACT_FOURTH_POWER_SHARE if fourth else 1.0
    return share


def _observer_panel(sys) -> float:
    """The longest quadrature panel [s] of the observers of ``sys`` (a linear system) in
    an exact step: :data:`EXACT_OBSERVER_PANEL` x :func:`_observer_share`, and at most
    :data:`EXACT_OBSERVER_PHASE` radians of the base system's fastest mode."""
    rate = _regime_rate(sys.info["base"], _linear_ss(sys)[0])
    return min(_observer_share(sys) * EXACT_OBSERVER_PANEL, EXACT_OBSERVER_PHASE / max(rate, 1e-300))


def _panels(sizes, panel: float) -> int:
    """Panels per exact step: enough for the longest of ``sizes`` [s] at ``panel`` [s]
    each (at least one)."""
    longest = float(np.max(sizes, initial=0.0))
    return max(1, math.ceil(longest / panel * (1.0 - 1e-9)))


def _exact_plan(sys, segs, T, ts):
    """The step lengths of exact steps on this road and these samples, as indices into
    their distinct values (rounded to :data:`EXACT_STEP_QUANTUM` x max(T, 1 s): a step
    that long shifts a state by less than 1e-12 of its change over 1 s; break points
    closer than half that, a sample and a segment edge apart by round-off, take no
    step). Kept for the last few (segments, horizon, break points) by content: the walk
    that plans reads nothing else (the system's tables only to pick its compiled code),
    so the cars of a sweep share the plan of each input (shared arrays, not written:
    writable, as the kernels' other tables, so that the exact walk keeps one compiled
    signature)."""
    segs = np.ascontiguousarray(segs, float)
    ts = np.ascontiguousarray(ts, float)
    if segs.nbytes + ts.nbytes > EXACT_PLAN_KEY_BYTES:  # a long road: planned each time
        return _exact_plan_of(sys, segs, T, ts)
    key = (segs.shape, segs.tobytes(), float(T), ts.tobytes())
    got = _EXACT_PLANS.get(key)
    if got is None:
        got = _exact_plan_of(sys, segs, T, ts)
        if len(_EXACT_PLANS) >= EXACT_PLANS_KEPT:
            _EXACT_PLANS.pop(next(iter(_EXACT_PLANS)))
        _EXACT_PLANS[key] = got
    return got


#: the plans of :func:`_exact_plan` kept in a process (by segments, horizon, samples)
EXACT_PLANS_KEPT = 32
#: ... only for segment tables and break points up to this size [bytes] together
EXACT_PLAN_KEY_BYTES = 1 << 20
_EXACT_PLANS: dict = {}


def _exact_plan_of(sys, segs, T, ts):
    """:func:`_exact_plan`, computed (a dry walk of the compiled exact steps)."""
    hs = np.empty(len(segs) + ts.size + 1)
    z = np.empty(0)
    q = EXACT_STEP_QUANTUM * max(T, 1.0)
    _, m = _integrate.exact_walk(
        False, segs, ts, T, z, 0.0, math.nan, math.inf, math.inf, True, z, sys.itab, sys.ftab,
        0.5 * q, hs, np.empty(0, np.int64), np.empty((0, 0, 0)), np.empty((0, 0)),
        np.empty((0, 0)), np.empty((0, 0)), np.empty((0, 3)), np.empty(0), np.empty(0),
        np.empty(0, np.int64), *_NO_OBSERVERS,
    )  # fmt: skip
    k = np.rint(hs[:m] / q).astype(np.int64)
    if m and k.min() == k.max():  # one length (samples on the segment edges): no sort
        return k[:1] * q, np.zeros(m, np.int64)
    keys, idx = np.unique(k, return_inverse=True)
    return keys * q, idx.astype(np.int64)



# ---------------------------------------------------------------------------------------
# exact steps of a nonlinear system in its linear regimes

#: no exact steps in linear regimes (the arguments of :func:`._integrate.integrate`)
_NO_REGIME = (
    np.empty((0, 0, 0, 0)), np.empty((0, 0, 0)), np.empty(0, np.int64), np.empty(0),
    np.empty(0, np.int64), np.empty(0, np.int64),
)  # fmt: skip
#: at most this many sine frequencies get tables of exact steps in one run
REGIME_MAX_CLASSES = 4
#: ``auto`` takes no exact steps in the linear regimes where the road stops driving the
#: car within this fraction of the horizon (:func:`_regime_pays`)
REGIME_FREE_DECAY = 0.5


def _regime_pays(sys, segs, T) -> bool:
    """Whether ``auto`` takes exact steps in the linear regimes of ``sys`` on the road
    ``segs`` over the horizon T: where the system has such regimes, and, where it has a
    nonlinear element (a regime it leaves), where the road drives it past
    :data:`REGIME_FREE_DECAY` of the horizon: the road's last segment that starts
    before T is a sine, a measured drive or several roads, or a constant rate that
    starts past that fraction (a sampled road's last sample). Otherwise (a drop, a bump,
    a ramp) the car decays freely over most of the horizon, its flywheel leaves
    saturation for good in the first transient, and the exact steps there replace a few
    dozen adaptive steps (0.1-0.3 ms of the `afw` car's 10 s) against 1-2 ms to build
    their tables for a new car (docs/decisions.md, stop 67). A linear system sits in
    its regime throughout: exact steps always."""
    if not sys.linear:  # (the road first: a sweep's drops build no regime system)
        i = max(int(np.searchsorted(segs[:, 0], T, side="left")) - 1, 0)
        if segs[i, 2] == 0.0 and segs[i, 0] <= REGIME_FREE_DECAY * T:
            return False
    return _regime_system(sys) is not None


def _regime_system(sys):
    """The system in the linear regime of every nonlinear element (a linear system: as
    it is), or None where one has none: (A, B, guard rows over (x, u) as (G_x, G_u),
    thresholds, element indices, C, D, the outputs it leaves undefined, and for a system
    with observers its augmented system (:func:`_augment`: A, B, ia, Sx, Su), else
    None); all but the last over the base system's states. Cached on the system."""
    if "regime" in sys.info:
        return sys.info["regime"]
    found = None
    if sys.observers:  # the base system's regime, with the observers
        reg = _regime_system(sys.info["base"])
        aug = None if reg is None else _augment(sys, reg[0], reg[1], reg[6], reg[7], reg[8])
        sys.info["regime"] = None if aug is None else (*reg[:9], aug)
        return sys.info["regime"]
    regimes = [(e, el.linear_regime()) for e, el in enumerate(sys.elements) if _nonlinear(el)]
    if all(r is not None for _, r in regimes) and sys.n_states:
        itab = sys.itab.copy()
        ftab = sys.ftab.copy()
        eo = int(sys.itab[_kernel.I_ELEM])
        for e, (lin, _, _) in regimes:
            b = eo + ELEM_W * e
            itab[b] = lin.code
            o = int(itab[b + 3])
            ftab[o : o + NPAR] = lin.row()
        itab.setflags(write=False)  # typed as the system's own: no second compilation
        ftab.setflags(write=False)
        A, B, C, D = _state_space(sys, itab, ftab)
        out0 = np.empty(len(sys.output_names))
        u0 = np.zeros(_kernel.road_layout_of(itab)[1])
        _kernel.outputs(0.0, np.zeros(sys.n_states), u0, itab, ftab, out0)
        names = list(sys.output_names)
        gx, gu, thr, idx = [], [], [], []
        for e, (_, arg, a) in regimes:
            b = eo + ELEM_W * e
            top, bot = int(sys.itab[b + 1]), int(sys.itab[b + 2])
            sfx = ".v" if arg == "velocity" else ".x"
            it = names.index(sys.node_names[top] + sfx)
            ib = names.index(sys.node_names[bot] + sfx)
            gx.append(C[it] - C[ib])
            gu.append(D[it] - D[ib])
            thr.append(a)
            idx.append(e)
        n = sys.n_states
        found = (
            A, B, np.array(gx, float).reshape(-1, n), np.array(gu, float).reshape(-1, 3),
            np.array(thr, float), np.array(idx, np.int64), C, D, np.isnan(out0), None,
        )  # fmt: skip
    sys.info["regime"] = found
    return found


#: exact steps in a linear regime between break points far apart (or past a break
#: point the regime does not reach): lengths H, H/2, ..., H/2^(REGIME_LEVELS - 1) with
#: H = min(REGIME_LEVEL_MAX, REGIME_LEVEL_PHASE / the fastest rate of the regime system
#: and the road), so a guard's cubic through the ends of a step follows it closely; no
#: levels where H would be below REGIME_LEVEL_MIN [s]
REGIME_LEVELS = 4
REGIME_LEVEL_MAX = 0.01
REGIME_LEVEL_MIN = 1e-4
REGIME_LEVEL_PHASE = 0.5


def _regime_rate(sys, A) -> float:
    """The largest |eigenvalue| [1/s] of the regime system's matrix A (cached)."""
    if "regime_rate" not in sys.info:
        sys.info["regime_rate"] = float(np.max(np.abs(np.linalg.eigvals(A)), initial=0.0))
    return sys.info["regime_rate"]


#: the regime tables of this many (road, horizon, samples) are kept on a system
REGIME_TABLES_KEPT = 8


def _regime_tables_for(sys, segs, T, ts):
    """:func:`_regime_tables` on the plan of exact steps for these break points, kept on
    the system for the last :data:`REGIME_TABLES_KEPT` (road, horizon, samples) by
    content: a study that runs one system on a few inputs many times (a benchmark, a
    fit) builds them once (about 1 ms of Python each)."""
    kept = sys.info.setdefault("regime_tables", {})
    key = (segs.tobytes(), float(T), ts.tobytes())
    got = kept.get(key)
    if got is None:
        got = _regime_tables(sys, segs, T, ts, _exact_plan(sys, segs, T, ts))
        if len(kept) >= REGIME_TABLES_KEPT:
            kept.pop(next(iter(kept)))
        kept[key] = got
    return got


def _regime_tables(sys, segs, T, ts, plan):
    """Arguments of :func:`._integrate.integrate` for exact steps while every nonlinear
    element sits in its linear regime (:meth:`ElementBase.linear_regime`), one matrix
    exponential per step length and per sine frequency of the road (0 for its linear
    segments): (XE, XG, keys, thresholds, elements, classes, level rows). The lengths:
    those between break points (``plan``, as for a linear system, where it has at most
    :data:`EXACT_MAX_STEP_SIZES`) and the levels (see :data:`REGIME_LEVELS`);
    :data:`_NO_REGIME` where the system has no such regime. With observers, the last
    entry is ``xo`` of :func:`._integrate._advance` (their tables over the augmented
    state for steps of m quadrature panels, and per class the longest step: m panels of
    at most :data:`EXACT_OBSERVER_PANEL` (x :func:`_observer_share`) and
    :data:`EXACT_OBSERVER_PHASE` over the class's sine frequency and the base system's
    fastest rate)."""
    reg = _regime_system(sys)
    if reg is None:
        return _NO_REGIME
    q = EXACT_STEP_QUANTUM * max(T, 1.0)
    sizes = plan[0] if plan is not None and plan[0].size <= EXACT_MAX_STEP_SIZES else np.empty(0)
    aug = reg[9]
    w = np.where(segs[:, 2] == 1.0, segs[:, 6], 0.0)
    ws = np.unique(w[segs[:, 2] != 2.0])[:REGIME_MAX_CLASSES]
    A, B, gx, gu, thr, idx = reg[:6]
    # the levels follow the motion (the base system's rates), not the observers' filters
    base = sys.info.get("base", sys)
    rate_x = _regime_rate(base, A)
    longest = REGIME_LEVEL_MAX
    if aug is not None:
        # with observers: steps of several quadrature panels where the break points are
        # far apart (no longer than the longest gap between them, nor than a panel: with
        # samples every 1 ms, one panel of the first, as before)
        panel = _observer_share(sys) * EXACT_OBSERVER_PANEL
        gap = float(np.max(plan[0])) if plan is not None and plan[0].size else T
        longest = min(EXACT_OBSERVER_LONGEST, EXACT_OBSERVER_PANELS * panel, max(gap, panel))
        sizes = sizes[sizes <= longest * (1.0 + 1e-9)]
    cls = np.full(len(segs), -1, np.int64)
    for c, wc in enumerate(ws):
        cls[(w == wc) & (segs[:, 2] != 2.0)] = c
    rate = max(rate_x, float(np.max(np.abs(ws), initial=0.0)))
    top = longest if rate == 0.0 else min(longest, REGIME_LEVEL_PHASE / rate)
    nlev = REGIME_LEVELS
    if aug is not None and top > panel:
        # steps of several panels: levels down to those of a one-panel top, so a step
        # that would leave the regime hands over to Dormand-Prince as close to the exit
        nlev += math.ceil(math.log2(top / panel))
    levels = top / 2.0 ** np.arange(nlev) if top >= REGIME_LEVEL_MIN else np.empty(0)
    lev_keys = np.rint(levels / q).astype(np.int64)
    keys = np.unique(np.r_[np.rint(sizes / q).astype(np.int64), lev_keys])
    keys = keys[keys > 0]
    if keys.size == 0:
        return _NO_REGIME
    xlev = np.searchsorted(keys, lev_keys).astype(np.int64)  # longest first
    hs = (keys * q).tobytes()
    if aug is None:
        XE, XG, *_ = _regime_exponentials(
            A.shape[0], A.tobytes(), B.tobytes(), gx.tobytes(), gu.tobytes(), tuple(ws.tolist()),
            hs, b"", b"", 1,
        )  # fmt: skip
        return XE, XG, keys, thr, idx, cls, xlev
    # each step's panels: as many as the longest step needs at the first panel length;
    # each class's panel at most EXACT_OBSERVER_PHASE of its sine and of the system's
    # modes, which bounds the steps of a fast class (m of its panels)
    m = _panels(keys * q, panel)
    fast = np.maximum(np.abs(ws), rate_x)
    cap = np.minimum(longest, m * np.minimum(panel, EXACT_OBSERVER_PHASE / np.maximum(fast, 1e-300)))
    ia, rows, sref, key = _regime_read(sys, reg)
    XE, XG, SR, TR = _regime_exponentials(*key[:5], tuple(ws.tolist()), hs, *key[5:], m)
    gw, gxs = _nodes(m)
    xo = (ia, SR, rows, gw, gxs, cap, TR, sref)
    return XE, XG, keys, thr, idx, cls, xlev, xo


def _regime_read(sys, reg):
    """What the regime tables of a system with observers read of it, fixed by the system
    and kept on it: (ia, the rows of :func:`_read_rows`, :func:`_signal_refs`, the
    system's part of the key of :func:`_regime_exponentials`: n, A, B, the guard rows
    over the augmented state, gu, and the distinct signals' rows)."""
    got = sys.info.get("regime_read")
    if got is None:
        A, B, ia, Sx, Su = reg[9]
        gx, gu = reg[2], reg[3]
        rows, nu = _read_rows(sys, Sx, Su)
        own = rows[:nu, 0]
        gx = np.hstack([gx, np.zeros((gx.shape[0], A.shape[0] - gx.shape[1]))])
        key = (
            A.shape[0], A.tobytes(), B.tobytes(), gx.tobytes(), gu.tobytes(),
            Sx[own].tobytes(), Su[own].tobytes(),
        )  # fmt: skip
        got = (ia, rows, _signal_refs(rows, nu, Sx.shape[0]), key)
        sys.info["regime_read"] = got
    return got


@lru_cache(maxsize=16)
def _regime_exponentials(n, a, b, gx, gu, ws, sizes, sx, su, m):
    """(XE, XG, SR, TR): XE[c, j] = the first n rows of exp(M_c h_j), XG[c] the guard
    rows and their rates over z = (x, e) (see :mod:`._integrate`), for the sine
    frequencies ws; SR[c] the observed signals' rows ``sx``, ``su`` (over x and u = Gin
    e) at the points theta = :func:`_points` (m)[p] of a step of m panels, over z at its
    start, in the layout of :func:`_point_tables`, and TR[c] their Taylor rows
    (:func:`_step_tables` of z' = M_c z; both empty without observers)."""
    A = np.frombuffer(a).reshape(n, n)
    B = np.frombuffer(b).reshape(n, 3)
    Gx = np.frombuffer(gx).reshape(-1, n)
    Gu = np.frombuffer(gu).reshape(-1, 3)
    Sx = np.frombuffer(sx).reshape(-1, n)
    Su = np.frombuffer(su).reshape(-1, 3)
    hs = np.frombuffer(sizes)
    ng = Gx.shape[0]
    th = _points(m) if Sx.shape[0] else np.empty(0)
    XE = np.empty((len(ws), hs.size, n, n + 3))
    XG = np.empty((len(ws), 2 * ng, n + 3))
    # the point rows laid out for the integrator (:func:`_point_layout`) per length as
    # they are kept, so each is copied once here
    SR = np.empty((len(ws), hs.size, n + 3, th.size * Sx.shape[0]))
    TR = []
    for c, w in enumerate(ws):
        Gin = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-w * w, 0.0, 0.0]])  # u = Gin e
        M = np.zeros((n + 3, n + 3))
        M[:n, :n] = A
        M[:n, n:] = B @ Gin
        M[n, n + 1] = 1.0
        M[n + 1, n] = -w * w
        rows = np.hstack([Gx, Gu @ Gin])
        XG[c, :ng] = rows
        XG[c, ng:] = rows @ M
        S = np.hstack([Sx, Su @ Gin])
        XE[c], items = _length_tables(M, S, hs, m if th.size else 0, n)
        if th.size:
            for j, (sr, _) in enumerate(items):
                SR[c, j] = sr
        TR.append([tr for _, tr in items])
    # padded to one table (the integrator passes it read-only, as the exact walk's)
    K = max((t.shape[1] for trs in TR for t in trs), default=0)  # no class: none
    TRs = np.zeros((len(ws), hs.size, Sx.shape[0], K, n + 3))
    for c, trs in enumerate(TR):
        for j, t in enumerate(trs):
            TRs[c, j, :, : t.shape[1]] = t
    return XE, XG, SR, TRs


#: the tables of this many (matrix, signals, panels, step length) are kept in a process
LENGTH_TABLES_KEPT = 256
_LENGTH_TABLES: dict = {}


def _length_tables(M, S, hs, m, n):
    """For the steps of lengths ``hs`` of z' = M z: the first n rows of exp(M h) [j],
    and per length (with observers, m panels, m > 0) the signal rows S at the points of
    a step (:func:`_step_tables`) in the integrator's layout (:func:`_point_layout`:
    [q, p nu + r]; None without) and the Taylor rows ([r, k, q], its own number of
    terms). Each length's tables are kept by content (M, S, m, h and its family's
    shortest length, :func:`_families`) for the last :data:`LENGTH_TABLES_KEPT`: a new
    road on a car computes only its new lengths (a bump after a drop: the bump's own;
    the regime levels are shared). A family with a length not kept is computed whole, so
    each length's tables depend on the length and its family's shortest length only,
    not on what was kept."""
    mk, sk = M.tobytes(), S.tobytes()
    base, shift = _families(hs)
    keys = [(mk, sk, m, n, h, b) for h, b in zip(hs.tolist(), hs[base].tolist(), strict=True)]
    got = {k: _LENGTH_TABLES[k] for k in keys if k in _LENGTH_TABLES}
    miss = [j for j, k in enumerate(keys) if k not in got]
    if miss:
        new = set(base[miss].tolist())  # the families with a new length
        sel = np.array([j for j, b in enumerate(base.tolist()) if b in new], np.int64)
        hm = hs[sel]
        fam = (np.searchsorted(sel, base[sel]), shift[sel])  # whole families: bases kept
        full = _expm_lengths(M, hm, fam)
        tr, kj, sr = _step_tables(M, S, hm, m, full, fam)
        N = M.shape[0]
        for i, j in enumerate(sel.tolist()):
            rows = None
            if sr is not None:  # [q, p nu + r]
                rows = np.ascontiguousarray(sr[:, i].transpose(2, 0, 1)).reshape(N, -1)
            item = (full[i, :n].copy(), rows, tr[i, :, : kj[i]].copy())
            for x in item:
                if x is not None:
                    x.setflags(write=False)
            got[keys[j]] = item
            if len(_LENGTH_TABLES) >= LENGTH_TABLES_KEPT:
                _LENGTH_TABLES.pop(next(iter(_LENGTH_TABLES)))
            _LENGTH_TABLES[keys[j]] = item
    items = [got[k] for k in keys]
    XE = np.array([it[0] for it in items]).reshape(hs.size, n, M.shape[0])
    return XE, [(it[1], it[2]) for it in items]


def _families(hs):
    """Each length's family among ``hs``, the lengths a power of two apart (equal
    mantissas: the regime levels H, H/2, ...): the index of its shortest member, and the
    length's shift e (the length is that member's 2^e)."""
    parts = [math.frexp(h) for h in hs.tolist()]
    first: dict = {}
    for j, (mv, e) in enumerate(parts):
        b = first.get(mv)
        if b is None or e < parts[b][1]:
            first[mv] = j
    base = np.array([first[mv] for mv, _ in parts], np.int64)
    shift = np.array([e - parts[first[mv]][1] for mv, e in parts], np.int64)
    return base, shift


def _expm_lengths(M, hs, fam=None):
    """exp(M hs[j]) for each length: per family (:func:`_families`), one
    :func:`scipy.linalg.expm` of its shortest length, squared up to each longer member
    (exp(2 M x) = exp(M x)^2, the squaring phase of scipy's own scaling and squaring);
    the identity for 0. Each matrix depends on its length and its family's shortest
    length only. On the cars' regime systems the squared members are within 5e-15 of a
    separate expm each, at a third of the cost (docs/decisions.md, stop 63). ``fam``:
    :func:`_families` of ``hs`` where the caller has it."""
    from scipy.linalg import expm

    base, shift = _families(hs) if fam is None else fam
    E = np.empty((hs.size, M.shape[0], M.shape[0]))
    bs = np.unique(base)
    nz = bs[hs[bs] != 0.0]
    E0 = expm(hs[nz][:, None, None] * M[None]) if nz.size else None
    for b in bs.tolist():
        js = np.flatnonzero(base == b)
        if hs[b] == 0.0:
            E[js] = np.eye(M.shape[0])
            continue
        P = E0[int(np.searchsorted(nz, b))]
        e = 0
        for j in js[np.argsort(shift[js], kind="stable")].tolist():
            while e < shift[j]:
                P = P @ P
                e += 1
            E[j] = P
    return E


def _exact_tables(A, B, sizes):
    """:func:`_exact_tables_of`, kept for the last few (A, B, step lengths) by content: a
    sweep over roads or seeds of one system computes its exponentials once."""
    return _exact_tables_cached(
        A.shape[0], A.tobytes(), B.tobytes(), np.ascontiguousarray(sizes, float).tobytes()
    )


@lru_cache(maxsize=16)
def _exact_tables_cached(n, a, b, sizes):
    A = np.frombuffer(a).reshape(n, n)
    B = np.frombuffer(b).reshape(n, 3)
    out = _exact_tables_of(A, B, np.frombuffer(sizes))
    for x in out:
        x.setflags(write=False)
    return out


def _exact_tables_of(A, B, sizes):
    """(Phi, GX, GB) per step length h: on a road segment the input u = (X1, X1', 0) has
    a constant rate, so z = (x, u, u') obeys z' = [[A, B, 0], [0, 0, I], [0, 0, 0]] z and
    e^{h [...]} propagates it exactly (first-order hold): x(t + h) = Phi x + GX X1(t) +
    GB X1' with Phi = E[:n, :n], GX = E[:n, n], GB = E[:n, n+1] + E[:n, n+3]. One batched
    matrix exponential per distinct step length."""
    from scipy.linalg import expm

    n = A.shape[0]
    big = np.zeros((n + 6, n + 6))
    big[:n, :n] = A
    big[:n, n : n + 3] = B
    big[n : n + 3, n + 3 : n + 6] = np.eye(3)
    E = expm(sizes[:, None, None] * big[None])[:, :n]
    Phi = np.ascontiguousarray(E[:, :, :n])
    GX = np.ascontiguousarray(E[:, :, n])
    return Phi, GX, np.ascontiguousarray(E[:, :, n + 1] + E[:, :, n + 3])


def _gauss_count(m: int) -> int:
    """Nodes of the one Gauss-Legendre rule of an exact step as long as m panels: the
    fewest n whose error on a component of pi rad per panel (the design phase of a panel:
    a square of Wk's 100 Hz section over 2.5 ms, its fourth power over 1.25 ms) is at
    most that of five nodes on each panel, the error of n nodes on exp(i phi theta) over
    [0, 1] being about phi^(2n) (n!)^4 / ((2n)!^3 (2n + 1)) of the integral. Below that
    phase (every slower component) the one rule's error falls faster than the
    composite's (its power 2n > 10): 5 nodes for m = 1, 10 for 4, 15 for 8, 24 for 16."""

    def err(n: int, phi: float) -> float:
        return phi ** (2 * n) * math.factorial(n) ** 4 / (math.factorial(2 * n) ** 3 * (2 * n + 1))

    n = 5
    while err(n, math.pi * m) > err(5, math.pi):
        n += 1
    return n


@lru_cache(maxsize=32)
def _nodes(m: int) -> tuple[np.ndarray, np.ndarray]:
    """(weights, nodes) of the observers' quadrature on an exact step as long as m
    panels, theta in [0, 1] increasing: one Gauss-Legendre rule of :func:`_gauss_count`
    (m) nodes over the whole step (for eight panels, 15 nodes where five on each panel
    took 40, at least as accurately: docs/model.md)."""
    x, w = np.polynomial.legendre.leggauss(_gauss_count(m))
    return 0.5 * w, 0.5 * (x + 1.0)  # writable, as the kernels' other tables


def _observer_system(sys, ss):
    """The augmented linear system of a linear system with observers
    (:func:`_augment` of its state space), or None."""
    base = sys.info["base"]
    out0 = np.empty(len(base.output_names))
    base.outputs(0.0, np.zeros(base.n_states), np.zeros(3), base.itab, base.ftab, out0)
    return _augment(sys, *ss, np.isnan(out0))


def _augment(sys, A0, B0, C0, D0, undefined):
    """The augmented linear system of the linear system (A0, B0, C0, D0) of ``sys``'s
    base (its own, or that of its linear regimes) with ``sys``'s observers: its states
    and its linear observers' (``integral`` of a signal of outputs and of those states)
    obey z' = A z + B u; the other observers' signals as rows over (z, u). Returns (A,
    B, ia: the rows of the state vector z holds, Sx, Su), or None where an observer
    reads something the linear system does not give (an output in ``undefined``, a
    nonlinear observer's state)."""
    from ._kernel import OBS_LINEAR

    n = A0.shape[0]
    obs = sys.observers
    lin = [q for q, o in enumerate(obs) if _kernel_kind(o) == OBS_LINEAR]
    ia = np.array(list(range(n)) + [n + q for q in lin], np.int64)
    pos = {int(s): i for i, s in enumerate(ia)}
    na = ia.size
    outs = {name: i for i, name in enumerate(sys.info["base"].output_names)}
    names = sys.state_names

    def row(sig):
        rx, ru = np.zeros(na), np.zeros(3)
        for ch, c in sig.items():
            if ch in outs:
                i = outs[ch]
                if undefined[i]:
                    return None
                rx[:n] += c * C0[i]
                ru += c * D0[i]
            else:
                s = names.index(ch)
                if s not in pos:
                    return None
                rx[pos[s]] += c
        return rx, ru

    A = np.zeros((na, na))
    B = np.zeros((na, 3))
    A[:n, :n] = A0
    B[:n] = B0
    for i, q in enumerate(lin):
        r = row(obs[q].signal)
        if r is None:
            return None
        A[n + i], B[n + i] = r
    nsg = int(sys.itab[_kernel.I_NSG])
    sigs = [None] * nsg
    ob = int(sys.itab[_kernel.I_OBS])
    for q, o in enumerate(obs):
        for k, sig in ((int(sys.itab[ob + 4 * q + 1]), o.signal), (int(sys.itab[ob + 4 * q + 2]), o.other)):
            if k >= 0 and sig is not None:
                r = row(sig)
                if r is None:
                    return None
                sigs[k] = r
    Sx = np.array([r[0] if r else np.zeros(na) for r in sigs]).reshape(nsg, na)
    Su = np.array([r[1] if r else np.zeros(3) for r in sigs]).reshape(nsg, 3)
    return A, B, ia, Sx, Su


def _read_rows(sys, Sx, Su) -> tuple[np.ndarray, int]:
    """The signals the quadratures and peaks of ``sys``'s observers read (a filter's
    own are in the augmented system), as rows (signal, source, sign): first the
    distinct ones (source: their row in the tables), then those equal to one of them
    (source: its signal) or to its negative (sign -1), which cost nothing (a ride's
    peaks of +-a, +-a_w, +-z; :func:`_signal_refs`)."""
    from ._kernel import OBS_LINEAR

    it = sys.itab
    ob = int(it[_kernel.I_OBS])
    read = set()
    for q in range(int(it[_kernel.I_NOB])):
        if int(it[ob + 4 * q]) != OBS_LINEAR:
            read.update(int(k) for k in it[ob + 4 * q + 1 : ob + 4 * q + 3] if k >= 0)
    own, alias, seen = [], [], {}
    for k in sorted(read):
        row = np.concatenate((Sx[k], Su[k])) + 0.0  # + 0.0: -0.0 and 0.0 alike
        key, neg = row.tobytes(), (0.0 - row).tobytes()
        if key in seen:
            alias.append((k, seen[key], 1))
        elif neg in seen:
            alias.append((k, seen[neg], -1))
        else:
            seen[key] = k
            own.append((k, len(own), 1))
    return np.array(own + alias, np.int64).reshape(-1, 3), len(own)


#: terms of an exact step's Taylor series at most (they fall as (rate h)^k / k!: below
#: round-off within 40 terms for rate h <= 2, the observers' steps)
TAYLOR_TERMS = 60


def _step_tables(M, S, hs, m=0, ends=None, fam=None):
    """(TR, kj, R) for steps of lengths ``hs`` of z' = M z and the signal rows S.

    TR[j, r, k] = S[r] (M hs[j])^k / k!: the signal S[r] . z(theta h) from z0 over a
    step of length hs[j] is sum_k (TR[j, r, k] . z0) theta^k (the peaks inside an exact
    step, :func:`._integrate._taylor_peak`). Its terms run until two in a row fall below
    1e-18 of the largest (kj[j] of them, at most :data:`TAYLOR_TERMS`; zeros past).

    Lengths a power of two apart (:func:`_families`) share one chain of products, that
    of the shortest: the terms of 2^e h are 2^(e k) times its terms to the last bit
    (scaling by a power of two commutes with rounding in every product and sum, and so
    with each term's stopping test), unless a product could leave the normal range,
    where each length runs its own chain.

    With m panels (m > 0) and ``ends`` = exp(M hs[j]): R[p, j] = S exp(M theta_p hs[j])
    at the points theta = :func:`_points` (m) of a step: its start S, its nodes the
    Taylor rows summed there, its end S ends[j]; else R is None. ``fam``:
    :func:`_families` of ``hs`` where the caller has it."""
    nr, nq = S.shape
    M = np.ascontiguousarray(M, float)
    S = np.ascontiguousarray(S, float)
    chains = []
    if nr == 0:  # no signals: two (empty) terms each, as the chain's test gives
        kj = np.full(hs.size, 2, np.int64)
    else:
        base, shift = _families(hs) if fam is None else fam
        kj = np.empty(hs.size, np.int64)
        for b in np.unique(base).tolist():
            js = np.flatnonzero(base == b)
            sh = shift[js]
            C, k = _tables.taylor_chain(M, S, float(hs[b]), sh, TAYLOR_TERMS)
            if sh.max() > 0 and _leaves_normal(C, M, float(hs[b]), int(sh.max())):
                for j in js.tolist():  # each length its own chain
                    one = np.zeros(1, np.int64)
                    Cj, kk = _tables.taylor_chain(M, S, float(hs[j]), one, TAYLOR_TERMS)
                    kj[j] = kk[0]
                    chains.append((Cj, kk, one, np.array([j], np.int64)))
            else:
                kj[js] = k
                chains.append((C, k, sh, js))
    K = int(kj.max(initial=1))
    TR = np.zeros((hs.size, nr, K, nq))
    th = _points(m) if m else np.empty(0)
    pw = th[1:-1, None] ** np.arange(K)[None] if m else np.empty((0, K))
    R = np.empty((th.size, hs.size, nr, nq)) if m else np.empty((0, hs.size, nr, nq))
    for C, k, sh, js in chains:
        _tables.family_rows(C, k, sh, js, pw, TR, R[1:-1])
    if not m:
        return TR, kj, None
    R[0] = S
    R[-1] = S @ ends
    return TR, kj, R


def _leaves_normal(C, M, h: float, top: int) -> bool:
    """Whether a product of the chain C of h, scaled by up to 2^(top k), could leave the
    normal range of floats."""
    lo, hi = _tables.abs_range(C)
    mlo, mhi = _tables.abs_range(M)
    if hi == 0.0 or mhi == 0.0:
        return False
    low = math.log2(lo) + math.log2(mlo * h / TAYLOR_TERMS)
    high = math.log2(hi) + math.log2(mhi * h) + top * (C.shape[0] + 1)
    return low < -1000.0 or high > 1000.0


def _signal_refs(rows, nu: int, nsg: int) -> np.ndarray:
    """For each signal k, sign(s) (r + 1) where it equals s times the distinct signal
    r of the rows of :func:`_read_rows` (0: not read): how
    :func:`._integrate._observe_steps` finds a signal's row."""
    ref = np.zeros(nsg, np.int64)
    for r in range(rows.shape[0]):
        k, src, sign = (int(v) for v in rows[r])
        ref[k] = r + 1 if r < nu else sign * ref[src]
    return ref


@lru_cache(maxsize=32)
def _points(m: int = 1) -> np.ndarray:
    """theta of the points of an exact step as long as m panels the observers read: 0,
    the Gauss-Legendre nodes (:func:`_nodes`), 1 (read-only: kept per m)."""
    th = np.concatenate(([0.0], _nodes(m)[1], [1.0]))
    th.setflags(write=False)
    return th


def _point_tables(A, B, Sx, Su, rows, sizes, m=1):
    """(:func:`_point_tables_of`, :func:`_step_tables` of the signals over v = (z,
    X1, X1')), kept for the last few systems, step lengths and panel counts by content
    (a sweep over roads or seeds computes them once)."""
    sx, su = Sx[rows], Su[rows]  # the distinct signals
    return _point_tables_cached(
        A.shape[0], A.tobytes(), B.tobytes(), sx.tobytes(), su.tobytes(),
        np.ascontiguousarray(sizes, float).tobytes(), m,
    )  # fmt: skip


@lru_cache(maxsize=16)
def _point_tables_cached(n, a, b, sx, su, sizes, m):
    A = np.frombuffer(a).reshape(n, n)
    B = np.frombuffer(b).reshape(n, 3)
    sx = np.frombuffer(sx).reshape(-1, n)
    su = np.frombuffer(su).reshape(-1, 3)
    hs = np.frombuffer(sizes)
    SR, TR = _point_tables_of(A, B, sx, su, hs, m)
    SR.setflags(write=False)
    TR.setflags(write=False)
    return SR, TR


def _point_tables_of(A, B, sx, su, sizes, m=1):
    """(SR, TR) over v = (z, X1, X1') at the start of an exact step of length sizes[j]
    (m panels long) on a linear road segment (:func:`_exact_tables_of`): SR[j, q, p nu
    + r] the signal r (rows sx, su over z and u; nu of them) at theta =
    :func:`_points` (m)[p] of the step, (Sx z + Su u) there = sum_q SR[j, q, p nu + r]
    v[q] (the layout :func:`._integrate._observe_steps` sums over); TR its Taylor rows
    (:func:`_step_tables` of v' = Mv v, X1'' = 0), which give the nodes' rows."""
    na = A.shape[0]
    Mv = np.zeros((na + 2, na + 2))
    Mv[:na, :na] = A
    Mv[:na, na:] = B[:, :2]
    Mv[na, na + 1] = 1.0
    S = np.hstack([sx, su[:, :2]])
    Phi, GX, GB = _exact_tables(A, B, sizes)  # exp(Mv h), from the exact tables
    E = np.zeros((sizes.size, na + 2, na + 2))
    E[:, :na, :na] = Phi
    E[:, :na, na] = GX
    E[:, :na, na + 1] = GB
    E[:, na, na] = E[:, na + 1, na + 1] = 1.0
    E[:, na, na + 1] = sizes
    TR, _, R = _step_tables(Mv, S, sizes, m, E)
    return _point_layout(R), TR


def _point_layout(SR):
    """SR[..., p, j, r, q] as SR[..., j, q, p nu + r] (contiguous)."""
    SR = np.moveaxis(SR, (-4, -3, -2, -1), (-2, -4, -1, -3))  # [..., j, q, p, r]
    return np.ascontiguousarray(SR.reshape(*SR.shape[:-2], SR.shape[-2] * SR.shape[-1]))


def _kernel_kind(o):
    from .observers import KINDS

    return KINDS[o.kind]


#: no observers in exact steps (the trailing arguments of :func:`._integrate.exact_walk`)
_NO_OBSERVERS = (
    np.empty((0, 0, 0)), np.empty(0), np.empty(0), np.empty((0, 0, 0, 0)), np.empty(0, np.int64),
)  # fmt: skip


def _walk_tables(sys, ss, sizes):
    """The tables of the exact walk over steps of ``sizes`` [s]: (Phi transposed for the
    walk's column products, GX, GB of :func:`_exact_tables`, the rows of the augmented
    state, the observers' tables: their signals at the points of a step and its Taylor
    rows, :func:`_point_tables`, the nodes and weights, the signals read). Kept on the
    system (:func:`_memo`, tied to its tables, which fix its state space and observers)
    for the last :data:`WALK_TABLES_KEPT` sets of step lengths by content: a run of the
    same plan again (another seed of a road of one grid, a benchmark) reads them without
    hashing the matrices again."""
    kept = _memo(sys).setdefault("walk_tables", {})
    key = np.ascontiguousarray(sizes, float).tobytes()
    got = kept.get(key)
    if got is not None:
        return got
    if sys.observers:
        A, B, ia, Sx, Su = sys.info["observer_system"]
        Phi, GX, GB = _exact_tables(A, B, sizes)
        if "observer_rows" not in sys.info:  # the signals read: fixed by the system
            rows, nu = _read_rows(sys, Sx, Su)
            sys.info["observer_rows"] = (rows, nu, _signal_refs(rows, nu, Sx.shape[0]))
        rows, nu, sref = sys.info["observer_rows"]
        m = _panels(sizes, _observer_panel(sys))  # the quadrature's panels per step
        SR, TR = _point_tables(A, B, Sx, Su, rows[:nu, 0], sizes, m)
        extra = (SR, *_nodes(m), TR, sref)
    else:
        A, B, _, _ = ss
        Phi, GX, GB = _exact_tables(A, B, sizes)
        ia = np.arange(sys.n_states, dtype=np.int64)
        extra = _NO_OBSERVERS
    PhiT = np.ascontiguousarray(Phi.transpose(0, 2, 1))  # the walk's column products
    got = (PhiT, GX, GB, ia, extra)
    if len(kept) >= WALK_TABLES_KEPT:
        kept.pop(next(iter(kept)))
    kept[key] = got
    return got


#: the exact walk's tables (:func:`_walk_tables`) of this many sets of step lengths are
#: kept on a system
WALK_TABLES_KEPT = 8


def _exact(sys, ss, plan, segs, y, x1, T, ts, jumps, jump_tol, v_before, vjump_tol, vjumps):
    """Matrix-exponential steps of a linear system on a piecewise-linear road
    (:func:`._integrate.exact_walk` with the tables of :func:`_exact_tables`): the
    states and the road (X1, X1', X1'') at the samples, and the statistics. Observers:
    the tables of the augmented system (:func:`_observer_system`) and of their signals
    at the quadrature nodes (:func:`_point_tables`)."""
    sizes, idx = plan
    PhiT, GX, GB, ia, extra = _walk_tables(sys, ss, sizes)
    Y = np.empty((ts.size, sys.n_states))
    U = np.zeros((ts.size, 3))
    status, m = _integrate.exact_walk(
        True, segs, ts, T, y, x1, v_before, jump_tol, vjump_tol, sys.jump_ok, sys.imp_unit,
        sys.itab, sys.ftab, 0.5 * EXACT_STEP_QUANTUM * max(T, 1.0), np.empty(0), idx, PhiT, GX,
        GB, Y, U, jumps, vjumps, ia, *extra,
    )  # fmt: skip
    if status != _integrate.OK:
        t0 = float(segs[np.flatnonzero(jumps)[-1], 0]) if np.any(jumps) else 0.0
        raise ConvergenceError(
            f"{sys.description}: the road steps at {t0:g} s and a step has no finite "
            "response here; smooth the edges"
        )
    return Y, U, {"exact_steps": int(m), "distinct_step_sizes": int(sizes.size)}


def _linear_outputs(sys, ss, Y, U):
    """The outputs of a linear system at the samples (one row per output): C x + D u,
    NaN where the right-hand side leaves them undefined (accelerations of massless
    nodes)."""
    _, _, C, D = ss
    out0 = np.empty(len(sys.output_names))
    u0 = np.zeros(_kernel.road_layout_of(sys.itab)[1])
    sys.outputs(0.0, np.zeros(sys.n_states), u0, sys.itab, sys.ftab, out0)
    O = np.empty((C.shape[0], Y.shape[0]))
    _integrate.linear_outputs(
        np.ascontiguousarray(Y.T), np.ascontiguousarray(U.T), C, D, np.isnan(out0), O
    )
    return O


def _impulse(x, road, itab, ftab, imp, dx):
    _kernel.evaluate(0.0, x, road, itab, ftab, np.empty(_kernel.work_size(itab)), dx, imp)


# ---------------------------------------------------------------------------------------
# systems


def _as_network(device_or_network, params):
    """(text, params) from a network text, an element object or a device model."""
    from ..devices.models import HydraulicDevice, RectifierDevice, ScrewDevice

    d = device_or_network
    if isinstance(d, str):
        return d, params
    if isinstance(d, ElementBase):
        return f"{d.prefix}", {d.prefix: d}
    if isinstance(d, HydraulicDevice | ScrewDevice | RectifierDevice):
        from ..elements import HydraulicElement, RectifierElement, ScrewElement

        cls = {"hydraulic": HydraulicElement, "screw": ScrewElement, "rectifier": RectifierElement}[
            d.kind
        ]
        extra = {}
        if d.kind == "screw":
            extra = {"backlash": d.backlash}
        elif d.kind == "rectifier":
            extra = {"freewheel": d.freewheel, "flywheel_drag": d.flywheel_drag}
        el = cls(
            stiffness=d.stiffness, damping=d.damping, friction=d.friction,
            friction_velocity=d.friction_velocity, flywheel=d.flywheel,
            ratio=d.transmission.ratio, law=d.law, **extra,
        )  # fmt: skip
        return cls.prefix, {cls.prefix: el}
    raise ParameterError(
        "device_or_network", d, "a network text, an element or a device of inerterlab.devices"
    )


def device_network(device) -> tuple[str, dict]:
    """(network text, parameters by ``"name.parameter"``) of a device of
    :mod:`inerterlab.devices` as a composite element: what :func:`rig` and
    :func:`inerterlab.identify.identify_network` take, each parameter settable by name.

    >>> from inerterlab.devices import device_preset
    >>> text, params = device_network(device_preset("screw"))
    >>> text, params["screw.stiffness"]
    ('screw', 1970000.0)
    """
    if isinstance(device, str):
        raise ParameterError("device", device, "a device of inerterlab.devices or an element")
    text, prm = _as_network(device, None)
    return text, {f"{text}.{k}": v for k, v in prm[text].parameters().items()}


def rig(device_or_network, params: dict | None = None) -> System:
    """A test rig: the network between a driven terminal (``drive``, the road input is
    its prescribed displacement) and the ground. Output ``force`` is the force the rig
    applies."""
    text, params = _as_network(device_or_network, params)
    tree, els = elements_of(text, params)

    def make(arrange):
        lay = Layout(arrange)
        top = lay.node("drive", "road")
        bot = lay.node("ground", "ground")
        # arranged toward the ground: the drive's velocity may jump (a sine from rest)
        lay.place(tree, top, bot, els, fixed=(False, True))
        return lay

    sys, lay = _laid_out("rig", f"rig with {text!r}", make, {"network": text})
    sys.info["edges"] = tuple(lay.edges)
    return sys


def base_excited(mass: float, network: str, params: dict | None = None) -> System:
    """A body of ``mass`` [kg] on ``network`` over a moving base (the ch. 7 system)."""
    m = check_positive("mass", mass, "kg")
    tree, els = elements_of(network, params)

    def make(arrange):
        lay = Layout(arrange)
        body = lay.node("body", "mass", m)
        base = lay.node("base", "road")
        lay.place(tree, body, base, els, fixed=(True, False))  # arranged toward the body
        return lay

    desc = f"base-excited body on {network!r}"
    return _laid_out("base_excited", desc, make, {"network": network})[0]
