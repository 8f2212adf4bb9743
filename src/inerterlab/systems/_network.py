"""Network text + parameters by name -> nodes and primitive two-terminal elements."""

from __future__ import annotations

from ..elements import ElementBase, kernel_law
from ..networks import Element, elements_of, parse_network

__all__ = ["Layout", "elements_of", "parse"]


def parse(text: str):
    """The series/parallel tree of ``text`` (the one grammar, :mod:`inerterlab.networks`)."""
    return parse_network(text).tree


def _rank(tree, elements: dict) -> int:
    """How firmly a sub-network ties the motion of its two ends: 0 an inertance on every
    path between them (an inerter, or a parallel branch of them), 1 an inertance
    somewhere inside, 2 a damper or inertance on every path, 3 a damper inside, 4
    springs and friction only."""
    if isinstance(tree, Element):
        el = elements[tree.name]
        exp = el.expansion()
        if exp is not None:
            stext, parts = exp
            return _rank(parse(stext), parts)
        law = kernel_law(el)
        if law.inertial:
            return 0
        return 2 if law.holds_velocity else 4
    ranks = [_rank(p, elements) for p in tree.parts]
    if tree.op == "|":
        return min(ranks)
    worst = max(ranks)
    if worst == 0:
        return 0
    if 0 in ranks or 1 in ranks:
        return 1
    return 2 if worst == 2 else (3 if 2 in ranks or 3 in ranks else 4)


class Layout:
    """Nodes and primitive edges of one or more networks placed between nodes.

    ``arrange``: lay each series chain out in the order of :func:`_rank` (the members
    that tie their ends by inertance, then by damping, next to the chain's ends that
    are fixed or carry mass; springs in the middle) instead of the order written. A
    series chain's order does not change what its two ends see (the same force passes
    through every member and the extensions add), so this changes only which massless
    internal nodes exist: it turns an inerter or damper between two massless nodes,
    which the node classification cannot integrate, into the same network with the
    springs next to each other (docs/model.md, "Networks")."""

    def __init__(self, arrange: bool = False) -> None:
        self.nodes: list[dict] = []
        self.edges: list[tuple[str, ElementBase, int, int]] = []
        self.arrange = arrange

    def node(self, name: str, kind: str = "internal", mass: float = 0.0, origin: str = "") -> int:
        self.nodes.append(dict(name=name, kind=kind, mass=float(mass), origin=origin))
        return len(self.nodes) - 1

    def place(
        self,
        tree,
        top: int,
        bot: int,
        elements: dict,
        path: str = "",
        text: str = "",
        fixed: tuple[bool, bool] = (True, True),
    ):
        """Place ``tree`` between nodes ``top`` and ``bot``; ``fixed`` says whether each
        end may anchor inertances when arranging: a mass or the ground, or a node tied
        to one by inertances. A prescribed terminal (a rig's drive, a moving base) is
        not one: its velocity may jump, and an inerter next to it would then be
        started spinning where the chain as written has a spring take the jump."""
        if isinstance(tree, Element):
            el = elements[tree.name]
            full = path + tree.name
            exp = el.expansion()
            if exp is None:
                self.edges.append((full, el, top, bot))
            else:
                stext, parts = exp
                self.place(parse(stext), top, bot, parts, full + ".", f"{full}: {stext}", fixed)
            return
        if tree.op == "|":
            for part in tree.parts:
                self.place(part, top, bot, elements, path, text, fixed)
            return
        cur = top
        where = (text + " in " if text else "") + f"'{tree.text()}'"
        if text and tree.text() == text.split(": ", 1)[-1]:
            where = text
        parts = list(tree.parts)
        ranks = None
        if self.arrange:
            ranks = {id(p): _rank(p, elements) for p in parts}
            ranked = sorted(parts, key=lambda p: ranks[id(p)])
            if fixed[0] and fixed[1]:
                parts = ranked[0::2] + ranked[1::2][::-1]
            elif fixed[1]:
                parts = ranked[::-1]
            else:
                parts = ranked
        tied = [ranks[id(p)] == 0 for p in parts] if ranks is not None else None
        for i, part in enumerate(parts):
            if i == len(parts) - 1:
                nxt = bot
            else:
                left = part.text() if isinstance(part, Element) else f"({part.text()})"
                nxt = self.node(
                    f"{path}n{len(self.nodes)}",
                    origin=f"the node after {left!s} in the series {where}",
                )
            ends = fixed
            if tied is not None:
                ends = (
                    fixed[0] and all(tied[:i]) or fixed[1] and all(tied[i:]),
                    fixed[0] and all(tied[: i + 1]) or fixed[1] and all(tied[i + 1 :]),
                )
            self.place(part, cur, nxt, elements, path, text, ends)
            cur = nxt
