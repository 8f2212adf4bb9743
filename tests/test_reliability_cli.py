"""Bad command-line input across every command: one line on stderr, exit status 2.

Each case names the option (or parameter) it must mention. The count of cases per
class is summarised in docs/reliability.md.
"""

import pytest

from inerterlab.cli import main

CASES = [
    # (class, args, what the message must name)
    ("non-number", ["simulate", "--suspension", "afw", "--amplitude", "abc"], "--amplitude"),
    ("non-number", ["simulate", "--horizon", "ten"], "--horizon"),
    ("non-finite", ["simulate", "--horizon", "nan"], "horizon"),
    ("non-finite", ["simulate", "--sprung-mass", "inf"], "sprung"),
    ("out of range", ["simulate", "--horizon", "-1"], "horizon"),
    ("out of range", ["simulate", "--sprung-mass", "-370"], "sprung"),
    (
        "out of range",
        ["simulate", "--changing-ratio", "1.2", "--suspension", "afw"],
        "changing_ratio",
    ),
    ("out of range", ["simulate", "--input", "sine", "--freq", "0"], "freq"),
    ("unknown choice", ["simulate", "--suspension", "magic"], "suspension"),
    ("unknown choice", ["simulate", "--law", "newton"], "law"),
    ("unknown choice", ["simulate", "--input", "iso8608", "--class", "Z"], "class"),
    ("missing file", ["simulate", "--input", "/nonexistent/road.csv"], "road.csv"),
    ("out of range", ["h2", "--suspension", "cfw", "--inertance", "-5"], "inertance"),
    ("unknown choice", ["h2", "--suspension", "afw"], "suspension"),
    ("out of range", ["frequency-response", "--fmin", "2", "--fmax", "1"], "--fmin"),
    ("out of range", ["frequency-response", "--harmonics", "0"], "harmonics"),
    ("out of range", ["frequency-response", "--df", "-0.1"], "df"),
    ("non-number", ["frequency-response", "--amplitude", "x"], "--amplitude"),
    ("unknown choice", ["frequency-response", "--method", "guess"], "method"),
    ("unknown choice", ["frequency-response", "--flywheel", "wood"], "flywheel"),
    ("non-number", ["device-force", "--amplitude", "abc"], "amplitude"),
    ("out of range", ["device-force", "--amplitude", "-0.01"], "amplitude"),
    ("out of range", ["device-force", "--freq", "0"], "freq"),
    ("unknown choice", ["device-force", "--device", "magnet"], "device"),
    ("unknown choice", ["device-force", "--signal", "chirp"], "signal"),
    ("unknown choice", ["device-force", "--amplitude", "0.01", "--law", "x"], "law"),
    ("out of range", ["optimize-ratio", "--comfort-weight", "1.5"], "comfort"),
    ("out of range", ["optimize-ratio", "--input-weights", "0.5,0.5,0.5"], "weights"),
    ("non-number", ["optimize-ratio", "--input-weights", "a,b,c"], "weights"),
    ("unknown choice", ["optimize-ratio", "--cost", "cheap"], "cost"),
    ("unknown choice", ["optimize-ratio", "--device", "magic"], "device"),
    ("missing file", ["sweep", "/nonexistent/cfg.toml", "--out", "/tmp/x.zarr"], "cfg.toml"),
    ("out of range", ["reproduce", "--tables", "99.1"], "--tables"),
    ("unknown choice", ["flywheel", "--preset", "wood"], "preset"),
    ("out of range", ["flywheel", "--changing-ratio", "0"], "changing_ratio"),
    (
        "missing file",
        ["identify", "--device", "hydraulic", "--data", "/nonexistent/dir"],
        "nonexistent",
    ),
    ("unknown choice", ["rig-simulate", "--matrix", "appendix-z", "--out", "/tmp/rigx"], "matrix"),
    ("out of range", ["rig-simulate", "--noise", "-1", "--out", "/tmp/rigx"], "noise"),
]


@pytest.mark.parametrize("kind, args, needle", CASES, ids=[" ".join(c[1][:3]) for c in CASES])
def test_bad_cli_input(kind, args, needle, capsys):
    rc = main(args)
    out, err = capsys.readouterr()
    assert rc == 2, (rc, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert needle.lower() in lines[0].lower(), lines[0]
    assert "Traceback" not in err
    assert "nan" not in out.lower()


def test_debug_flag_shows_traceback_for_internal_errors(capsys, monkeypatch):
    import inerterlab.flywheels as fw

    def boom(*a, **k):
        raise RuntimeError("simulated internal failure")

    monkeypatch.setattr(fw, "flywheel", boom)
    rc = main(["flywheel", "--json"])
    err = capsys.readouterr().err
    assert rc == 1 and "--debug" in err and "simulated internal failure" in err
    with pytest.raises(RuntimeError):
        main(["flywheel", "--json", "--debug"])
