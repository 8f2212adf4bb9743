"""The coverage benchmark's machinery on a tiny run (not its statistics)."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_identify_coverage.py"


def _tiny_run(out, *extra) -> list:
    """Two screw campaigns of 0.5 s records at 100 Hz into ``out``; ``--sample-rate``
    comes last so a test can change it."""
    return [sys.executable, str(BENCH), "--campaigns", "2", "--devices", "screw",
            "--out", str(out), *extra, "--max-duration", "0.5", "--sample-rate", "100"]  # fmt: skip


@pytest.mark.slow
def test_coverage_benchmark_runs_caches_and_resumes(tmp_path):
    out = tmp_path / "cov"
    cmd = _tiny_run(out)
    first = subprocess.run(cmd, capture_output=True, text=True)
    assert first.returncode == 0, first.stderr
    assert "2 to run" in first.stdout
    lines = [ln.split() for ln in first.stdout.splitlines() if ln.startswith("screw ")]
    assert [ln[1] for ln in lines[:3]] == ["stiffness", "damping", "friction"]
    for ln in lines[:3]:
        assert ln[2] == "2" and 0.0 <= float(ln[3]) <= 1.0
    files = sorted((out / "screw").glob("seed_*.json"))
    assert [f.name for f in files] == ["seed_0001.json", "seed_0002.json"]
    rec = json.loads(files[0].read_text())
    assert rec["stiffness"]["ci95"][0] <= rec["stiffness"]["value"] <= rec["stiffness"]["ci95"][1]
    # resumed: one result removed, only that one is computed again, same summary
    files[1].unlink()
    second = subprocess.run(cmd, capture_output=True, text=True)
    assert second.returncode == 0, second.stderr
    assert "1 cached, 1 to run" in second.stdout
    summary = lambda s: [ln for ln in s.splitlines() if ln.startswith("screw ")][:3]  # noqa: E731
    assert summary(second.stdout) == summary(first.stdout)
    # other settings into the same folder are refused
    bad = subprocess.run(cmd[:-1] + ["200"], capture_output=True, text=True)
    assert bad.returncode == 2 and "settings" not in bad.stdout and "another --out" in bad.stderr


@pytest.mark.slow
def test_coverage_benchmark_studies_a_designed_campaign(tmp_path):
    out = tmp_path / "cov_design"
    cmd = _tiny_run(out, "--design", "3")
    first = subprocess.run(cmd, capture_output=True, text=True)
    assert first.returncode == 0, first.stderr
    design = json.loads((out / "screw" / "design.json").read_text())
    assert design["budget"] == 3 and len(set(design["tests"])) == 3
    assert 0.0 < design["efficiency"] < 1.0
    # the predicted standard errors of fewer tests are no smaller than the whole matrix's
    assert all(r >= 1.0 - 1e-9 for r in design["predicted_se_ratio"].values())
    assert f"designed campaign of 3 tests {design['tests']}" in first.stdout
    for f in sorted((out / "screw").glob("seed_*.json")):
        assert json.loads(f.read_text())["tests"] == design["tests"]
    rows = [ln.split() for ln in first.stdout.splitlines() if ln.startswith("screw ")]
    assert all(float(r[6]) > 0 for r in rows[:6])  # the mean interval width
    # a rerun reads the stored design and every campaign from the cache
    second = subprocess.run(cmd, capture_output=True, text=True)
    assert second.returncode == 0 and "2 cached, 0 to run" in second.stdout


@pytest.mark.slow
def test_coverage_benchmark_runs_the_network_engine(tmp_path):
    """--engine network fits the device as a composite element with identify_network:
    on the screw (affine, no internal state) it gives the device kernel's estimates."""
    runs = {}
    for engine in ("device", "network"):
        out = tmp_path / engine
        done = subprocess.run(_tiny_run(out, "--engine", engine), capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        runs[engine] = json.loads((out / "screw" / "seed_0001.json").read_text())
    assert json.loads((tmp_path / "network" / "settings.json").read_text())["engine"] == "network"
    for n in ("stiffness", "damping", "friction"):
        a, b = runs["device"][n], runs["network"][n]
        assert abs(a["value"] - b["value"]) <= 1e-3 * a["std_error"], n
