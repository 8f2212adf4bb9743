"""Network text + parameters by name -> nodes and primitive two-terminal elements."""

from __future__ import annotations

from collections import Counter
from typing import Any

from .. import networks as _nw
from ..elements import ElementBase, element_class
from ..errors import ParameterError
from ..networks import NetworkError


class _Parser(_nw._Parser):
    """The network grammar of :mod:`inerterlab.networks` with the element registry's names."""

    def factor(self) -> Any:
        if self.peek() == "name":
            name = self.toks[self.i][1]
            self.i += 1
            return _nw.Element(name, element_class(name).description)
        return super().factor()


def parse(text: str):
    """The series/parallel tree of ``text`` (names from the element registry)."""
    if not isinstance(text, str) or not text.strip():
        raise NetworkError(f"network {text!r}: empty; write e.g. 'k | c'")
    p = _Parser(text)
    tree = p.network()
    if p.i != len(p.toks):
        raise p.fail("'|', '-' or the end")
    counts = Counter(e.name for e in tree.elements())
    dup = [n for n, c in counts.items() if c > 1]
    if dup:
        raise NetworkError(
            f"network {text!r}: element {dup[0]!r} appears {counts[dup[0]]} times; "
            "give every element its own name (k, k2, ...)"
        )
    return tree


def elements_of(text: str, params: dict | None) -> tuple[Any, dict[str, ElementBase]]:
    """Parse ``text`` and build each element from ``params``.

    ``params`` maps an element name to a number (its first parameter), a dict of
    parameters or an element object; ``"name.parameter"`` keys set one parameter.
    Unknown names are an error naming them; missing values name the element.
    """
    tree = parse(text)
    names = [e.name for e in tree.elements()]
    params = dict(params or {})
    grouped: dict[str, Any] = {}
    for key, value in params.items():
        base, _, sub = str(key).partition(".")
        if base not in names:
            raise ParameterError(
                str(key), value, f"a parameter of an element of {text!r} ({', '.join(names)})"
            )
        if sub:
            cur = grouped.get(base)
            if cur is None:
                cur = {}
            elif not isinstance(cur, dict):
                first = element_class(base).PARAMETERS[0].name
                cur = {first: cur}
            cur = dict(cur)
            cur[sub] = value
            grouped[base] = cur
        else:
            cur = grouped.get(base)
            if isinstance(cur, dict) and not isinstance(value, dict | ElementBase):
                first = element_class(base).PARAMETERS[0].name
                grouped[base] = {first: value, **cur}
            else:
                grouped[base] = value
    elements = {n: element_class(n).from_value(n, grouped.get(n)) for n in names}
    return tree, elements


class Layout:
    """Nodes and primitive edges of one or more networks placed between nodes."""

    def __init__(self) -> None:
        self.nodes: list[dict] = []
        self.edges: list[tuple[str, ElementBase, int, int]] = []

    def node(self, name: str, kind: str = "internal", mass: float = 0.0, origin: str = "") -> int:
        self.nodes.append(dict(name=name, kind=kind, mass=float(mass), origin=origin))
        return len(self.nodes) - 1

    def place(self, tree, top: int, bot: int, elements: dict, path: str = "", text: str = ""):
        if isinstance(tree, _nw.Element):
            el = elements[tree.name]
            full = path + tree.name
            exp = el.expansion()
            if exp is None:
                self.edges.append((full, el, top, bot))
            else:
                stext, parts = exp
                self.place(parse(stext), top, bot, parts, full + ".", f"{full}: {stext}")
            return
        if tree.op == "|":
            for part in tree.parts:
                self.place(part, top, bot, elements, path, text)
            return
        cur = top
        where = (text + " in " if text else "") + f"'{tree.text()}'"
        if text and tree.text() == text.split(": ", 1)[-1]:
            where = text
        for i, part in enumerate(tree.parts):
            if i == len(tree.parts) - 1:
                nxt = bot
            else:
                left = part.text() if isinstance(part, _nw.Element) else f"({part.text()})"
                nxt = self.node(
                    f"{path}n{len(self.nodes)}",
                    origin=f"the node after {left!s} in the series {where}",
                )
            self.place(part, cur, nxt, elements, path, text)
            cur = nxt
