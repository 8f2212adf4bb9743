"""Figure of a quarter-car simulation (matplotlib imported only when called; no backend
is chosen: see :mod:`inerterlab.plotting`)."""

from __future__ import annotations


def plot_simulation(result, *, title: str | None = None):
    """Body acceleration, suspension deflection and tyre force against time.

    Parameters
    ----------
    result : SimulationResult
        With sampled output (``output="series"``).
    title : str, optional
        Figure title; by default the suspension and input.
    """
    from ..plotting import subplots

    t = result.time
    if t is None:
        result._need_series()
    fig, axes = subplots(3, 1, figsize=(9, 7.5), sharex=True)
    axes[0].plot(t, result.body_acc, lw=0.8, label="a3")
    axes[0].plot(t, result.body_acc_wk, lw=0.8, label="Wk-weighted")
    axes[0].set_ylabel("body acceleration [m/s$^2$]")
    axes[0].legend(loc="upper right")
    axes[1].plot(t, 1e3 * result.deflection, lw=0.8)
    axes[1].set_ylabel("deflection X3 - X2 [mm]")
    axes[2].plot(t, result.tyre_force, lw=0.8)
    axes[2].axhline(0.0, c="grey", lw=0.6, ls="--")
    axes[2].set_ylabel("tyre force [N]")
    axes[2].set_xlabel("time [s]")
    m = result.metrics()
    axes[0].set_title(
        title
        or f"{result.model.suspension}, input {result.excitation.name}: "
        + (
            "rms a3 not finite (road step)"
            if m["rms_body_acc"] is None
            else f"rms a3 {m['rms_body_acc']:.3g} m/s$^2$"
        )
        + f", rms z {1e3 * m['rms_deflection']:.3g} mm"
    )
    fig.tight_layout()
    return fig
