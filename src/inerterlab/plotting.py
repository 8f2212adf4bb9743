"""Figures. The only module (with the report) that imports matplotlib."""

from __future__ import annotations

import numpy as np


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_flywheel(fw, *, speed_max: float | None = None):
    """Inertia and slider position against speed (thesis Fig. 3.3 and 3.8)."""
    plt = _plt()
    wmax = speed_max or 1.5 * fw.saturation_speed
    w = np.linspace(0.0, wmax, 600)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.plot(w, 1e3 * np.asarray(fw.slider_position(w)))
    a1.axvline(fw.saturation_speed, ls="--", c="grey", lw=0.8)
    a1.set_xlabel("flywheel speed [rad/s]")
    a1.set_ylabel("slider radius l [mm]")
    a1.set_title("slider position (3.9), clamped")
    a2.plot(w, 1e4 * np.asarray(fw.inertia(w)))
    a2.axvline(fw.saturation_speed, ls="--", c="grey", lw=0.8)
    a2.set_xlabel("flywheel speed [rad/s]")
    a2.set_ylabel("inertia I [1e-4 kg m^2]")
    a2.set_title(f"{fw.name}: changing ratio {100 * fw.changing_ratio:.2f} %")
    fig.tight_layout()
    return fig
