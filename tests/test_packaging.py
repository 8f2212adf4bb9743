"""The package carries every resource it reads: a non-editable install runs the report.

The slow test builds a wheel of this checkout (from a copy of the tracked files, so the
worktree stays clean), installs it without dependencies into a fresh virtual environment
that sees the current environment's site-packages, and runs
``inerterlab reproduce --quick --tables 3.A`` there from an unrelated directory (a table
of the flywheel's check values: it reads the package's data and the errata). It runs no
simulation: in a fresh copy that compiles every kernel again, about four minutes of
CPU, and the compiled kernels' caching is the subject of ``test_numba_cache.py``.
"""

import os
import shutil
import site
import subprocess
import sys
import tomllib
from importlib import resources
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_declared_package_data_exists():
    conf = tomllib.loads((ROOT / "pyproject.toml").read_text())
    patterns = conf["tool"]["setuptools"]["package-data"]["inerterlab"]
    pkg = ROOT / "src" / "inerterlab"
    for pat in patterns:
        assert list(pkg.glob(pat)), f"package data {pat!r} matches no file"
    # every file the code reads through importlib.resources is declared
    for name in ("errata.md", "appendix_a.csv", "thesis_ch4_6.csv", "thesis_ch7.csv",
                 "reproduce_costs.json"):
        assert any((pkg / "data" / name).match(f"*/{p}") for p in patterns), name


def test_errata_read_from_the_package():
    from inerterlab.report.build import read_errata

    text = read_errata()
    assert text == resources.files("inerterlab.data").joinpath("errata.md").read_text()
    assert "Metal flywheel constant" in text


def _git_files():
    out = subprocess.run(
        ["git", "ls-files", "-co", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    return [f for f in out if (ROOT / f).is_file()]


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_non_editable_install_finds_its_resources(tmp_path):
    src = tmp_path / "src"
    for f in _git_files():
        (src / f).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / f, src / f)
    # nothing of this checkout on the path: only the installed copy may be found
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["MPLBACKEND"] = "Agg"
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    py = venv / "bin" / "python"
    purelib = subprocess.run(
        [str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    # the dependencies come from the running environment (a path entry, not its .pth
    # files, so an editable inerterlab there cannot shadow the installed one)
    (Path(purelib) / "_deps.pth").write_text("\n".join(site.getsitepackages()) + "\n")
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "--python",
            str(py),
            "install",
            "-q",
            "--no-deps",
            "--no-build-isolation",
            "--no-index",
            str(src),
        ],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    where = subprocess.run(
        [str(py), "-c", "import inerterlab; print(inerterlab.__file__)"],
        capture_output=True,
        text=True,
        check=True,
        cwd=tmp_path,
        env=env,
    ).stdout.strip()
    assert where.startswith(str(venv)), where
    run = tmp_path / "run"
    run.mkdir()
    r = subprocess.run(
        [
            str(venv / "bin" / "inerterlab"),
            "reproduce",
            "--quick",
            "--tables",
            "3.A",
            "--out",
            str(run / "report"),
        ],
        capture_output=True,
        text=True,
        cwd=run,
        env=env,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    html = (run / "report" / "index.html").read_text()
    assert "errata not found" not in html + r.stdout + r.stderr
    assert "Metal flywheel constant" in html
