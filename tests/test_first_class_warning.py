"""The integrator takes its right-hand side as a first-class function, which numba marks
experimental with a warning wherever it unifies such a function's type while compiling
(the integrator's first compilation after an install: four times). A command printed it
after its output on a user's first run ("inerterlab: warning:
NumbaExperimentalFeatureWarning: First-class function type feature is experimental").
The package filters that one warning, and only it: in the command line's record of
warnings, and for a program that imports the package."""

from __future__ import annotations

import json
import subprocess
import sys
import warnings

import inerterlab.cli as cli

CHOICE = '''
import numba as nb

def compile_a_first_class_choice():
    """numba's own example of the warning, in fresh dispatchers at each call."""

    @nb.njit
    def more(x):
        return x + 1

    @nb.njit
    def less(x):
        return x - 1

    @nb.njit
    def pick(sel, x):
        fn = more if sel else less
        return fn(x)

    return pick(True, 10)
'''


def _choice():
    space: dict = {}
    exec(CHOICE, space)  # noqa: S102 (the test's own source, above)
    return space["compile_a_first_class_choice"]


def test_the_command_line_does_not_print_it_and_prints_the_others(monkeypatch, capsys):
    compile_choice = _choice()

    def command(args, debug):
        assert compile_choice() == 11
        warnings.warn("another warning", UserWarning, stacklevel=1)
        return 0

    monkeypatch.setattr(cli, "_main", command)
    assert cli.main([]) == 0
    err = capsys.readouterr().err
    assert "First-class" not in err, err
    assert "inerterlab: warning: UserWarning: another warning" in err, err
    # the same compilation warns where nothing filters it: the test sees the real warning
    with warnings.catch_warnings(record=True) as raw:
        warnings.resetwarnings()
        warnings.simplefilter("always")
        assert compile_choice() == 11
    assert any("First-class" in str(w.message) for w in raw), [str(w.message) for w in raw]


def test_a_program_that_imports_the_package_does_not_see_it():
    script = CHOICE + '''
import json, warnings
import inerterlab.systems._compiled  # the package's integrator

with warnings.catch_warnings(record=True) as caught:
    compile_a_first_class_choice()
    warnings.warn("another warning", UserWarning, stacklevel=1)
print(json.dumps([str(w.message) for w in caught]))
'''
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    messages = json.loads(out.stdout.strip().splitlines()[-1])
    assert not any("First-class" in m for m in messages), messages
    assert any("another warning" in m for m in messages), messages
