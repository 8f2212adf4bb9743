"""Gaussian-equivalent (statistical) linearisation of the elements of a core system.

Under a stationary zero-mean Gaussian response, the linear law that comes closest to a
nonlinear element's force F in mean square is, by Gaussian integration by parts (Stein's
lemma; Roberts and Spanos, *Random Vibration and Statistical Linearization*, Wiley 1990,
ch. 5), the expectation of its derivatives: F ~ k_eq y + c_eq v + b_eq a with

    k_eq = E[dF/dy] = E[y F] / sigma_y^2,   c_eq = E[dF/dv] = E[v F] / sigma_v^2,
    b_eq = E[dF/da],

y, v, a the element's relative displacement, velocity and acceleration (top minus
bottom). In a stationary response y and v are uncorrelated, and so are v and a, hence
(jointly Gaussian) independent. Each expectation here is a quadrature against the
Gaussian density of the element's *own* compiled force function, the one the time
integration evaluates (spring, damper, friction and flywheel-row kernel laws), so a new
element of an existing kernel law needs nothing extra:

* elastic rows (springs, gas springs, bump stops, backlash): k_eq = E[y F(y)] / sigma_y^2;
* dissipative rows (dampers with a quadratic or asymmetric law, friction):
  c_eq = E[v F(v)] / sigma_v^2;
* the adaptive-flywheel inerter (force m_e(v) a, laws ``thesis`` and ``momentum``):
  b_eq = E[m_e(v)] (v and a independent, so E[m_e(v) a^2] / E[a^2] = E[m_e(v)]).

A rectifying law (an asymmetric damper: slope c1 while extending, c2 while shortening)
also has a mean force under a zero-mean motion, E[F(v)] = (c1 - c2) sigma_v / sqrt(2 pi)
for the two-slope damper: :func:`mean_force` gives it from the element's own law, and
the statistical linearisation applies it to the equivalent car as a constant load, which
sets the car down (or up) by a mean offset. A velocity's mean is zero in a stationary
response, so this is exact for the dissipative rows; an inertance's mean force
E[m_e(v) a] = E[m_e(v)] E[a] is zero. (An elastic law's mean force would move its
operating point, which changes its equivalent in turn; that coupling is not solved.)

Linear elements (springs, linear dampers, inerters, a tyre that always presses) keep
their law. Elements whose force depends on states of their own or on a contact rule (a
one-way clutch, a ball screw with backlash, sliders with dynamics) and a tyre that
lifts off have no such equivalent: :func:`nonlinear_elements` refuses them, naming the
element.

:func:`equivalent_system` is the system with every nonlinear element replaced by a row
of its own kernel law whose linearisation about rest is the equivalent (a spring row of
stiffness k_eq; a damper row c_eq; a friction row whose slope at rest F_c / v_eps is
c_eq; a flywheel row of constant inertance b_eq), so the one linearisation of the core
(:func:`inerterlab.systems.equilibrium.linearise`) gives its state space.

The quadrature is adaptive Gauss-Kronrod (``scipy.integrate.quad``, relative tolerance
:data:`QUADRATURE_RTOL`) over +-12 standard deviations, split where the law has a kink
or a narrow transition: at rest (friction, asymmetric and quadratic dampers), at a free
play's ends, at a bump stop's contact and at a flywheel's saturation speed. A fixed
Gauss-Hermite rule would not do: its nodes near rest are a tenth of a standard
deviation apart, wider than a friction's transition (v_eps of a few mm/s), where it
errs by per cent.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..elements._base import NO_GAUSSIAN_EQUIVALENT, NPAR
from ..errors import ParameterError
from . import _kernel
from ._kernel import ELEM_W
from .observers import derive, uncached_info

__all__ = [
    "QUADRATURE_RTOL", "nonlinear_elements", "gaussian_gains", "mean_force", "equivalent_system",
    "argument_rows", "equivalent_gains", "FixedPoint",
]

#: relative tolerance of the Gaussian expectations
QUADRATURE_RTOL = 1e-11


def _expect(f, sigma: float, kinks) -> float:
    """E[f(x)] for x ~ N(0, sigma^2), the interval split at ``kinks`` (and at 0)."""
    from scipy.integrate import quad

    lim = 12.0 * sigma
    pts = sorted({0.0, *(float(k) for k in kinks if abs(k) < lim)})
    c = 1.0 / (sigma * math.sqrt(2.0 * math.pi))

    def g(x):
        return f(x) * c * math.exp(-0.5 * (x / sigma) ** 2)

    edges = [-lim, *pts, lim]
    return float(sum(
        quad(g, a, b, epsabs=0.0, epsrel=QUADRATURE_RTOL, limit=200)[0]
        for a, b in zip(edges[:-1], edges[1:], strict=True)
    ))  # fmt: skip


def _row(sys, e: int) -> np.ndarray:
    itab, ftab = sys.tables
    o = int(itab[int(itab[_kernel.I_ELEM]) + ELEM_W * e + 3])
    return np.array(ftab[o : o + NPAR], dtype=float)


def _law(sys, e: int):
    """The statistical linearisation of element ``e``'s kernel law (None: it has none)."""
    from ..elements import KERNEL_LAWS

    return KERNEL_LAWS.get(sys.elements[e].code)


def nonlinear_elements(sys) -> list[tuple[int, str, str]]:
    """(element index, name, argument) of every element of ``sys`` whose law is not
    linear, the argument its equivalent depends on (``displacement``, ``velocity`` or
    ``acceleration`` for an inertance); ParameterError naming an element that has no
    Gaussian equivalent (module docstring)."""
    out = []
    for e, (name, el) in enumerate(zip(sys.element_names, sys.elements, strict=True)):
        if el.is_linear:
            continue
        law = _law(sys, e)
        row = _row(sys, e)
        if law is not None and law.gaussian_keeps(row):
            continue
        why = (el.description, NO_GAUSSIAN_EQUIVALENT) if law is None else (
            law.gaussian_refusal(row, el.description)
        )  # fmt: skip
        if why is not None:
            raise ParameterError(name, *why)
        out.append((e, name, law.argument))
    return out


def gaussian_gains(sys, e: int, sigma: float) -> float:
    """The Gaussian equivalent of element ``e`` of ``sys`` whose argument (see
    :func:`nonlinear_elements`) is zero-mean Gaussian of standard deviation ``sigma``
    [m, m/s; for an inertance the relative velocity's]: k_eq [N/m], c_eq [N s/m] or
    b_eq [kg] (module docstring), from its kernel law's own
    (:class:`~inerterlab.elements.KernelLaw`). ``sigma`` = 0 gives the slope at rest."""
    law = _law(sys, e)
    row = _row(sys, e)
    if (
        law is None or law.gaussian_keeps(row)
        or law.gaussian_refusal(row, sys.elements[e].description) is not None
    ):  # fmt: skip
        raise ParameterError(
            sys.element_names[e], sys.elements[e].description,
            "an element with a Gaussian equivalent (nonlinear_elements)",
        )  # fmt: skip
    val = law.gaussian_gain(row, sigma, _expect)
    if not math.isfinite(val):
        raise ParameterError(
            sys.element_names[e], f"standard deviation {sigma:.4g}",
            "a motion inside the element's working range (its law is undefined within "
            f"{12 * sigma:.3g} from rest)",
        )  # fmt: skip
    return val


def _velocity_law(sys, e: int):
    """The force law F(v) [N] of the dissipative element ``e`` (a damper or friction
    row) and its kinks, from its compiled force function."""
    law = _law(sys, e)
    if law is None or law.argument != "velocity":
        raise ParameterError(
            sys.element_names[e], sys.elements[e].description,
            "a damper or friction (an element whose force depends on its velocity)",
        )  # fmt: skip
    return law.force_law(_row(sys, e))


def mean_force(sys, e: int, sigma: float) -> float:
    """E[F(v)] [N] (tension positive) of the dissipative element ``e`` of ``sys`` (a
    damper or friction: :func:`nonlinear_elements`' ``velocity`` argument) under a
    zero-mean Gaussian relative velocity of standard deviation ``sigma`` [m/s], by the
    quadrature of its own compiled law: non-zero for a rectifying law (an asymmetric
    damper: (c1 - c2) sigma / sqrt(2 pi)); F(0) for ``sigma`` = 0."""
    law, kinks = _velocity_law(sys, e)
    if sigma <= 0.0:
        return float(law(0.0))
    return _expect(law, sigma, kinks)


def equivalent_system(sys, gains: dict):
    """``sys`` with element ``e`` replaced, for every ``e`` in ``gains``, by a row of its
    own kernel law whose linearisation about rest is the gain (module docstring); the
    elements' objects stay (they name and describe the elements)."""
    def make(sys):
        itab, ftab = sys.tables
        eo = int(itab[_kernel.I_ELEM])
        ft = np.array(ftab, dtype=float, copy=True)
        for e, g in gains.items():
            o = int(itab[eo + ELEM_W * e + 3])
            ft[o : o + NPAR] = _law(sys, e).gaussian_row(_row(sys, e), float(g))
        ft.setflags(write=False)
        return dataclasses.replace(sys, ftab=ft, info=uncached_info(sys.info))

    return derive(sys, make)


def argument_rows(sys, els, ss) -> tuple[np.ndarray, np.ndarray]:
    """(C, D): the rows of each element of ``els`` (:func:`nonlinear_elements`)'s
    argument, its relative displacement or velocity (top minus bottom), in the state
    space ``ss`` = (A, B, C, D) of ``sys``'s core layout
    (:meth:`~inerterlab.systems.System.linear_state_space`): argument = C x + D u."""
    from .equilibrium import _structure

    _, _, Cs, Ds = ss
    ends = _structure(sys)[5]
    names = list(sys.output_names)
    rows_c, rows_d = [], []
    for e, _, arg in els:
        sfx = ".x" if arg == "displacement" else ".v"
        t, b = (names.index(sys.node_names[n] + sfx) for n in ends[e])
        rows_c.append(Cs[t] - Cs[b])
        rows_d.append(Ds[t] - Ds[b])
    return np.array(rows_c), np.array(rows_d)


@dataclasses.dataclass(frozen=True)
class FixedPoint:
    """The Gaussian-equivalent system of :func:`equivalent_gains`: ``gains`` (element
    index -> k_eq, c_eq or b_eq), the equivalent ``system`` and its ``state_space``, the
    arguments' RMS ``sigma`` (element name -> m or m/s) at the last iteration,
    ``iterations`` and whether the gains ``converged``."""

    gains: dict
    system: object
    state_space: tuple
    sigma: dict
    iterations: int
    converged: bool


#: Anderson acceleration of :func:`equivalent_gains`: the iterates it combines, its mixing
#: and the longest step it takes in the logarithm of a gain (a factor e^4) before it
#: falls back to the mixing alone
ANDERSON_MEMORY = 3
ANDERSON_MIXING = 0.5
ANDERSON_LONGEST = 4.0


def equivalent_gains(
    sys, argument_rms, *, tol: float = 1e-10, max_iter: int = 200, start: dict | None = None
) -> FixedPoint:
    """The statistical linearisation of ``sys``: every nonlinear element
    (:func:`nonlinear_elements`) replaced by its Gaussian equivalent
    (:func:`gaussian_gains`) at the RMS of its argument in the equivalent linear system
    itself, iterated to a fixed point. ``argument_rms(eq, ss)`` gives those RMS
    (element name -> m or m/s) of the equivalent system ``eq`` with the state space
    ``ss`` (the caller's road: a white road velocity by a Lyapunov equation, a band of
    a road spectrum by a spectral integral).

    The iteration starts from each law's slope at rest (or from ``start``, element index
    -> gain, where given: the fixed point of a car nearby, as a propagation of
    uncertainty evaluates many) and stops where no gain changes
    by more than ``tol`` relative (at most ``max_iter`` passes), returning the last
    gains computed. Between passes it works on the logarithms of the gains (a friction's
    gain goes like 1 / sigma, and sigma like a power of the gain: a straight line
    there) by Anderson's acceleration: the next iterate is the mixed step (half the way
    to the new gains, :data:`ANDERSON_MIXING`) corrected by the least-squares
    combination of the last :data:`ANDERSON_MEMORY` steps that best cancels the
    residual. Where a gain is not positive, or the step would change a gain by more than
    e^:data:`ANDERSON_LONGEST`, it takes the mixed step alone (in the gains themselves
    where one is not positive) and forgets the history. A linear system is its own
    equivalent."""
    from .equilibrium import linearise

    els = nonlinear_elements(sys)
    if not els:
        return FixedPoint({}, sys, sys.linear_state_space(), {}, 0, True)
    keys = [e for e, _, _ in els]
    if start is not None and set(start) != set(keys):
        raise ParameterError("start", sorted(start), f"a gain for each of the elements {keys}")
    gains = ({e: gaussian_gains(sys, e, 0.0) for e in keys} if start is None  # slope at rest
             else {e: float(start[e]) for e in keys})  # fmt: skip
    hist: list = []  # (log gains, residual in logs) of the last passes
    converged = False
    it = 0
    sigma: dict = {}
    while it < max_iter:
        it += 1
        eq = equivalent_system(sys, gains)
        sigma = argument_rms(eq, linearise(eq))
        new = {e: gaussian_gains(sys, e, sigma[name]) for e, name, _ in els}
        change = max(abs(new[e] - gains[e]) / max(abs(new[e]), 1e-300) for e in keys)
        if change < tol:
            gains = new
            converged = True
            break
        g = np.array([gains[e] for e in keys])
        gn = np.array([new[e] for e in keys])
        if np.all(g > 0.0) and np.all(gn > 0.0):
            x = np.log(g)
            f = np.log(gn) - x
            hist = [*hist[-ANDERSON_MEMORY:], (x, f)]
            step = ANDERSON_MIXING * f
            if len(hist) > 1:
                pairs = list(zip(hist[:-1], hist[1:], strict=True))
                dX = np.array([b[0] - a[0] for a, b in pairs]).T
                dF = np.array([b[1] - a[1] for a, b in pairs]).T
                gam = np.linalg.lstsq(dF, f, rcond=None)[0]
                acc = step - (dX + ANDERSON_MIXING * dF) @ gam
                if np.all(np.isfinite(acc)) and np.max(np.abs(acc)) <= ANDERSON_LONGEST:
                    step = acc
                else:
                    hist = hist[-1:]
            gx = np.exp(x + step)
        else:
            hist = []
            gx = 0.5 * (gn + g)
        gains = {e: float(v) for e, v in zip(keys, gx, strict=True)}
    eq = equivalent_system(sys, gains)
    return FixedPoint(gains, eq, linearise(eq), sigma, it, converged)
