"""Figures of core simulations (matplotlib imported only when called; no backend is
chosen: see :mod:`inerterlab.plotting`)."""

from __future__ import annotations

from ..errors import ParameterError

#: the outputs shown by default, by kind of system
DEFAULT_OUTPUTS = {
    "quarter_car": ("body_acc", "deflection", "tyre_force"),
    "rig": ("force", "drive.x"),
    "base_excited": ("body.x", "body.a"),
}
_LABELS = {
    "body_acc": ("body acceleration", "m/s$^2$", 1.0),
    "deflection": ("deflection (body - wheel)", "mm", 1e3),
    "tyre_force": ("tyre force, dynamic", "N", 1.0),
    "tyre_grip": ("tyre grip index", "-", 1.0),
    "force": ("force at the drive", "N", 1.0),
}
_SUFFIX = {".x": ("displacement", "mm", 1e3), ".v": ("velocity", "m/s", 1.0),
           ".a": ("acceleration", "m/s$^2$", 1.0), ".force": ("force", "N", 1.0)}  # fmt: skip


def _label(name: str) -> tuple[str, str, float]:
    if name in _LABELS:
        return _LABELS[name]
    for suf, (what, unit, scale) in _SUFFIX.items():
        if name.endswith(suf):
            return f"{name[: -len(suf)]} {what}", unit, scale
    return name, "", 1.0


def plot_result(result, outputs=None, *, title: str | None = None):
    """Sampled outputs of a :class:`~inerterlab.systems.CoreResult` against time [s],
    one panel per output name (see :meth:`CoreResult.plot`)."""
    from ..plotting import subplots

    names = tuple(outputs) if outputs is not None else DEFAULT_OUTPUTS.get(result.system.kind, ())
    if not names:
        names = tuple(n for n in result.outputs if n.endswith(".x"))[:3]
    for n in names:
        if n not in result.outputs:
            known = ", ".join(result.outputs)
            raise ParameterError("outputs", n, f"names of the result's outputs ({known})")
    fig, axes = subplots(len(names), 1, figsize=(9, 2.5 * len(names) + 0.5), sharex=True,
                         squeeze=False)  # fmt: skip
    for ax, n in zip(axes[:, 0], names, strict=True):
        what, unit, scale = _label(n)
        ax.plot(result.time, scale * result.outputs[n], lw=0.8)
        ax.set_ylabel(f"{what} [{unit}]" if unit else what)
    axes[-1, 0].set_xlabel("time [s]")
    axes[0, 0].set_title(title or f"{result.system.description}, {result.method} steps")
    fig.tight_layout()
    return fig
