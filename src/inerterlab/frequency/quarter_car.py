"""The quarter car as a first-order system for the harmonic balance.

A quarter car of :func:`inerterlab.quarter_car` with a named smooth suspension is
balanced as the model core's quarter car (the suspension's preset network ``k | c``,
``k | c | b`` or ``k | c | afw`` between body and wheel with the car's values): the balance evaluates the
core's compiled right-hand side and outputs, the same functions its time simulation
integrates (docs/model.md §11): no second copy of the physics. The states in the balance
are the core system's (``state_names``); the outputs are computed from the periodic
states afterwards:

``body_displacement`` [m]      body.x
``body_acceleration`` [m/s^2]  body.a
``suspension_deflection`` [m]  body.x - wheel.x
``tyre_force`` [N]             the tyre spring's and damper's forces

The road is X1 = A sin(Omega t). A system with several roads (a half or full car) is
driven through a *road pattern* (:func:`from_core_system` ``pattern``): road k is
A g_k sin(Omega t + phi_k - Omega d_k), a gain g_k, a phase phi_k and a delay d_k [s]
(the rear wheels a wheelbase behind the front ones at a speed V: d = L / V). The engine
still drives one sine; the compiled right-hand side of :func:`patterned_rhs` spreads it
over the roads, so the balance, its Jacobian, the stability and the brute-force time
integration are the same code for one road or several.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numba import njit

from ..errors import ParameterError
from ..systems import _compiled, _kernel
from .first_order import FREQ_SLOT, FirstOrderSystem

__all__ = [
    "FirstOrderSystem",
    "quarter_car_system",
    "from_core_system",
    "QUARTER_CAR_OUTPUTS",
    "SMOOTH_SUSPENSIONS",
    "patterned_rhs",
    "patterned_outputs",
]

#: output name -> unit
QUARTER_CAR_OUTPUTS = {
    "body_displacement": "m",
    "body_acceleration": "m/s^2",
    "suspension_deflection": "m",
    "tyre_force": "N",
}
SMOOTH_SUSPENSIONS = ("traditional", "cfw", "afw")


def quarter_car_system(car) -> FirstOrderSystem:
    """The first-order system of a quarter car with a named smooth suspension.

    ``car`` is what :func:`inerterlab.quarter_car` returns for ``traditional``, ``cfw``
    or ``afw`` (a core system carrying its description in ``info["model"]``), or that
    description (:class:`~inerterlab.suspension.model.QuarterCar`), which is built into
    the same core system from its preset network
    (:func:`inerterlab.systems.quarter_car.preset_network`).

    ``device`` and ``device-afw`` carry the friction of the real device,
    F_fh tanh(u / v_eps) with v_eps of order 1e-3 m/s, a near-switch that needs hundreds
    of harmonics; they are refused with a pointer to the time simulation, as is a tyre
    that may lift off (a switch too).
    """
    from ..suspension.model import QuarterCar
    from ..systems import System
    from ..systems import quarter_car as core_quarter
    from ..systems.quarter_car import preset_network

    core = car if isinstance(car, System) else None
    model = core.info.get("model") if core is not None else car
    if not isinstance(model, QuarterCar):
        raise ParameterError(
            "system", car, "a quarter car of inerterlab.quarter_car with a named suspension"
        )
    if model.suspension not in SMOOTH_SUSPENSIONS:
        raise ParameterError(
            "suspension",
            model.suspension,
            "traditional, cfw or afw for the harmonic balance (the real device's friction "
            "tanh(u/v_eps) switches within millimetres per second, beyond a truncated "
            "Fourier series; use `inerterlab simulate` with a sine road for it)",
        )
    if model.tyre_lift_off:
        raise ParameterError(
            "tyre_lift_off", True, "False for the harmonic balance (a tyre leaving the road "
            "is a switch; use `inerterlab simulate` with a sine road for it)",
        )  # fmt: skip
    if core is None:
        text, elements = preset_network(model)
        core = core_quarter(text, elements, parameters=model.parameters)
    fo = from_core_system(core)
    return FirstOrderSystem(
        **{f: getattr(fo, f) for f in fo.__dataclass_fields__ if f != "label"},
        label=f"quarter car, {model.suspension}",
    )


_PAIRS = ((".x", ".v"), (".x_rel", ".v_rel"), (".slider_radius", ".slider_rate"))


def velocity_pairs(system, rhs=None, tables=None) -> tuple[int, ...]:
    """``velocity_of`` of a core system: each displacement state whose derivative is,
    by its name, a velocity state (``n.x``/``n.v``, ``n.x_rel``/``n.v_rel``, the
    sliders' radius and rate), kept only where the compiled right-hand side returns
    exactly that state as its derivative at a trial state."""
    names = list(system.state_names)
    n = len(names)
    vel = [-1] * n
    for i, name in enumerate(names):
        for a, b in _PAIRS:
            if name.endswith(a) and name[: -len(a)] + b in names:
                vel[i] = names.index(name[: -len(a)] + b)
    if max(vel) < 0:
        return tuple(vel)
    itab, ftab = system.tables if tables is None else tables
    x = np.asarray(system.initial_state(), dtype=float).copy()
    x += 1e-3 * np.sin(np.arange(1, n + 1)) * np.asarray(system.state_scales, dtype=float)
    out = np.zeros(n)
    road = np.array([1e-3, 1e-2, 1e-1, 2.0 * np.pi])
    ok = (system.rhs if rhs is None else rhs)(0.1, x, road, np.array(itab), np.array(ftab), out)
    return tuple(j if ok and j >= 0 and out[i] == x[j] else -1 for i, j in enumerate(vel))


@njit(cache=True, inline="always")
def _spread(road, itab, ftab, r):
    """The core road vector of every road of a pattern into ``r`` (``free`` + 1 entries,
    :func:`inerterlab.systems._kernel.road_layout_of`) from the engine's one sine
    ``road`` = [A sin tau, A Omega cos tau, -A Omega^2 sin tau, Omega] (the pattern at
    the end of the tables: itab[-2] roads, from ftab[itab[-1]] (gain, phase, delay) each)."""
    n = itab.size
    m = itab[n - 2]
    po = itab[n - 1]
    _, free, _ = _kernel.road_layout_of(itab)
    r[: free + 1] = 0.0  # no held sides: the elements' own laws
    w = road[FREQ_SLOT]
    u0, u1, u2 = road[0], road[1], road[2]
    for k in range(m):
        g = ftab[po + 3 * k]
        th = ftab[po + 3 * k + 1] - w * ftab[po + 3 * k + 2]
        c = math.cos(th)
        s = math.sin(th)
        # A g sin(tau + th) and its derivatives, from the one sine and its derivatives
        r[3 * k] = g * (c * u0 + s * u1 / w)
        r[3 * k + 1] = g * (c * u1 + s * u2 / w)
        r[3 * k + 2] = g * (c * u2 - s * w * u1)
    r[free] = w
    return r[: free + 1]


def pattern_size(itab) -> int:
    """The entries of the road vector of a pattern (:func:`_spread`), which the
    patterned evaluations keep past the buffer of :func:`buffer_size`."""
    return int(_kernel.road_layout_of(itab)[1]) + 1


def buffer_size(itab) -> int:
    """The ``work_size`` of a core system as a first-order system: its states, then the
    work array of its evaluation (:func:`buffered_rhs`)."""
    n = int(itab[_kernel.I_NS] + itab[_kernel.I_NOB])
    return n + _kernel.work_size(itab)


@njit(cache=True)
def buffered_rhs(t, x, road, itab, ftab, out):
    """The core right-hand side (:func:`inerterlab.systems._kernel.rhs`, the same
    evaluation to the last bit) with its work array in ``out`` past the derivatives:
    out[:n] = x', out[n:] the work array, where ``out`` has :func:`buffer_size` entries
    (the engine's arrays do: the system's ``work_size``), so that a call allocates
    nothing and counts no references (docs/decisions.md, stop 58). It is the time
    integration's generic code: a division by zero gives inf or NaN (the point then
    fails as non-finite), not an exception, as everywhere. A shorter ``out`` is served as
    :func:`inerterlab.systems._kernel.rhs` serves it."""
    n = itab[_kernel.I_NS] + itab[_kernel.I_NOB]
    w = _kernel._work_size(itab)
    if out.size < n + w:
        return _kernel.rhs(t, x, road, itab, ftab, out)
    return _rhs_in(float(t), x, road, itab, ftab, out, n, w)


@njit(cache=True, _nrt=False)
def _rhs_in(t, x, road, itab, ftab, out, n, w):
    W = out[n : n + w]
    dx = out[:n]
    ok = _kernel.evaluate(t, x, road, _kernel.readonly(itab), _kernel.readonly(ftab), W, dx,
                          out[:0])  # fmt: skip
    if itab[_kernel.I_NOB] > 0:
        _kernel.observe(_kernel.readonly(itab), _kernel.readonly(ftab), W, x, dx, np.bool_(False))
    return ok


@njit(cache=True)
def buffered_outputs(t, x, road, itab, ftab, out):
    """The core outputs (:func:`inerterlab.systems._kernel.outputs`: node displacements,
    velocities, accelerations, element forces, into out[:3 nn + ne]) with the work array
    in ``out`` itself, where it has :func:`buffer_size` entries: no allocation per call.
    A shorter ``out`` is served as :func:`inerterlab.systems._kernel.outputs` serves it."""
    n = itab[_kernel.I_NS] + itab[_kernel.I_NOB]
    w = _kernel._work_size(itab)
    if out.size < n + w:
        return _kernel.outputs(t, x, road, itab, ftab, out)
    return _outputs_in(float(t), x, road, itab, ftab, out, n, w)


@njit(cache=True, _nrt=False)
def _outputs_in(t, x, road, itab, ftab, out, n, w):
    return _kernel.evaluate(t, x, road, _kernel.readonly(itab), _kernel.readonly(ftab), out[:w],
                            out[w : w + n], out[:0])  # fmt: skip


@njit(cache=True)
def patterned_rhs(t, x, road, itab, ftab, out):
    """The core right-hand side (:func:`buffered_rhs`) with every road driven by the
    pattern at the end of the tables (:func:`_spread`), the road vector kept in ``out``
    past the work array where it has room (:func:`buffer_size` + :func:`pattern_size`
    entries: the engine's arrays do), else allocated."""
    n = itab[_kernel.I_NS] + itab[_kernel.I_NOB]
    w = _kernel._work_size(itab)
    free = _kernel.road_layout_of(itab)[1]
    if out.size < n + w + free + 1:
        return buffered_rhs(t, x, _spread(road, itab, ftab, np.empty(free + 1)), itab, ftab, out)
    return _rhs_in(float(t), x, _spread(road, itab, ftab, out[n + w :]), itab, ftab, out, n, w)


@njit(cache=True)
def patterned_outputs(t, x, road, itab, ftab, out):
    """The core outputs (:func:`buffered_outputs`) under the pattern, its road vector
    kept as in :func:`patterned_rhs`."""
    n = itab[_kernel.I_NS] + itab[_kernel.I_NOB]
    w = _kernel._work_size(itab)
    free = _kernel.road_layout_of(itab)[1]
    if out.size < n + w + free + 1:
        return buffered_outputs(t, x, _spread(road, itab, ftab, np.empty(free + 1)), itab, ftab,
                                out)  # fmt: skip
    return _outputs_in(float(t), x, _spread(road, itab, ftab, out[n + w :]), itab, ftab, out, n, w)


def _pattern_tables(system, pattern):
    """The system's tables with the road pattern (m, 3: gain, phase [rad], delay [s])
    appended (the core reads its tables by the offsets of their headers, so what follows
    them is not seen)."""
    itab, ftab = system.tables
    m = max(int(system.info.get("roads", 1)), 1)
    P = np.asarray(pattern, dtype=float)
    if P.shape != (m, 3) or not np.all(np.isfinite(P)) or np.any(P[:, 2] < 0):
        raise ParameterError(
            "pattern", P.tolist(), f"{m} rows (gain, phase [rad], delay >= 0 [s]) of finite values"
        )
    ft = np.concatenate([np.asarray(ftab, float), P.ravel()])
    it = np.concatenate([np.asarray(itab, np.int64), [m, len(ftab)]]).astype(np.int64)
    return it, ft


def from_core_system(system, pattern=None) -> FirstOrderSystem:
    """A system of the model core (``inerterlab.systems``: ``n_states``, ``rhs``,
    ``tables``, compiled ``outputs`` and ``output_names``) as a first-order system.

    ``pattern`` (one row per road: gain, phase [rad], delay [s]) drives a system of
    several roads (a vehicle; module docstring); a system of one road may go without.

    Every velocity state that is the derivative of a displacement state is eliminated
    from the unknowns (:func:`velocity_pairs`). A quarter car (nodes ``body``, ``wheel``
    and the tyre elements ``tyre_k``, ``tyre_c``) reports the four quarter-car outputs; any other system reports every
    node displacement, velocity, acceleration and element force by its name.
    """
    names = tuple(system.output_names)
    index = {name: i for i, name in enumerate(names)}
    roads = int(getattr(system, "info", {}).get("roads", 1))
    if pattern is None and roads > 1:
        raise ParameterError(
            "pattern", None, f"a road pattern (gain, phase, delay) for each of the {roads} roads"
        )
    on_generic = None
    if pattern is None:
        itab, ftab = system.tables
        # the structure's own code where the time integration would take it, else the
        # generic code: the same arithmetic (bit for bit), whose time then counts towards
        # compiling the structure (as an integration's does)
        own = _compiled.first_order_for(itab)
        rhs, outfn = own or (buffered_rhs, buffered_outputs)
        if own is None:
            on_generic = functools.partial(_compiled.record, np.array(itab, dtype=np.int64))
    else:
        itab, ftab = _pattern_tables(system, pattern)
        rhs, outfn = patterned_rhs, patterned_outputs
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
        rhs=rhs,
        velocity_of=velocity_pairs(system, rhs, (itab, ftab)),
        int_table=np.array(itab, dtype=np.int64),
        float_table=np.array(ftab, dtype=float),
        work_size=buffer_size(itab) + (0 if pattern is None else pattern_size(itab)),
        state_scales=np.asarray(system.state_scales, dtype=float),
        rest_state=np.asarray(system.initial_state(), dtype=float),
        compiled_outputs=outfn,
        n_outputs=len(names),
        combine_outputs=combine,
        output_units=units,
        response_state=response,
        label=str(getattr(system, "description", "model-core system")),
        on_generic=on_generic,
    )
