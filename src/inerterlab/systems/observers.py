"""Observers: quantities integrated as states beside a system's own (docs/model.md,
"Observers").

An observer reads *signals*: weighted sums of the system's outputs (``<node>.x``,
``<node>.v``, ``<node>.a``, ``<element>.force``) and states (observer states
included). Kinds:

``integral``  q' = a            (a linear filter when a reads other observer states)
``square``    q' = a^2          (RMS: sqrt(q(T) / T))
``fourth``    q' = a^4          (VDV: q(T)^(1/4))
``product``   q' = a b          (power of an element: force times relative velocity)
``peak``      q = max a         (running maximum, located on the continuous extension)

The integrator carries them in its stages and its error norm (absolute tolerance
``rtol`` x ``scale``), so an RMS, a weighted RMS or an energy is as accurate as the
motion, not a sum over samples; a linear filter among them (the Wk weighting) and the
squares and powers that read it are advanced outside the adaptive steps' stages, exactly
over each accepted step (:func:`filter_split`); the exact (matrix-exponential) steps carry them too, the
linear filters in the augmented matrix, the others by Gauss-Legendre sums of their exact
values (docs/model.md §11). :func:`with_observers` returns the system with them;
:meth:`CoreResult.observed` reads their final values. Ready-made sets:
:func:`weighted` (a linear filter of a signal, e.g. ISO 2631-1 Wk), :func:`energy`
(the energy ledger: work done on every element and mass, and by the road) and
:func:`ride` (the quarter car's ride metrics).

>>> from inerterlab.systems import quarter_car
>>> car = quarter_car("k | c", {"k": 3e4, "c": 1.5e3})
>>> obs = with_observers(car, [Observer("i_acc", "square", {"body.a": 1.0}, scale=1e-2)])
>>> obs.state_names[-1], obs.n_states - car.n_states
('i_acc', 1)
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from . import _kernel

__all__ = ["Observer", "with_observers", "weighted", "energy", "ride", "KINDS"]

KINDS = {
    "integral": _kernel.OBS_LINEAR,
    "square": _kernel.OBS_SQUARE,
    "fourth": _kernel.OBS_FOURTH,
    "product": _kernel.OBS_PRODUCT,
    "peak": _kernel.OBS_PEAK,
}
#: what :mod:`.core` computes for a system and keeps in its ``info`` (its linear
#: regimes, their fastest rate, its augmented linear system, its ride observers, the
#: tables of its exact steps in the regimes and what they read of it, its observers'
#: panel share; a vehicle's comfort observers' system,
#: :func:`inerterlab.vehicles.simulation.simulate_vehicle`): the system with observers
#: computes its own
_CACHED = ("regime", "regime_rate", "observer_system", "ride_system", "regime_tables", "memo",
           "comfort_observed", "regime_read", "observer_share")


def uncached_info(info: dict, **extra) -> dict:
    """A new ``info`` dict for a system derived from one with ``info`` (new element rows,
    observers added): its description without what was computed and cached for the
    original (:data:`_CACHED`), plus ``extra``. Sharing or copying those caches would
    let the derived system run on the original's regime tables."""
    out = {k: v for k, v in info.items() if k not in _CACHED}
    out.update(extra)
    return out

def derive(sys, make):
    """``make(sys)``, a system derived from ``sys`` with new element rows (a Gaussian
    equivalent, a rebuilt equilibrium). A system with observers is derived through its
    base, and the observers are added again: its linear part (``info["base"]``, which
    the exact steps and the state space read) is then the derived one, not the
    original's."""
    if "base" in sys.info:
        return with_observers(make(sys.info["base"]), sys.info["observers"])
    return make(sys)


#: a running peak starts here (a finite number: the continuous extension subtracts
#: states, and -inf - -inf is NaN)
PEAK_START = -1e300


@dataclass(frozen=True)
class Observer:
    """One observer state.

    Parameters
    ----------
    name : str
        Its state name (unique in the system).
    kind : {"integral", "square", "fourth", "product", "peak"}
    signal : dict
        a = sum of coefficient x channel, channels by name (outputs, then states).
    other : dict, optional
        b of a ``product``.
    scale : float
        Typical size of the state; its absolute tolerance is rtol x scale.
    """

    name: str
    kind: str
    signal: dict
    other: dict | None = None
    scale: float = 1.0

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ParameterError("kind", self.kind, f"one of {', '.join(KINDS)}")
        if (self.kind == "product") != (self.other is not None):
            raise ParameterError("other", self.other, "a signal for a product, none otherwise")
        if not self.scale > 0:
            raise ParameterError("scale", self.scale, "a positive typical size")


def _channels(sys, names: tuple) -> dict:
    out = {n: i for i, n in enumerate(sys.output_names)}
    no = len(sys.output_names)
    for i, n in enumerate(names):
        out.setdefault(n, no + i)
    return out


def with_observers(sys, observers) -> System:  # noqa: F821
    """``sys`` with the observer states of ``observers`` appended (after those it has)."""
    base = sys.info.get("base", sys)
    old = tuple(sys.info.get("observers", ()))
    obs = old + tuple(observers)
    names = base.state_names + tuple(o.name for o in obs)
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise ParameterError("name", dup, "a state name not used already")
    ch = _channels(base, names)
    sig_rows: list[dict] = []

    def row(sig):
        for k in sig:
            if k not in ch:
                raise ParameterError(
                    "signal", k, f"an output or state of {base.description} "
                    f"({', '.join(base.output_names)}, or a state name)",
                )  # fmt: skip
        sig_rows.append({ch[k]: float(v) for k, v in sig.items()})
        return len(sig_rows) - 1

    orows = []
    nphys = base.n_states
    for q, o in enumerate(obs):
        a = row(o.signal)
        b = row(o.other) if o.other is not None else -1
        orows.append((KINDS[o.kind], a, b, nphys + q))
    ptr = np.zeros(len(sig_rows) + 1, np.int64)
    idx, coef = [], []
    for k, r in enumerate(sig_rows):
        for c, v in sorted(r.items()):
            idx.append(c)
            coef.append(v)
        ptr[k + 1] = len(idx)
    itab = np.array(base.itab, copy=True)
    ftab = np.array(base.ftab, copy=True)
    io = itab.size
    sg = io + _kernel.OBS_W * len(obs)
    itab = np.concatenate([itab, np.array(orows, np.int64).reshape(-1), ptr, np.array(idx, np.int64)])
    itab[_kernel.I_NOB] = len(obs)
    itab[_kernel.I_OBS] = io
    itab[_kernel.I_NSG] = len(sig_rows)
    itab[_kernel.I_SG] = sg
    itab[_kernel.I_SGF] = ftab.size
    ftab = np.concatenate([ftab, np.array(coef, float)])
    itab.setflags(write=False)
    ftab.setflags(write=False)
    x0 = [PEAK_START if o.kind == "peak" else 0.0 for o in obs]
    # the base's information, not what was computed and cached for the base alone
    info = uncached_info(base.info, base=base, observers=obs)
    return dataclasses.replace(
        base,
        state_names=names,
        itab=itab,
        ftab=ftab,
        x0_template=np.concatenate([base.x0_template, np.array(x0, float)]),
        state_scales=np.concatenate([base.state_scales, [o.scale for o in obs]]),
        info=info,
    )


#: five-point Gauss-Legendre nodes and weights on [0, 1]: the quadratures of the
#: observers that read a filter advanced outside the stages (exact for degree 9)
_GL_X, _GL_W = np.polynomial.legendre.leggauss(5)
_GL_X, _GL_W = 0.5 * (_GL_X + 1.0), 0.5 * _GL_W
_GL_X[3:] = 1.0 - _GL_X[1::-1]  # symmetric about 1/2 to the last bit (_fz_step uses it)
_GL_W[3:] = _GL_W[1::-1]
assert _GL_X[2] == 0.5  # the middle node (its exponential serves a step's midpoint)
#: no filter outside the stages (the tables of :func:`filter_split`: their header of
#: counts, all zero)
NO_SPLIT = (np.zeros(5, np.int64), np.empty(0), np.empty(0, np.complex128))


def filter_split(itab, ftab, n: int):
    """(oit, fzi, fzf, fzc): a copy of ``itab`` whose observers are those the stages
    move (neither split nor running peaks: the others get derivative 0 there), or
    ``itab`` itself where nothing is split, and the tables of the linear filter among a
    system's observers that the adaptive Dormand-Prince steps advance outside their
    stages (their layout: :mod:`._integrate`, before :func:`._integrate._fz_begin`), or
    :data:`NO_SPLIT`. ``n``: the number of states.

    The filter: the ``integral`` observers, z' = A z + u, where one of them reads
    another (the Wk weighting, as :func:`weighted` builds it; A not zero). Its inputs u
    must be P y + Q y' over the system's own states y: node displacements and
    velocities of mass nodes, states, and mass nodes' accelerations (the derivative of
    their velocity states). Then w = z - Q y obeys w' = A w + (A Q + P) y, a linear
    filter of the states alone, which the step's continuous extension (a quartic in the
    step's fraction, the order of the motion's own accuracy) drives exactly: per
    eigenvalue of A = V diag(lam) V^-1 the phi-functions of lam h (one of each complex
    pair). The observers that read the filter (``square``, ``fourth``, ``product``:
    their signals over states only) are five-node Gauss-Legendre sums over the step on
    the exact filter. Neither is in the stages nor in the error control, so the step
    follows the motion, not the filter's fastest section (Wk: 100 Hz, which bounded the
    explicit step by stability once the motion settled). No split (the stages carry
    everything, as before) where the system has no states of its own, an input or a
    quadrature reads anything else, another observer reads a split state, or A's
    eigenvectors are ill-conditioned (condition number above 1e6).

    Kept for the last :data:`SPLITS_KEPT` by what it reads: the integer table and the
    coefficients of the signals of the ``integral`` observers and of the quadratures
    that read their states (:func:`_filter_coefficients`), so the cars of a sweep,
    which differ in their element values and in the tyre-grip coefficient, share the
    split of their one Wk filter. Looked up first by the whole tables (a system run
    again: the coefficients' key takes about 40 us to build, the tables' bytes 1 us)."""
    whole = (itab.tobytes(), ftab.tobytes(), n)
    got = _SPLITS_BY_TABLES.get(whole)
    if got is not None:
        return got
    key = (whole[0], _filter_coefficients(itab, ftab), n)
    got = _SPLITS.get(key)
    if got is None:
        ro = np.frombuffer(key[0], np.int64)  # read only, as the tables
        out = _split(ro, ftab, n)
        got = (ro, *NO_SPLIT) if out is None else out
        _keep(_SPLITS, key, got)
    _keep(_SPLITS_BY_TABLES, whole, got)
    return got


#: the splits of :func:`filter_split` kept in a process (by what they read, and by the
#: whole tables)
SPLITS_KEPT = 64
_SPLITS: dict = {}
_SPLITS_BY_TABLES: dict = {}


def _keep(kept: dict, key, value) -> None:
    """Keep ``value`` under ``key``, the oldest entry dropped past :data:`SPLITS_KEPT`."""
    if len(kept) >= SPLITS_KEPT:
        kept.pop(next(iter(kept)))
    kept[key] = value


def _filter_coefficients(itab, ftab) -> bytes:
    """The coefficients :func:`_split` reads of ``ftab``, as bytes: those of the signals
    of the ``integral`` observers and of the quadratures that read one of their states
    (the others' and the peaks' signals are read for their channels only, which
    ``itab`` holds: a car's tyre-grip quadrature, whose coefficient is the car's
    static tyre load, does not reach the split)."""
    K = _kernel
    ob, sg, cf = int(itab[K.I_OBS]), int(itab[K.I_SG]), int(itab[K.I_SGF])
    ci = sg + int(itab[K.I_NSG]) + 1
    no = 3 * int(itab[K.I_NN]) + int(itab[K.I_NE])
    nob = int(itab[K.I_NOB])
    rows = [itab[ob + K.OBS_W * q : ob + K.OBS_W * (q + 1)] for q in range(nob)]
    filt = {int(r[3]) + no for r in rows if r[0] == K.OBS_LINEAR}  # their states' channels
    parts = []
    for r in rows:
        kind = r[0]
        if kind == K.OBS_PEAK:
            continue
        reads = [int(r[1])]
        if kind == K.OBS_PRODUCT:  # a product's second factor
            reads.append(int(r[2]))
        spans = [(int(itab[sg + a]), int(itab[sg + a + 1])) for a in reads]
        if kind != K.OBS_LINEAR and not any(
            int(itab[ci + j]) in filt for a, b in spans for j in range(a, b)
        ):
            continue  # a quadrature of no filter state
        for a, b in spans:
            parts.append(ftab[cf + a : cf + b])
    return np.concatenate(parts).tobytes() if parts else b""


def _split(itab, ftab, n):  # noqa: C901 (one pass of checks over the tables)
    K = _kernel
    nob = int(itab[K.I_NOB])
    if nob == 0:
        return None
    ob = int(itab[K.I_OBS])
    rows = [tuple(int(v) for v in itab[ob + K.OBS_W * q : ob + K.OBS_W * (q + 1)]) for q in range(nob)]
    slot_of = {r[3]: q for q, r in enumerate(rows)}
    nn, ne = int(itab[K.I_NN]), int(itab[K.I_NE])
    no = 3 * nn + ne
    sg, nsg, cf = int(itab[K.I_SG]), int(itab[K.I_NSG]), int(itab[K.I_SGF])

    def sig(k):
        ci = sg + nsg + 1
        return [(int(itab[ci + j]), float(ftab[cf + j])) for j in range(itab[sg + k], itab[sg + k + 1])]

    mech = [s for s in range(n) if s not in slot_of]
    if not mech:  # nothing else to set the step: the stages carry the filter
        return None
    lin = [q for q, r in enumerate(rows) if r[0] == K.OBS_LINEAR]
    fcol = {rows[q][3]: i for i, q in enumerate(lin)}  # filter state -> its index
    nf = len(lin)

    def node_state(c):
        """(state, derivative?) of an output channel of a mass node, or None."""
        node, kind = c % nn, c // nn
        b = int(itab[K.I_NODE]) + K.NODE_W * node
        if kind > 2 or itab[b] != K.DYN:
            return None
        return (int(itab[b + 1]), False) if kind == 0 else (int(itab[b + 2]), kind == 2)

    A = np.zeros((nf, nf))
    P = np.zeros((nf, n))
    Q = np.zeros((nf, n))
    for i, q in enumerate(lin):
        for c, v in sig(rows[q][1]):
            if c >= no and c - no in fcol:
                A[i, fcol[c - no]] += v
            elif c >= no and c - no in slot_of:
                return None  # reads another observer's state
            elif c >= no:
                P[i, c - no] += v
            else:
                ns = node_state(c) if c < 3 * nn else None
                if ns is None:
                    return None
                (Q if ns[1] else P)[i, ns[0]] += v
    if not nf or not A.any():
        return None
    split = set(fcol)
    quad = []
    for q, r in enumerate(rows):
        if r[0] in (K.OBS_SQUARE, K.OBS_FOURTH, K.OBS_PRODUCT):
            chans = sig(r[1]) + (sig(r[2]) if r[2] >= 0 else [])
            if any(c >= no and c - no in split for c, _ in chans):
                if any(c < no or (c - no in slot_of and c - no not in split) for c, _ in chans):
                    return None  # a quadrature over anything but states and the filter
                quad.append(q)
    qslots = {rows[q][3] for q in quad}
    qread = {  # the system's own states the quadratures read
        c - no
        for q in quad
        for c, _ in sig(rows[q][1]) + (sig(rows[q][2]) if rows[q][2] >= 0 else [])
        if c - no not in split
    }
    for q, r in enumerate(rows):  # nothing else reads a quadrature; only peaks, the filter
        if q in quad or q in lin:
            continue
        chans = sig(r[1]) + (sig(r[2]) if r[2] >= 0 else [])
        reads = {c - no for c, _ in chans if c >= no}
        if reads & qslots or (r[0] != K.OBS_PEAK and reads & split):
            return None
    lam, V = np.linalg.eig(A)
    if np.linalg.cond(V) > 1e6:
        return None
    Vi = np.linalg.inv(V)
    # one eigenvalue of each complex pair (weight 2: the pair's sum is twice its real
    # part), the real ones (weight 1)
    tol = 1e-12 * max(1.0, float(np.max(np.abs(lam))))
    keep = [m for m in range(nf) if lam[m].imag > tol or abs(lam[m].imag) <= tol]
    om = np.array([2.0 if lam[m].imag > tol else 1.0 for m in keep])
    probe = np.random.default_rng(0).standard_normal(nf)
    back = (V[:, keep] * om) @ (Vi[keep] @ probe)
    if np.max(np.abs(back.real - probe)) > 1e-9 * np.max(np.abs(probe)):
        return None  # the pairs are not conjugate to rounding
    G = A @ Q + P
    used = np.any(G != 0.0, axis=0) | np.any(Q != 0.0, axis=0)
    used[sorted(qread)] = True
    cols = np.flatnonzero(used)
    # the stages' observers: the rows of those they move first, and only those counted
    dead = split | qslots | {r[3] for r in rows if r[0] == K.OBS_PEAK}
    order = [q for q, r in enumerate(rows) if r[3] not in dead]
    order += [q for q, r in enumerate(rows) if r[3] in dead]
    oitab = np.array(itab, copy=True)
    oitab[ob : ob + K.OBS_W * nob] = np.concatenate([itab[ob + K.OBS_W * q : ob + K.OBS_W * (q + 1)] for q in order])
    oitab[K.I_NOB] = sum(r[3] not in dead for r in rows)
    oitab.setflags(write=False)
    dead = sorted(dead)
    fzi = np.array(
        [nf, cols.size, len(quad), len(dead), len(keep), *(rows[q][3] for q in lin), *cols,
         *quad, *dead], np.int64,
    )  # fmt: skip
    # each quadrature's signals (two rows a quadrature, the second zero but for a
    # product) over the filter's modes (S, on the modes' values with their weights, as
    # the step keeps them) and over the states it reads (R): a signal is then a few
    # products at each node, not the filter's states and a walk of the tables
    col_of = {int(c): j for j, c in enumerate(cols)}
    S = np.zeros((2 * len(quad), len(keep)), complex)
    R = np.zeros((2 * len(quad), cols.size))
    for k, q in enumerate(quad):
        for half, a in enumerate((rows[q][1], rows[q][2])):
            if a < 0 or (half and rows[q][0] != K.OBS_PRODUCT):
                continue
            for c, v in sig(a):
                s = c - no
                if s in fcol:
                    S[2 * k + half] += v * V[fcol[s], keep]
                    R[2 * k + half] += v * Q[fcol[s], cols]
                else:
                    R[2 * k + half, col_of[s]] += v
    fzf = np.concatenate([Q[:, cols].ravel(), om, _GL_X, _GL_W, R.ravel()])
    fzc = np.concatenate([lam[keep], V[:, keep].ravel(), Vi[keep].ravel(), (Vi[keep] @ G[:, cols]).ravel(),
                          S.ravel()])  # fmt: skip
    return oitab, fzi, fzf, fzc.astype(np.complex128)


def weighted(name: str, signal: dict, A, B, C, D, *, scale: float = 1.0):
    """(observers, weighted signal) of the linear filter z' = A z + B a, w = C z + D a
    of the signal a: its states ``<name>.z0``, ... (``integral`` observers), and w as a
    signal over them and a's channels (for a ``square``, ``fourth`` or ``peak``)."""
    A = np.atleast_2d(np.asarray(A, float))
    B = np.ravel(np.asarray(B, float))
    C = np.ravel(np.asarray(C, float))
    n = A.shape[0]
    zs = [f"{name}.z{i}" for i in range(n)]
    obs = []
    for i in range(n):
        sig = {zs[j]: A[i, j] for j in range(n) if A[i, j] != 0.0}
        for k, v in signal.items():
            if B[i] != 0.0:
                sig[k] = sig.get(k, 0.0) + B[i] * v
        obs.append(Observer(zs[i], "integral", sig, scale=scale))
    w = {zs[j]: C[j] for j in range(n) if C[j] != 0.0}
    for k, v in signal.items():
        if float(D) != 0.0:
            w[k] = w.get(k, 0.0) + float(D) * v
    return obs, w


def _masses(sys) -> dict:
    it = sys.itab
    fm = int(it[_kernel.I_FMASS])
    return {
        n: float(sys.ftab[fm + i])
        for i, n in enumerate(sys.node_names)
        if sys.ftab[fm + i] > 0.0
    }


def energy(sys, *, scale: float = 1e-2) -> list[Observer]:
    """The energy ledger [J] of a system: ``energy.<element>``, the work done on each
    element (its force times its relative velocity, integrated: the energy a spring
    stores, a damper dissipates, an inerter holds as kinetic energy); ``energy.<node>``,
    the kinetic energy a mass gains; ``energy.input``, the work the road (a rig's
    drive) does on the system. Input = sum of the others, to the integration's
    tolerance (tests/test_core_observers.py)."""
    base = sys.info.get("base", sys)
    nodes = base.node_names
    obs = []
    drive = []
    for e, name in enumerate(base.element_names):
        top, bot = int(base.itab[base.itab[_kernel.I_ELEM] + _kernel.ELEM_W * e + 1]), int(
            base.itab[base.itab[_kernel.I_ELEM] + _kernel.ELEM_W * e + 2]
        )
        vt, vb = f"{nodes[top]}.v", f"{nodes[bot]}.v"
        rel = {vt: 1.0} if top == bot else {vt: 1.0, vb: -1.0}
        obs.append(Observer(f"energy.{name}", "product", {f"{name}.force": 1.0}, rel, scale=scale))
        # the road pushes the element with +F at its top, -F at its bottom
        if base.node_types[top] == _kernel.ROAD:
            drive.append((name, 1.0, vt))
        if base.node_types[bot] == _kernel.ROAD:
            drive.append((name, -1.0, vb))
    for n, m in _masses(base).items():
        obs.append(Observer(f"energy.{n}", "product", {f"{n}.a": m}, {f"{n}.v": 1.0}, scale=scale))
    if drive:
        sig: dict = {}
        for name, s, _ in drive:
            sig[f"{name}.force"] = sig.get(f"{name}.force", 0.0) + s
        obs.append(Observer("energy.input", "product", sig, {drive[0][2]: 1.0}, scale=scale))
    return obs


#: the ride observers of a quarter car and their typical sizes (absolute tolerance
#: rtol x size): int a^2, int grip^2, int z^2, the Wk filter, int a_w^2, int a_w^4. The
#: Wk filter's states (of the size of an acceleration, 0.1 m/s^2) get a 100 x looser
#: absolute tolerance where they are in the stages (the fixed RK4 steps; the adaptive
#: steps advance the filter outside them, :func:`filter_split`): the filter is linear and
#: stable, its error does not grow, and at the acceleration's own tolerance its 100 Hz
#: section set the step size (the ch. 4-6 runs of the traditional, afw and device cars:
#: 66 670 steps and rejections at 0.1, 47 313 at 10, 39 645 at 1000; docs/decisions.md,
#: "Observers")
RIDE_SCALES = {"i_acc": 1e-2, "i_grip": 1e-4, "i_defl": 1e-7, "wk": 1e1, "i_wk": 1e-2, "i_wk4": 1e-3}


def ride(sys) -> list[Observer]:
    """The ride observers of a quarter car (:func:`inerterlab.systems.quarter_car`):
    ``ride.i_acc`` = int a3^2, ``ride.i_grip`` = int grip^2 (4.20), ``ride.i_defl`` =
    int z^2, the ISO 2631-1 Wk filter of a3 (``ride.wk.z0``, ...), ``ride.i_wk`` = int
    a_w^2, ``ride.i_wk4`` = int a_w^4 (VDV), and the running peaks of +-a3, +-a_w, +-z
    and the tyre's dynamic force (``ride.peak_*``)."""
    from ..metrics import wk_state_space

    base = sys.info.get("base", sys)
    if base.kind != "quarter_car":
        raise ParameterError("sys", base.description, "a quarter car (systems.quarter_car)")
    car = base.info["car"]
    load = (car["sprung_mass"] + car["unsprung_mass"]) * car["gravity"]
    g = car["tyre_stiffness"] / load
    acc = {"body.a": 1.0}
    defl = {"body.x": 1.0, "wheel.x": -1.0}
    tyre = {f"{e}.force": 1.0 for e in base.element_names if e in ("tyre", "tyre_k", "tyre_c")}
    s = RIDE_SCALES
    wk_obs, aw = weighted("ride.wk", acc, *wk_state_space(), scale=s["wk"])
    neg = lambda d: {k: -v for k, v in d.items()}  # noqa: E731
    return [
        Observer("ride.i_acc", "square", acc, scale=s["i_acc"]),
        Observer("ride.i_grip", "square", {"wheel.x": g, "road.x": -g}, scale=s["i_grip"]),
        Observer("ride.i_defl", "square", defl, scale=s["i_defl"]),
        *wk_obs,
        Observer("ride.i_wk", "square", aw, scale=s["i_wk"]),
        Observer("ride.i_wk4", "fourth", aw, scale=s["i_wk4"]),
        Observer("ride.peak_acc", "peak", acc),
        Observer("ride.peak_neg_acc", "peak", neg(acc)),
        Observer("ride.peak_wk", "peak", aw),
        Observer("ride.peak_neg_wk", "peak", neg(aw)),
        Observer("ride.peak_defl", "peak", defl),
        Observer("ride.peak_neg_defl", "peak", neg(defl)),
        Observer("ride.peak_tyre", "peak", tyre),
    ]


def ride_metrics(observed: dict, horizon: float, static_load: float) -> dict:
    """The ride metrics (:data:`inerterlab.metrics.METRIC_KEYS`) from the final values of
    the :func:`ride` observers over ``horizon`` [s]; ``static_load`` (M + M_t) g [N].

    RMS = sqrt(int a^2 / T) (4.15, 4.21, 4.26), the Wk RMS likewise, VDV = (int a_w^4)^(1/4),
    crest factor = peak |a_w| / RMS a_w, ``min_tyre_force`` = static load minus the
    largest dynamic tyre force (unclipped: negative where the tyre would pull)."""
    import math

    v = observed
    T = horizon
    rms_wk = math.sqrt(max(v["ride.i_wk"], 0.0) / T)
    peak_wk = max(v["ride.peak_wk"], v["ride.peak_neg_wk"])
    return {
        "rms_body_acc": math.sqrt(max(v["ride.i_acc"], 0.0) / T),
        "rms_tyre_grip": math.sqrt(max(v["ride.i_grip"], 0.0) / T),
        "rms_deflection": math.sqrt(max(v["ride.i_defl"], 0.0) / T),
        "rms_body_acc_wk": rms_wk,
        "vdv": max(v["ride.i_wk4"], 0.0) ** 0.25,
        "crest_factor": peak_wk / rms_wk if rms_wk > 0 else 0.0,
        "peak_body_acc": max(v["ride.peak_acc"], v["ride.peak_neg_acc"]),
        "peak_body_acc_wk": peak_wk,
        "peak_deflection": max(v["ride.peak_defl"], v["ride.peak_neg_defl"]),
        "min_tyre_force": static_load - v["ride.peak_tyre"],
        "tyre_lift_off": bool(v["ride.peak_tyre"] >= static_load),
    }
