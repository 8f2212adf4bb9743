"""The quarter-car sweep's point function gives the metrics recorded for 12 points of
benchmarks/bench_sweep.py's grid (the `afw` car on a drop, a bump and a 5 Hz sine, four
cars), to 1e-9 relative: a speed change of the sweep's set-up must keep them."""

import json
import math
from pathlib import Path

from inerterlab.studies.quarter_car import quarter_car_point

DATA = Path(__file__).parent / "data" / "sweep_points_afw.json"


def test_sweep_points_keep_their_recorded_metrics():
    points = json.loads(DATA.read_text())["points"]
    assert len(points) == 12
    for p in points:
        got = quarter_car_point(p["params"])
        assert got.keys() == p["metrics"].keys()
        for k, want in p["metrics"].items():
            if want is None:
                assert got[k] is None, (p["params"]["input"], k)
            else:
                assert math.isclose(got[k], want, rel_tol=1e-9, abs_tol=0.0), (
                    p["params"]["input"], k, got[k], want,
                )
