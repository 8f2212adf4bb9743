"""Plotting never chooses a matplotlib backend: the user's stays, headless still works."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

SRC = str(Path(__file__).resolve().parents[1] / "src")

SCRIPT = textwrap.dedent(
    """
    import sys
    import matplotlib
    {select}
    before = matplotlib.get_backend()
    import inerterlab
    from inerterlab.plotting import plot_flywheel

    figs = [plot_flywheel(inerterlab.flywheel("nylon"))]
    car = inerterlab.quarter_car("traditional")
    figs.append(inerterlab.simulate(car, inerterlab.bump(0.05), 0.5).plot())
    fr = inerterlab.frequency_response(inerterlab.chapter7_system(0.03), "shb",
                                       freq_hz=[0.8, 1.2])
    figs.append(fr.plot())
    dev = inerterlab.device_preset("hydraulic")
    f = inerterlab.device_force(dev, inerterlab.Motion.sine(frequency=1.0, amplitude=0.005),
                                duration=0.5, sample_rate=50)
    figs.append(f.plot().figure)
    for i, fig in enumerate(figs):
        fig.savefig(sys.argv[1] + f"/fig{{i}}.png")
    print(before, matplotlib.get_backend(), "matplotlib.pyplot" in sys.modules)
    """
)


def _run(tmp_path, select, env_extra=None):
    env = {k: v for k, v in os.environ.items() if k not in ("MPLBACKEND", "DISPLAY")}
    env["PYTHONPATH"] = SRC
    env.update(env_extra or {})
    script = tmp_path / "plot.py"
    script.write_text(SCRIPT.format(select=select))
    r = subprocess.run(
        [sys.executable, str(script), str(tmp_path)],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr[-3000:]
    assert len(list(tmp_path.glob("fig*.png"))) == 4
    return r.stdout.split()


def test_backend_chosen_by_the_user_is_left_alone(tmp_path):
    before, after, pyplot = _run(tmp_path, 'matplotlib.use("template")')
    assert before == after == "template"
    assert pyplot == "False"  # the object-oriented API only


def test_headless_without_any_backend_setting(tmp_path):
    before, after, _ = _run(tmp_path, "")
    assert after == before
