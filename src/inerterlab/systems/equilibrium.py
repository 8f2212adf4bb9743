"""Static equilibrium of a core system under gravity, by Newton's method.

The states of a core :class:`~inerterlab.systems.System` are measured from the
configuration in which every element is force-free (every spring at its free length).
A linear spring's static deflection never shows in that convention (superposition), but
a nonlinear spring's does: a gas spring stiffens as it takes the weight, a bump stop
engages or not. :func:`equilibrium` solves the whole nonlinear static balance with
gravity,

    sum over the elastic elements at node n of their forces  -  m_n g  =  0

at every node with a displacement state (masses and massless nodes alike; the
accelerations and velocities are zero at rest, so dampers, inerters and friction carry
nothing), by Newton's method with a finite-difference Jacobian and a step halved until
the residual falls and every element stays where its law is defined. The elements'
working ranges (a gas spring's stroke, a bump stop's travel) are then checked: an
equilibrium outside one is refused in one line naming the element.

The result's :attr:`Equilibrium.system` is the same system about that rest: each
nonlinear elastic element takes its law about its static extension y0 (the force
F(y0 + x) - F(y0)), so its states are again deviations from rest, x = 0 is the
equilibrium and every analysis of the core (time simulation, harmonic balance,
linearisation) applies unchanged. :meth:`Equilibrium.linear_state_space` is the
linearisation about the equilibrium (central differences of the right-hand side).

The tyre element carries load at rest like a spring (its static extension is the
wheel's sag on the road). A body with several coordinates (a vehicle's bounce, pitch
and roll) has its weight on the translational coordinate alone: the coordinates that
:attr:`System.info` ``["weightless"]`` names (pitch, roll: the body's centre of gravity
is its reference point) take the body's moment of inertia as their mass and no weight.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..elements import KERNEL_LAWS, kernel_law
from ..elements._base import NPAR
from ..errors import ConvergenceError, NetworkError, ParameterError, check_positive
from . import _kernel
from ._kernel import DYN, ELEM_W, NODE_W, REL, RELV, VEL
from .observers import derive, uncached_info

__all__ = ["Equilibrium", "equilibrium"]


@dataclass(frozen=True, eq=False)
class Equilibrium:
    """The static equilibrium of a system under gravity (see :func:`equilibrium`).

    Attributes
    ----------
    system : System
        The system about this rest (nonlinear elastic elements at their operating
        points): its state 0 is the equilibrium.
    original : System
        The system as given (states from the force-free configuration).
    state : ndarray
        The equilibrium in the original system's states [m] (velocities 0).
    displacements : dict
        Node -> displacement from the force-free configuration [m] (up positive).
    extensions : dict
        Elastic element -> static extension [m] (negative: compressed).
    forces : dict
        Elastic element -> static force [N] (tension positive).
    gravity : float
        [m/s^2].
    weight : float
        Total weight of the masses [N].
    residual : float
        Largest force imbalance at a node [N].
    iterations : int
        Newton iterations.
    """

    system: object
    original: object
    state: np.ndarray
    displacements: dict
    extensions: dict
    forces: dict
    gravity: float
    weight: float
    residual: float
    iterations: int

    def __repr__(self) -> str:
        return (
            f"<Equilibrium of {self.original.description}: weight {self.weight:.6g} N, "
            f"residual {self.residual:.3g} N after {self.iterations} Newton steps>"
        )

    def linear_state_space(self, step: float = 1e-5):
        """(A, B, C, D) of the system linearised about this equilibrium, in the layout
        of :meth:`System.linear_state_space` (input: road displacement, velocity,
        acceleration; outputs :attr:`System.output_names`), by central differences of
        the right-hand side with steps ``step`` x each state's scale (:func:`linearise`)."""
        return linearise(self.system, step=step)


def _structure(sys):
    itab, ftab = sys.tables
    nn = int(itab[_kernel.I_NN])
    ne = int(itab[_kernel.I_NE])
    no, eo = int(itab[_kernel.I_NODE]), int(itab[_kernel.I_ELEM])
    fm = int(itab[_kernel.I_FMASS])
    types = [int(itab[no + NODE_W * n]) for n in range(nn)]
    xstate = [int(itab[no + NODE_W * n + 1]) for n in range(nn)]
    masses = np.array([ftab[fm + n] for n in range(nn)])
    ends = [(int(itab[eo + ELEM_W * e + 1]), int(itab[eo + ELEM_W * e + 2])) for e in range(ne)]
    laws = [KERNEL_LAWS[int(itab[eo + ELEM_W * e])] for e in range(ne)]
    # a combination node (a body point) passes a force to its members by its coefficients
    share = {n: [(n, 1.0)] for n in range(nn)}
    for n in range(nn):
        b = no + NODE_W * n
        if types[n] == _kernel.LIN:
            mo, cnt, co = int(itab[b + 1]), int(itab[b + 2]), int(itab[b + 3])
            share[n] = [(int(itab[mo + j]), float(ftab[co + j])) for j in range(cnt)]
    return nn, ne, types, xstate, masses, ends, laws, share


def _rebuilt(sys, elements: list):
    """``sys`` with its elements replaced (same kernel codes, new rows)."""
    return derive(sys, lambda sys: _replaced(sys, elements))


def _replaced(sys, elements: list):
    itab, ftab = sys.tables
    eo = int(itab[_kernel.I_ELEM])
    ft = ftab.copy()
    L = np.array(sys.info["spring_laplacian"], dtype=float, copy=True)
    for e, (old, new) in enumerate(zip(sys.elements, elements, strict=True)):
        if new is old:
            continue
        o = int(itab[eo + ELEM_W * e + 3])
        ft[o : o + NPAR] = new.row()
        if kernel_law(new).elastic:
            t, b = int(itab[eo + ELEM_W * e + 1]), int(itab[eo + ELEM_W * e + 2])
            dk = new.row()[0] - old.row()[0]
            L[t, t] += dk
            L[b, b] += dk
            L[t, b] -= dk
            L[b, t] -= dk
    ft.setflags(write=False)
    info = uncached_info(sys.info, spring_laplacian=L)
    return dataclasses.replace(sys, ftab=ft, elements=tuple(elements), info=info)


def equilibrium(system, gravity: float | None = None, *, heights=None,
                max_iterations: int = 100) -> Equilibrium:  # fmt: skip
    """The static equilibrium of ``system`` (a core :class:`System`) under ``gravity``
    [m/s^2] (default: a quarter car's own, else 9.81; 0: no weight, for a system about
    its rest), the ground at 0 and each road at its entry of ``heights`` [m] (default 0).

    Newton's method on the nonlinear force balance of every node with a displacement
    state (module docstring), from the force-free configuration. Raises NetworkError
    naming the element where the equilibrium leaves an element's working range (a gas
    spring past its stroke, a bump stop past its travel) or where no spring holds a
    mass, and ConvergenceError if Newton's method does not converge.

    >>> from inerterlab.systems import quarter_car
    >>> car = quarter_car("gas | c", {"gas": {"pressure": 2e6}, "c": 3e3})
    >>> eq = equilibrium(car)
    >>> round(eq.forces["gas"], 3) == round(-370.0 * 9.81, 3)
    True
    """
    if gravity is None:
        gravity = float(system.info.get("car", {}).get("gravity", 9.81))
    g = 0.0 if gravity == 0.0 else check_positive("gravity", gravity, "m/s^2")
    st = _solve(system, g, heights, None, max_iterations)
    x, X, F, springs, ends, laws, scale = (
        st["x"], st["X"], st["F"], st["springs"], st["ends"], st["laws"], st["scale"]
    )
    nn = len(X)
    names = system.element_names
    extensions = {names[e]: float(X[ends[e][0]] - X[ends[e][1]]) for e in springs}
    forces = {names[e]: float(F[e]) for e in springs}
    # the working ranges, then each nonlinear elastic element about its static extension
    new = list(system.elements)
    for e in springs:
        el = system.elements[e]
        y = extensions[names[e]]
        rng = getattr(el, "static_range", None)
        if rng is not None:
            lo, hi, what = rng()
            if not lo <= y <= hi:
                raise NetworkError(
                    f"{system.description}: no static equilibrium within the elements' "
                    f"ranges: {names[e]} ({el.description}) would take {-y:.6g} m of "
                    f"compression carrying {-forces[names[e]]:.6g} N, beyond {what}"
                )
        if el.is_linear or laws[e].contact:  # a tyre's law is about its static load
            continue
        if hasattr(el, "at_operating_point"):
            new[e] = el.at_operating_point(el.operating_point + y)
        elif abs(y) > 1e-12 and abs(forces[names[e]]) > 1e-12 * scale:
            # (moved inside its free play, carrying nothing: at rest anywhere there)
            raise NetworkError(
                f"{system.description}: {names[e]} ({el.description}) is moved {y:.6g} m at "
                "rest by the static load, and its law is taken about the force-free "
                "position only; carry the load with springs beside it"
            )
    about = _rebuilt(system, new)
    return Equilibrium(
        system=about,
        original=system,
        state=x,
        displacements={system.node_names[n]: float(X[n]) for n in range(nn)},
        extensions=extensions,
        forces=forces,
        gravity=g,
        weight=st["weight"],
        residual=st["residual"],
        iterations=st["iterations"],
    )


def _solve(system, g: float, heights, loads, max_iterations: int) -> dict:
    """Newton's method on the static balance of ``system`` under gravity ``g`` with the
    roads at ``heights`` and constant element forces ``loads`` (element index -> force
    [N], tension positive) besides the elastic elements' own: the state ``x``, node
    displacements ``X``, element forces ``F`` and the bookkeeping :func:`equilibrium`
    reads."""
    itab, ftab = system.tables
    nn, ne, types, xstate, masses, ends, laws, share = _structure(system)
    springs = [e for e in range(ne) if laws[e].elastic or laws[e].contact]  # carry load at rest
    sprung = {m for e in springs for n in ends[e] for m, _ in share[n]}
    loads = {int(e): float(f) for e, f in (loads or {}).items()}
    # a massless node that no spring touches (between a damper and an inerter) carries
    # nothing at rest anywhere: it stays where it is
    rows = [
        n for n in range(nn)
        if types[n] in (DYN, VEL, REL, RELV) and (n in sprung or masses[n] > 0)
    ]  # fmt: skip
    unknown = np.array([xstate[n] for n in rows], dtype=np.int64)
    weights = masses * g
    for name in system.info.get("weightless", ()):  # rotational coordinates
        weights[system.node_names.index(name)] = 0.0
    weight = float(weights.sum())
    # the tolerance's scale: the weight (or, without gravity, the weight it would be)
    scale = max(weight if g > 0 else float(masses.sum()) * 9.81, 1.0)
    W = np.empty(_kernel.work_size(itab))
    dx = np.empty(system.n_states)
    road = np.zeros(_kernel.road_layout_of(itab)[1])  # every road at rest
    if heights is not None:
        h = np.atleast_1d(np.asarray(heights, dtype=float))
        nr = max(int(itab[_kernel.I_NRD]), 1)
        if h.shape != (nr,) or not np.all(np.isfinite(h)):
            raise ParameterError("heights", heights, f"{nr} finite road heights [m]")
        road[0 : 3 * nr : 3] = h
    base = np.array(system.x0_template, dtype=float)
    pos = {n: i for i, n in enumerate(rows)}
    for e in loads:
        free = [m for n in ends[e] for m, _ in share[n]
                if types[m] in (DYN, VEL, REL, RELV) and m not in pos]  # fmt: skip
        if free:
            raise NetworkError(
                f"{system.description}: {system.element_names[e]} carries a constant force "
                f"at node {system.node_names[free[0]]}, which no spring holds at rest (no "
                "static balance of that force)"
            )

    # the residual's terms, in the order they are added: each spring's force (then each
    # constant load) times its signed share at the unknowns its two ends move (top
    # end -c, bottom end +c)
    t_row, t_coef, t_el, t_load, t_spring = [], [], [], [], []
    terms = [(e, 0.0, True) for e in springs] + [(e, f, False) for e, f in loads.items()]
    for e, load, spring in terms:
        for end, sign in zip(ends[e], (-1.0, 1.0), strict=True):
            for m, c in share[end]:
                if m in pos:
                    t_row.append(pos[m])
                    t_coef.append(sign * c)
                    t_el.append(e)
                    t_load.append(load)
                    t_spring.append(spring)
    t_row = np.array(t_row, dtype=np.int64)
    t_coef = np.array(t_coef, dtype=float)
    t_el = np.array(t_el, dtype=np.int64)
    t_load = np.array(t_load, dtype=float)
    t_spring = np.array(t_spring, dtype=bool)
    row_weights = np.array([weights[n] for n in rows], dtype=float)

    def balance(z):
        """(node displacements X, element forces F, residual R [N] per unknown)."""
        x = base.copy()
        x[unknown] = z
        _kernel.evaluate(0.0, x, road, itab, ftab, W, dx, _kernel._NO_IMPULSE)
        X = W[:nn].copy()
        F = W[3 * nn : 3 * nn + ne].copy()
        R = np.zeros(len(rows))
        # added one by one in that order (np.add.at), so R is what a loop gives
        np.add.at(R, t_row, t_coef * np.where(t_spring, F[t_el], t_load))
        R -= row_weights
        return X, F, R

    def residual(z):
        return balance(z)[2]

    def singular(J):
        # a massless node that only a spring with free play (inside its play) holds
        # carries nothing at rest: Newton takes the least-squares step there
        w, v = np.linalg.eigh(0.5 * (J + J.T))
        null = np.abs(w) <= 1e-12 * max(float(np.abs(w).max(initial=0.0)), 1e-300)
        if np.all(np.isfinite(J)) and null.any():
            heavy = [i for i, n in enumerate(rows) if masses[n] > 0]
            if np.abs(v[np.ix_(heavy, np.flatnonzero(null))]).max(initial=0.0) <= 1e-9:
                return
        raise NetworkError(
            f"{system.description}: no static equilibrium: {_unheld(system, rows, J)} is "
            "held by no spring at rest (the static stiffness is singular); give it a spring "
            "path to the road or ground"
        )

    z, it = newton(residual, len(rows), 1e-12 * scale, system.description, singular,
                   max_iterations=max_iterations)  # fmt: skip
    X, F, R = balance(z)
    res = float(np.max(np.abs(R))) if rows else 0.0
    x = base.copy()
    x[unknown] = z
    return {"x": x, "X": X, "F": F, "springs": springs, "ends": ends, "laws": laws,
            "scale": scale, "weight": weight, "residual": res, "iterations": it}  # fmt: skip


def loaded_rest(system, loads: dict) -> np.ndarray:
    """The state of ``system`` (about its rest, no gravity) at rest under constant forces
    in its elements, ``loads``: element index -> force [N] (tension positive, pulling its
    ends together), balanced by the elastic elements (springs, tyres) by Newton's method
    as :func:`equilibrium`. A rectifying law's mean force (an asymmetric damper's under
    random motion) is such a load: its mean offset. NetworkError where a loaded element
    ends at a node no spring holds."""
    return _solve(system, 0.0, None, loads, 100)["x"]


def newton(residual, n: int, tol: float, what: str, singular, *, max_iterations: int = 100,
           step: float = 1e-7):  # fmt: skip
    """z with max |residual(z)| <= ``tol`` by Newton's method from z = 0: the Jacobian by
    central differences (steps ``step`` x max(0.01, |z_j|)), each step halved until the
    residual falls and stays finite (a law undefined there gives NaN). ``singular(J)``
    raises where the Jacobian is singular, or returns where the singular part carries no
    load (then the least-squares step is taken). Returns (z, iterations); ConvergenceError
    naming ``what`` if it does not converge."""
    z = np.zeros(n)
    if n == 0:
        return z, 0
    R = residual(z)
    it = 0
    while True:
        res = float(np.max(np.abs(R)))
        if res <= tol:
            return z, it
        if it >= max_iterations:
            raise ConvergenceError(
                f"{what}: no static equilibrium after {max_iterations} Newton steps "
                f"(residual {res:.3g})"
            )
        J = np.empty((n, n))
        for j in range(n):
            d = step * max(1e-2, abs(z[j]))
            zp, zm = z.copy(), z.copy()
            zp[j] += d
            zm[j] -= d
            J[:, j] = (residual(zp) - residual(zm)) / (2 * d)
        if not np.all(np.isfinite(J)) or np.linalg.cond(J) > 1e14:
            singular(J)  # raises, or returns where the singular part carries no load
            dz = np.linalg.lstsq(J, -R, rcond=None)[0]
        else:
            dz = np.linalg.solve(J, -R)
        lam = 1.0
        while True:
            zt = z + lam * dz
            Rt = residual(zt)
            rt = float(np.max(np.abs(Rt)))
            if math.isfinite(rt) and (rt < res or lam < 1e-3 and rt <= res * 1.0001):
                break
            lam *= 0.5
            if lam < 1e-12:
                raise ConvergenceError(
                    f"{what}: Newton's method for the static equilibrium stalled "
                    f"(residual {res:.3g})"
                )
        z, R = zt, Rt
        it += 1
        if float(np.max(np.abs(lam * dz))) <= 1e-15 * max(1.0, float(np.max(np.abs(z)))):
            return z, it


def _unheld(system, rows, J) -> str:
    w, v = np.linalg.eigh(0.5 * (J + J.T))
    k = int(np.argmin(np.abs(w)))
    i = int(np.argmax(np.abs(v[:, k])))
    return f"node {system.node_names[rows[i]]}"


def linearise(system, x0=None, *, step: float = 1e-5):
    """(A, B, C, D) of ``system`` about the state ``x0`` (default 0, the rest) with the
    roads at rest, by central differences of the right-hand side and the outputs with
    Richardson's extrapolation (steps h and h/2, h = ``step`` x each state's scale; 1 m,
    m/s, m/s^2 x ``step`` for the road): the error is of order h^4 for a smooth law, and
    the round-off eps F / h stays small at these steps. Outputs undefined at massless
    nodes (accelerations) are 0, as in :meth:`System.linear_state_space`."""
    itab, ftab = system.tables
    n = system.n_states
    no = len(system.output_names)
    x0 = np.zeros(n) if x0 is None else np.asarray(x0, float)
    nu = _kernel.road_layout_of(itab)[1]  # 3 inputs per road (the free slot follows them)
    A, B = np.zeros((n, n)), np.zeros((n, nu))
    C, D = np.zeros((no, n)), np.zeros((no, nu))

    def at(x, u):
        f = np.empty(n)
        y = np.empty(no)
        system.rhs(0.0, x, u, itab, ftab, f)
        system.outputs(0.0, x, u, itab, ftab, y)
        return np.concatenate([f, np.nan_to_num(y)])

    def slope(x, u, dx, du, d):
        def central(h):
            return (at(x + h * dx, u + h * du) - at(x - h * dx, u - h * du)) / (2 * h * d)

        return (4.0 * central(0.5) - central(1.0)) / 3.0

    u0 = np.zeros(nu)
    for k in range(n):
        d = step * max(float(system.state_scales[k]), 1e-6)
        e = np.zeros(n)
        e[k] = d
        col = slope(x0, u0, e, u0, d)
        A[:, k], C[:, k] = col[:n], col[n:]
    for k in range(nu):
        e = np.zeros(nu)
        e[k] = step
        col = slope(x0, u0, np.zeros(n), e, step)
        B[:, k], D[:, k] = col[:n], col[n:]
    return A, B, C, D
