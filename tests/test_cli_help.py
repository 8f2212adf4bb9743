"""Every command documents itself: --help works, states units and shows an example."""

import re

import pytest
import typer

from inerterlab.cli import app, main

COMMANDS = sorted(c.name for c in typer.main.get_command(app).commands.values())


def test_expected_commands_present():
    expected = {
        "flywheel",
        "device-force",
        "simulate",
        "h2",
        "sweep",
        "optimize-ratio",
        "frequency-response",
        "rig-simulate",
        "identify",
        "reproduce",
    }
    assert expected <= set(COMMANDS), sorted(expected - set(COMMANDS))


@pytest.mark.parametrize("name", COMMANDS)
def test_help_has_units_and_example(name, capsys):
    rc = main([name, "--help"])
    out = capsys.readouterr().out
    assert rc == 0
    assert "Example" in out, f"'{name} --help' shows no example"
    assert f"inerterlab {name}" in out
    assert re.search(r"\[(s|m|Hz|kg|N/m|m/s|rad/s|N s/m|kg m\^2|N|-)\]", out) or "SI" in out, (
        f"'{name} --help' states no unit"
    )


@pytest.mark.parametrize("name", COMMANDS)
def test_unknown_option_fails_with_exit_2(name, capsys):
    rc = main([name, "--definitely-not-an-option", "1"])
    err = capsys.readouterr().err
    assert rc == 2
    assert "--definitely-not-an-option" in err and len(err.strip().splitlines()) == 1
