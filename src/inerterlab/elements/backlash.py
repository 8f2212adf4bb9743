"""Backlash: a contact spring with free play (docs/model.md, "Backlash").

The two terminals move freely against each other over the free play p (total, split
evenly: a dead zone |x| <= p/2 about the rest position) and meet a contact spring of
stiffness k beyond it:

    F = k (x - p/2)   for x >  p/2,
    F = 0             for |x| <= p/2,
    F = k (x + p/2)   for x < -p/2.

The law is the spring's (:func:`inerterlab.elements.spring.spring_force`, with the half
play as the second number of the kernel row); a spring is backlash with no play. The
force is continuous with a kink at each contact, which the adaptive integrator locates
(the switching function |x| - p/2 of :func:`~inerterlab.elements.spring.spring_switch`:
no step integrates across a contact); there is no impact loss (add a damper in parallel for one). A
massless node held only by springs and backlash has no unique rest position inside the
play, so the system builder refuses such a node (it needs a mass, an inertance or a
damper at it). In series with an inerter (``gap - b``) the inerter is disengaged while
the play is open. (The thesis's screw device has its own backlash rule, (3.36)-(3.37),
on its flywheel: :mod:`.screw_backlash`.)
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ._base import SPRING, ElementBase, Param

__all__ = ["Backlash"]


@dataclass(frozen=True, kw_only=True)
class Backlash(ElementBase):
    """Contact spring of ``stiffness`` k [N/m] > 0 with ``free_play`` p [m] >= 0 (total
    play, a dead zone of +-p/2 about rest); p = 0 is a linear spring."""

    stiffness: float
    free_play: float

    prefix = "gap"
    description = "spring with free play (backlash)"
    ROLE = "elastic"
    EXAMPLE = {"stiffness": 2e5, "free_play": 0.004}
    PARAMETERS = (Param("stiffness", "N/m"), Param("free_play", "m", low_open=False))
    code = SPRING

    def row(self):
        return self._row(self.stiffness, 0.5 * self.free_play)

    def scaled(self, factor):  # copies moving together share the play
        return dataclasses.replace(self, stiffness=self.stiffness * factor)

    @property
    def is_linear(self):
        return self.free_play == 0.0

    def rest_network(self):
        """At rest the terminals sit in the middle of the play: no force for small
        motions (an open circuit); with no play, the contact spring."""
        return ("k", {"k": self.stiffness}) if self.free_play == 0.0 else None
