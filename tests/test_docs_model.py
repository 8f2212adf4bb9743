"""The project describes its own model in docs/model.md and every reference resolves."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCANNED = ["src", "docs", "tests", "examples", "benchmarks", "README.md"]


def _files():
    for name in SCANNED:
        p = ROOT / name
        paths = [p] if p.is_file() else sorted(p.rglob("*"))
        for f in paths:
            if f.is_file() and f.suffix in {".py", ".md", ".toml", ".html", ".css"}:
                yield f


def _sections() -> dict[str, str]:
    text = (ROOT / "docs" / "model.md").read_text()
    return {m.group(1): m.group(2) for m in re.finditer(r"^## (\d+)\. (.+)$", text, re.M)}


def test_model_has_the_sections_and_references():
    text = (ROOT / "docs" / "model.md").read_text()
    assert list(_sections()) == [str(i) for i in range(1, 14)]
    assert "## References" in text
    # every bracketed citation used in the text is listed under References
    refs = text.split("## References", 1)[1]
    for key in set(re.findall(r"\[([A-Z][A-Za-z0-9]*\d*)\]", text.split("## References")[0])):
        assert f"[{key}]" in refs, key


def test_no_reference_to_an_external_brief():
    offenders = [
        f"{f.relative_to(ROOT)}:{i}"
        for f in _files()
        if f.name != "test_docs_model.py"
        for i, line in enumerate(f.read_text(errors="replace").splitlines(), 1)
        if re.search(r"\bSPEC\b", line)
    ]
    assert offenders == []


def test_every_model_reference_points_to_a_section():
    sections = _sections()
    slugs = {
        re.sub(r"[^\w\- ]", "", f"{n}. {title}".lower()).replace(" ", "-")
        for n, title in sections.items()
    }
    seen = 0
    for f in _files():
        text = f.read_text(errors="replace")
        for n in re.findall(r"model(?:\.md)? §(\d+)", text):
            assert n in sections, f"{f}: §{n}"
            seen += 1
        for slug in re.findall(r"model\.md#([\w\-]+)", text):
            assert slug in slugs, f"{f}: #{slug}"
    assert seen > 30
