"""Deriving the missing motion signal of a rig record.

* velocity from displacement: Savitzky-Golay first derivative (local cubic fit over a
  window of ``window`` seconds, default 20 ms, at least 5 samples), which differentiates
  without amplifying sensor noise the way a finite difference does; the displacement is
  replaced by the same local fit, so x and v stay consistent and a model that needs the
  acceleration (the screw's inertance) does not see the raw noise differentiated twice;
* displacement from velocity: cumulative trapezoid integral, then the constant offset
  removed (``detrend="constant"``, right for records of whole periods of a signal
  symmetric about zero, as in thesis Appendix A) or a least-squares line
  (``detrend="linear"``, for records with sensor drift; note that it also removes the
  linear part of a sine over a finite record).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import cumulative_trapezoid
from scipy.signal import savgol_filter

from ..errors import check_choice, check_positive

__all__ = ["velocity_from_displacement", "displacement_from_velocity", "complete_motion"]


def velocity_from_displacement(t, x, *, window: float = 0.02, polyorder: int = 3, deriv: int = 1):
    """v [m/s] from x [m] sampled at (near-)uniform times t [s] by a Savitzky-Golay derivative."""
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    check_positive("window", window, "s")
    dt = float(np.median(np.diff(t)))
    n = max(polyorder + 2, int(round(window / dt)))
    n += 1 - n % 2
    n = min(n, x.size - (1 - x.size % 2))
    return savgol_filter(x, n, polyorder, deriv=deriv, delta=dt, mode="interp")


def displacement_from_velocity(t, v, *, detrend: str = "constant"):
    """x [m] from v [m/s] by the cumulative trapezoid rule with the offset removed."""
    check_choice("detrend", detrend, ("constant", "linear", "none"))
    t = np.asarray(t, dtype=float)
    x = cumulative_trapezoid(np.asarray(v, dtype=float), t, initial=0.0)
    if detrend == "constant":
        x = x - x.mean()
    elif detrend == "linear":
        x = x - np.polyval(np.polyfit(t, x, 1), t)
    return x


def complete_motion(test, *, window: float = 0.02, detrend: str = "constant"):
    """(x, v) of a :class:`~inerterlab.identify.data.RigTest`, deriving the missing one."""
    x, v = test.displacement, test.velocity
    if v is None:
        v = velocity_from_displacement(test.t, x, window=window)
        x = velocity_from_displacement(test.t, x, window=window, deriv=0)
    if x is None:
        x = displacement_from_velocity(test.t, v, detrend=detrend)
    return x, v
