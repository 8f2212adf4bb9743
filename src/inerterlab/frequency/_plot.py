"""Figure of a frequency response (matplotlib imported lazily, only here)."""

from __future__ import annotations

import numpy as np


def plot_frequency_response(fr, ax=None, *, label: str | None = None, scale: float = 100.0):
    """Amplitude [cm by default] against frequency [Hz]; both scan directions.

    Unstable points (Hill's method) are marked with red crosses; failed points are
    left out. Returns the matplotlib figure.
    """
    from ..plotting import _plt

    plt = _plt()
    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 4.2))
    else:
        fig = ax.figure
    unit = {100.0: "cm", 1.0: "m", 1000.0: "mm"}.get(scale, f"x{scale:g} m")
    styles = {"down": ("-", "scan down"), "up": ("--", "scan up")}
    for d in dict.fromkeys(fr.direction.tolist()):
        b = fr.branch(d) if d in ("down", "up") else fr
        ok = b.converged
        ls, text = styles.get(d, ("-", d))
        name = (
            f"{label or fr.method}, {text}"
            if len(set(fr.direction.tolist())) > 1
            else (label or fr.method)
        )
        ax.plot(b.freq_hz[ok], scale * b.amplitude_m.data[ok], ls, lw=1.2, label=name)
        st = np.ma.filled(b.stable, True)
        bad = ok & ~st
        if bad.any():
            ax.plot(b.freq_hz[bad], scale * b.amplitude_m.data[bad], "rx", ms=4,
                    label=f"unstable ({text})")  # fmt: skip
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"amplitude of X1 (half peak-to-peak) [{unit}]")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=8)
    return fig
