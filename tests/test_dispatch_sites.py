"""Outside ``elements/`` and the compiled evaluation, no module decides by an element's
kernel code, class or network prefix: what a kernel law means to the system builder,
the static balance, the statistical linearisation and the vehicle models is its
:class:`~inerterlab.elements.KernelLaw` (``KERNEL_LAWS``), and what an element is, its
own declarations. So a new element or kernel law reaches every analysis through its
own module and the registries, and this scan fails where a module names one again."""

from __future__ import annotations

import re
from pathlib import Path

import inerterlab

ROOT = Path(inerterlab.__file__).resolve().parent

#: the one module that branches on the kernel code: the compiled evaluation of the rows
#: (a numba kernel reads the code from its integer table; it has no dispatch by class)
KERNEL = "systems/_kernel.py"

#: a kernel code imported, a code or a prefix compared, a class of the registry tested
PATTERNS = (
    re.compile(r"\b(SPRING|DAMPER|INERTER|FRICTION|FLYWHEEL|TYRE)\b"),
    re.compile(r"\.code\s*(==|!=|\bin\b|\bnot in\b)"),
    re.compile(r"\.prefix\s*(==|!=|\bin\b)"),
    re.compile(
        r"isinstance\([^)]*\b(Spring|Damper|Inerter|Friction|Backlash|GasSpring|BumpStop|"
        r"BearingDrag|AsymmetricDamper|OneWayClutch|ScrewContact|HydraulicElement|"
        r"ScrewElement|RectifierElement|FluidInerter|AdaptiveFlywheelInerter|Tyre)\b"
    ),
)

#: type checks of what a user passed (a vehicle's tyre, its adaptive inerter), not a
#: decision by element kind: (module, the line's text)
VALIDATION = {
    ("vehicles/parameters.py", "if not isinstance(self.adaptive, AdaptiveFlywheelInerter):"),
    ("vehicles/parameters.py", "if not isinstance(self.tyre, Tyre):"),
}


def _hits() -> list[str]:
    out = []
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        if rel.startswith("elements/") or rel == KERNEL:
            continue
        for i, line in enumerate(path.read_text().splitlines(), 1):
            text = line.strip()
            if text.startswith("#") or (rel, text) in VALIDATION:
                continue
            if any(p.search(line) for p in PATTERNS):
                out.append(f"{rel}:{i}: {text}")
    return out


def test_no_module_outside_elements_decides_by_element_kind():
    assert _hits() == []


def test_the_scan_finds_a_decision_by_code():
    """The patterns catch the forms the code used before (so the scan can fail)."""
    for line in (
        "from ..elements._base import DAMPER, NPAR",
        "if el.code in (INERTER, FLYWHEEL):",
        "gap = edges[e][1].prefix == 'gap'",
        "if isinstance(el, Damper):",
    ):
        assert any(p.search(line) for p in PATTERNS), line
