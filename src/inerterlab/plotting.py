"""Figures, made with matplotlib's object-oriented API.

Nothing here selects a matplotlib backend or imports pyplot: a script, a notebook or a
headless server keeps whatever backend it has, and ``fig.savefig`` works everywhere.
"""

from __future__ import annotations

import numpy as np


def subplots(*args, figsize=None, dpi=None, layout=None, **kwargs):
    """``(figure, axes)`` like ``pyplot.subplots``, through matplotlib's object-oriented
    API: no backend is chosen, switched or even imported, so this works headless and
    leaves an interactive session's backend alone. The figure is not registered with
    pyplot (nothing to close); ``fig.savefig`` writes it, and Jupyter displays it.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, dpi=dpi, layout=layout)
    return fig, fig.subplots(*args, **kwargs)


class _FigureFactory:
    """The two pyplot calls the plotting code uses, without pyplot."""

    subplots = staticmethod(subplots)

    @staticmethod
    def close(fig=None) -> None:
        """Nothing to do: figures from :func:`subplots` are not held by pyplot."""


def _plt():
    return _FigureFactory


def plot_flywheel(fw, *, speed_max: float | None = None):
    """Inertia and slider position against speed (thesis Fig. 3.3 and 3.8)."""
    wmax = speed_max or 1.5 * fw.saturation_speed
    w = np.linspace(0.0, wmax, 600)
    fig, (a1, a2) = subplots(1, 2, figsize=(10, 4))
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
