"""Pseudo-arclength continuation of harmonic-balance solutions through folds.

Unknowns y = (X, Omega), scaled so that both parts are of order one. From a converged
point the tangent t (null vector of [dR/dX, dR/dOmega], oriented like the previous
one) gives the predictor y + ds t; the corrector solves R = 0 together with
t . (y - y_pred) = 0 by Newton. The step ds grows when the corrector needs few
iterations and is halved when it fails, down to ``min_step``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ContinuationPath", "continue_branch"]


@dataclass(frozen=True)
class ContinuationPath:
    """Points along the solution branch."""

    omega: np.ndarray
    coefficients: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray
    completed: bool
    message: str

    def __repr__(self) -> str:
        if len(self.omega) == 0:
            return f"<ContinuationPath empty: {self.message}>"
        return (
            f"<ContinuationPath {len(self.omega)} points, Omega {self.omega.min():.4g} .. "
            f"{self.omega.max():.4g} rad/s, {'completed' if self.completed else 'stopped'}: "
            f"{self.message}>"
        )

    def _repr_html_(self) -> str:
        from .._display import html_table

        rows = [("points", str(len(self.omega))), ("completed", str(self.completed)),
                ("message", self.message)]  # fmt: skip
        if len(self.omega):
            rows.insert(1, ("Omega [rad/s]", f"{self.omega.min():.4g} .. {self.omega.max():.4g}"))
        return html_table("continuation path", rows)

    def to_xarray(self):
        """The path as an xarray Dataset over ``point`` (Omega in rad/s, coefficients in
        the units of the response)."""
        import xarray as xr

        ds = xr.Dataset(
            {
                "coefficients": (("point", "coefficient"), self.coefficients),
                "residual": ("point", self.residual, {"units": "1"}),
                "iterations": ("point", self.iterations),
            },
            coords={"omega": ("point", self.omega, {"units": "rad/s"})},
        )
        ds.attrs.update(completed=str(self.completed), message=self.message)
        return ds


def _domega(engine, X, omega):
    h = 1e-7 * omega
    return (engine.residual(X, omega + h) - engine.residual(X, omega - h)) / (2.0 * h)


def _tangent(J, dRdw, xs, ws, prev=None):
    """Unit tangent in scaled variables (X / xs, Omega / ws)."""
    A = np.hstack([J * xs, (dRdw * ws)[:, None]])
    _, _, vt = np.linalg.svd(A)
    t = vt[-1]
    if prev is not None and float(t @ prev) < 0:
        t = -t
    elif prev is None and t[-1] < 0:
        t = -t
    return t


def continue_branch(
    engine,
    X0,
    omega_start: float,
    omega_end: float,
    *,
    step: float = 0.02,
    min_step: float = 1e-5,
    max_step: float = 0.2,
    max_points: int = 5000,
    rtol: float = 1e-10,
    max_iter: int = 15,
    scale: float = 1.0,
) -> ContinuationPath:
    """Follow the branch from (X0, omega_start) until Omega passes ``omega_end``.

    ``X0`` need not be converged: it is first corrected at fixed Omega. ``step`` is
    the arclength in the scaled variables (X / scale, Omega / omega_start).
    """
    X, ok, it, rn, code = engine.newton(X0, omega_start, rtol, 50, scale)
    if not ok:
        return ContinuationPath(
            np.array([]), np.zeros((0, len(X0))), np.array([]), np.array([]), False,
            "the starting point did not converge",
        )  # fmt: skip
    xs, ws = scale, abs(omega_start)
    sign = 1.0 if omega_end > omega_start else -1.0
    y = np.concatenate([X / xs, [omega_start / ws]])
    R, J = engine.residual_jacobian(X, omega_start)
    t = _tangent(J, _domega(engine, X, omega_start), xs, ws)
    if np.sign(t[-1]) != sign:
        t = -t
    omegas, coeffs, res, its = [omega_start], [X.copy()], [rn], [it]
    ds = step
    message, completed = "", False
    while len(omegas) < max_points:
        y_pred = y + ds * t
        yc = y_pred.copy()
        conv = False
        for k_iter in range(max_iter):  # noqa: B007 - used after the loop
            Xc, wc = yc[:-1] * xs, yc[-1] * ws
            R, J = engine.residual_jacobian(Xc, wc)
            dRdw = _domega(engine, Xc, wc)
            A = np.zeros((len(yc), len(yc)))
            A[:-1, :-1] = J * xs
            A[:-1, -1] = dRdw * ws
            A[-1] = t
            b = np.concatenate([-R, [-(t @ (yc - y_pred))]])
            try:
                dy = np.linalg.solve(A, b)
            except np.linalg.LinAlgError:
                break
            yc = yc + dy
            if not np.all(np.isfinite(yc)):
                break
            if np.linalg.norm(dy) <= rtol * (np.linalg.norm(yc) + 1.0):
                conv = True
                break
        if not conv:
            ds *= 0.5
            if ds < min_step:
                message = f"step fell below {min_step:g} near Omega = {y[-1] * ws:.6g} rad/s"
                break
            continue
        Xc, wc = yc[:-1] * xs, yc[-1] * ws
        R, J = engine.residual_jacobian(Xc, wc)
        t = _tangent(J, _domega(engine, Xc, wc), xs, ws, prev=t)
        y = yc
        omegas.append(wc)
        coeffs.append(Xc.copy())
        res.append(float(np.linalg.norm(R)))
        its.append(k_iter + 1)
        ds = float(
            np.clip(ds * (1.6 if k_iter < 3 else (1.0 if k_iter < 6 else 0.6)), min_step, max_step)
        )
        if sign * (wc - omega_end) >= 0:
            completed = True
            break
    else:
        message = f"stopped after {max_points} points"
    return ContinuationPath(
        np.array(omegas), np.array(coeffs), np.array(res), np.array(its), completed, message
    )
