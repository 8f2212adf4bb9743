"""The console outputs printed in README.md and docs/guide/*.md, run and compared.

A block is checked when its fence reads ```` ```console check ```` (words after
``check``: ``slow`` marks it slow, ``rtol=X`` sets its tolerance). Inside, each line
``$ inerterlab ...`` (continued by a trailing backslash, ``# comment`` dropped, ``> FILE``
redirects the output to a file) is one command, and the lines up to the next ``$`` are
its expected output. The commands of a block run in order in one fresh folder, where
``examples`` is the repository's. How output is compared (docs/guide/README.md):

* both sides are cut into tokens: numbers, words and single punctuation marks; white
  space, line breaks and box-drawing characters do not count;
* a number agrees when it is within ``rtol`` (default 1e-3) of the printed one, or
  rounds to the digits the guide shows (within half a unit of its last digit);
* ``...`` in the expected output stands for any run of output (an elision), and the
  expected output is otherwise anchored at both ends;
* lines that report time (``wall 3.1 s``, ``elapsed``, ``took``) and the folder the
  commands run in are left out of the comparison;
* a command whose expected output holds ``inerterlab: error:`` must exit with 2 (its
  standard error is compared), any other with 0.

``pytest tests/test_guides.py --update-guides`` rewrites the expected output of every
command that no longer agrees with what the command prints now.
"""

from __future__ import annotations

import math
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FILES = [ROOT / "README.md", *sorted((ROOT / "docs" / "guide").glob("*.md"))]
RTOL = 1e-3
#: terminal width the commands print tables for (the guides' outputs were made at it)
COLUMNS = "100"

_FENCE = re.compile(r"^```console\s+check\b(.*)$")
_TIMING = re.compile(r"^\s*(wall|elapsed|took)\b.*\d", re.I)
_NUMBER = r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?"
_TOKEN = re.compile(rf"\.\.\.|…|{_NUMBER}|[A-Za-z_][A-Za-z0-9_]*|[^\sA-Za-z0-9_]")
_BOX = re.compile(r"[\u2500-\u257f]")


@dataclass
class Command:
    line: int  # 1-based line of the "$ " in the file
    end: int  # 1-based line after the last line of its expected output
    text: str  # the command as written, continuation lines joined
    expected: list[str] = field(default_factory=list)


@dataclass
class Block:
    path: Path
    index: int  # the block's place among the file's checked blocks
    line: int
    slow: bool
    rtol: float
    commands: list[Command]

    @property
    def id(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def parse_blocks(path: Path) -> list[Block]:
    """The checked console blocks of a Markdown file."""
    lines = path.read_text(encoding="utf-8").split("\n")
    blocks, i = [], 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        opts = m.group(1).split()
        rtol = next((float(o.split("=", 1)[1]) for o in opts if o.startswith("rtol=")), RTOL)
        start, i = i + 1, i + 1
        cmds: list[Command] = []
        while i < len(lines) and not lines[i].startswith("```"):
            s = lines[i]
            if s.startswith("$ "):
                first = i + 1
                text = s[2:]
                while text.rstrip().endswith("\\") and i + 1 < len(lines):
                    i += 1
                    text = text.rstrip()[:-1] + " " + lines[i].strip()
                cmds.append(Command(line=first, end=i + 2, text=text))
            elif cmds:
                cmds[-1].expected.append(s)
                cmds[-1].end = i + 2
            else:
                raise AssertionError(f"{path}:{i + 1}: output before the first '$ ' line")
            i += 1
        if not cmds:
            raise AssertionError(f"{path}:{start}: a checked block without a command")
        blocks.append(Block(path, len(blocks), start, "slow" in opts, rtol, cmds))
        i += 1
    return blocks


def tokens(lines: list[str], folder: str | None = None) -> list[str]:
    out = []
    for s in lines:
        if folder:
            s = s.replace(folder + os.sep, "").replace(folder, ".")
        if _TIMING.match(s):
            continue
        out += _TOKEN.findall(_BOX.sub(" ", s))
    return ["..." if t == "…" else t for t in out]


def _is_number(t: str) -> bool:
    return re.fullmatch(_NUMBER, t) is not None


def number_agrees(expected: str, actual: str, rtol: float) -> bool:
    e, a = float(expected), float(actual)
    if math.isclose(a, e, rel_tol=rtol, abs_tol=1e-300):
        return True
    mant = re.split(r"[eE]", expected.lstrip("+-"))[0]
    places = len(mant.split(".", 1)[1]) if "." in mant else 0
    exp = int(re.split(r"[eE]", expected)[1]) if re.search(r"[eE]", expected) else 0
    return abs(a - e) <= 0.5 * 10.0 ** (exp - places) * (1 + 1e-9)


def _token_agrees(e: str, a: str, rtol: float) -> bool:
    if _is_number(e) and _is_number(a):
        return number_agrees(e, a, rtol)
    return e == a


def _segment_at(seg: list[str], act: list[str], pos: int, rtol: float) -> bool:
    return pos + len(seg) <= len(act) and all(
        _token_agrees(e, a, rtol) for e, a in zip(seg, act[pos : pos + len(seg)], strict=False)
    )


def agrees(expected: list[str], actual: list[str], rtol: float) -> str | None:
    """None if ``actual`` matches ``expected`` (tokens, with ``...`` elisions), else why not."""
    segs, cur = [], []
    for t in expected:
        if t == "...":
            segs.append(cur)
            cur = []
        else:
            cur.append(t)
    segs.append(cur)
    if len(segs) == 1:
        seg = segs[0]
        if len(seg) == len(actual) and _segment_at(seg, actual, 0, rtol):
            return None
        return _first_difference(seg, actual, rtol)
    first, *middle, last = segs
    if not _segment_at(first, actual, 0, rtol):
        return "start: " + (_first_difference(first, actual[: len(first)], rtol) or "too short")
    pos = len(first)
    end = len(actual) - len(last)
    if end < pos or not _segment_at(last, actual, end, rtol):
        return "end: " + (_first_difference(last, actual[max(end, 0) :], rtol) or "too short")
    for seg in middle:
        found = next((p for p in range(pos, end - len(seg) + 1) if _segment_at(seg, actual, p, rtol)), None)
        if found is None:
            return f"not found after token {pos}: {' '.join(seg[:30])}"
        pos = found + len(seg)
    return None


def _first_difference(exp: list[str], act: list[str], rtol: float) -> str:
    for i, (e, a) in enumerate(zip(exp, act, strict=False)):
        if not _token_agrees(e, a, rtol):
            ctx = " ".join(act[max(0, i - 6) : i + 6])
            return f"token {i}: expected {e!r}, got {a!r} (... {ctx} ...)"
    return f"expected {len(exp)} tokens, got {len(act)}"


def run(cmd: Command, folder: Path) -> tuple[int, list[str]]:
    """Run one command in ``folder``: (exit code, the lines it printed)."""
    args = shlex.split(cmd.text, comments=True)
    if not args or args[0] != "inerterlab":
        raise AssertionError(f"line {cmd.line}: a checked command starts with 'inerterlab'")
    target = None
    if ">" in args:
        k = args.index(">")
        args, target = args[:k], args[k + 1]
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "COLUMNS": COLUMNS,
           "NO_COLOR": "1", "TERM": "dumb"}  # fmt: skip
    p = subprocess.run(
        [sys.executable, "-m", "inerterlab", *args[1:]], cwd=folder, env=env,
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    if target is not None:
        (folder / target).write_text(p.stdout, encoding="utf-8")
        out = ""
    else:
        out = p.stdout
    if p.returncode != 0:
        out += p.stderr
    return p.returncode, out.rstrip("\n").split("\n") if out.strip() else []


BLOCKS = [b for f in FILES for b in parse_blocks(f)]


def test_blocks_are_found():
    """The convention is in use: the guides' stale outputs of the past are checked."""
    ids = {b.path.name for b in BLOCKS}
    assert {"README.md", "networks.md", "vehicles.md"} <= ids, ids


@pytest.mark.parametrize(
    "block",
    [pytest.param(b, id=b.id, marks=[pytest.mark.slow] if b.slow else []) for b in BLOCKS],
)
def test_guide_block(block: Block, tmp_path: Path, request):
    update = request.config.getoption("--update-guides")
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    failures, fixes = [], []
    for cmd in block.commands:
        rc, printed = run(cmd, tmp_path)
        want_error = any("inerterlab: error:" in s for s in cmd.expected)
        why = None
        if rc != (2 if want_error else 0):
            why = f"exit code {rc}: {' '.join(printed)[-600:]}"
        else:
            why = agrees(tokens(cmd.expected), tokens(printed, str(tmp_path)), block.rtol)
        if why is not None:
            failures.append(f"{block.path.name}:{cmd.line} $ {cmd.text[:80]}\n    {why}")
            if update and rc in (0, 2):
                fixes.append((block.commands.index(cmd), printed))
    if update and fixes:
        _rewrite(block, fixes, str(tmp_path))
        pytest.skip(f"rewrote {len(fixes)} output(s) in {block.path.name}")
    assert not failures, "\n".join(failures)


def _rewrite(block: Block, fixes, folder: str) -> None:
    """Replace the expected output of each (command index, printed lines) of ``block``;
    the file is read again (another block of it may have been rewritten already)."""
    path = block.path
    now = parse_blocks(path)[block.index]
    lines = path.read_text(encoding="utf-8").split("\n")
    for j, printed in sorted(fixes, key=lambda f: -f[0]):
        cmd = now.commands[j]
        first = cmd.end - 1 - len(cmd.expected)  # 0-based index of the first output line
        new = [s.replace(folder + os.sep, "").replace(folder, ".") for s in printed]
        lines[first : cmd.end - 1] = new
    path.write_text("\n".join(lines), encoding="utf-8")


# ------------------------------------------------------- the comparison itself


def test_comparison_rules():
    """Numbers to the printed digits or rtol, elisions, timing lines, white space."""
    t = tokens
    assert agrees(t(["x = 1.2132"]), t(["x =   1.21320001"]), RTOL) is None
    assert agrees(t(["x = 1.2132"]), t(["x = 1.3439"]), RTOL) is not None
    assert agrees(t(["gain +6.3 %"]), t(["gain +6.34 %"]), 1e-6) is None  # rounds to 6.3
    assert agrees(t(["gain +6.3 %"]), t(["gain +6.36 %"]), 1e-6) is not None
    assert agrees(t(["8.5e-05"]), t(["8.544e-05"]), 1e-6) is None
    assert agrees(t(['{"a": 1, ...}']), t(['{"a": 1.0000001, "b": [2, 3]}']), RTOL) is None
    assert agrees(t(['{"a": 1, ...}']), t(['{"b": 1, "a": 1}']), RTOL) is not None
    assert agrees(t(["a ... c"]), t(["a b b c"]), RTOL) is None
    assert agrees(t(["a ... c"]), t(["a b b c d"]), RTOL) is not None
    assert agrees(t(["│ k | c │ 64.96 │", "wall 31.10 s"]), t(["┃ k | c ┃   64.96 ┃"]), RTOL) is None
    assert agrees(t(["a", "b"]), t(["a b extra"]), RTOL) is not None


def test_blocks_parse(tmp_path):
    md = tmp_path / "g.md"
    md.write_text(
        "text\n```console check slow rtol=0.01\n$ inerterlab h2 \\\n   --json  # note\n"
        "{...}\n$ inerterlab x > f.txt\n```\n```console\n$ inerterlab y\n```\n"
    )
    (b,) = parse_blocks(md)
    assert b.slow and b.rtol == 0.01 and b.line == 2 and b.index == 0
    assert [c.text.split() for c in b.commands] == [
        ["inerterlab", "h2", "--json", "#", "note"], ["inerterlab", "x", ">", "f.txt"]
    ]
    assert b.commands[0].expected == ["{...}"] and b.commands[1].expected == []
    assert shlex.split(b.commands[0].text, comments=True) == ["inerterlab", "h2", "--json"]
