"""The observers the block-sum tests put on a quarter car: one of each kind the exact
steps sum (square, fourth power, product, peaks of both signs), over its body and wheel."""

from __future__ import annotations

from inerterlab.systems.observers import Observer

#: their names, in the order of :func:`probes`
OBS = ("i_acc", "x4", "av", "p_acc", "n_acc", "p_defl")


def probes() -> list[Observer]:
    return [
        Observer("i_acc", "square", {"body.a": 1.0}, scale=1.0),
        Observer("x4", "fourth", {"body.x": 1.0, "wheel.x": -1.0}, scale=1e-8),
        Observer("av", "product", {"body.a": 1.0}, other={"body.v": 1.0}, scale=1e-2),
        Observer("p_acc", "peak", {"body.a": 1.0}),
        Observer("n_acc", "peak", {"body.a": -1.0}),
        Observer("p_defl", "peak", {"body.x": 1.0, "wheel.x": -1.0}),
    ]
