"""Static equilibrium of a vehicle that rests on nonlinear springs.

The vehicle's coordinates are displacements from static equilibrium. With linear struts
that equilibrium never needs computing (superposition); a corner device whose gas spring
or bump stop (:mod:`inerterlab.elements`) sits straight across the strut carries part of
the weight by its nonlinear law, so the equilibrium is solved: with K0 the static
stiffness of the linear laws (struts, tyres, anti-roll bars) and T_j(e) the tension of
corner j's nonlinear springs at the strut extension e (from their force-free lengths),

    K0 q + sum_j u_j T_j(u_j . q) = f_g        (f_g the weights on q),

by Newton's method (:func:`inerterlab.systems.equilibrium.newton`), the same route as the
core systems' :func:`~inerterlab.systems.equilibrium`. Each such spring then takes its law
about its static extension (F(e0 + e) - F(e0)), so it carries no force at q = 0 and the
coordinates stay deviations from rest; the static tyre loads come from this equilibrium.
An equilibrium beyond a spring's working range (a gas spring's stroke, a bump stop's
travel) is refused, naming the corner.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import NetworkError

__all__ = ["rest_on_springs"]


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
    """``vehicle`` (a :class:`~inerterlab.vehicles.model.LinearVehicle`) at its static
    equilibrium: unchanged if no nonlinear spring carries load; otherwise with each such
    spring about its static extension and ``static_state`` the equilibrium q0 [m, rad]
    from the force-free configuration."""
    from ..systems.equilibrium import newton
    from .parameters import _split

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
