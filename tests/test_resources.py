import pytest

from inerterlab import ParameterError
from inerterlab.resources import available_memory, check_memory


def test_estimate_and_refusal():
    assert check_memory(1000, what="x", parameter="--horizon") == 8000
    with pytest.raises(ParameterError) as e:
        check_memory(1e12, what="saved time series", parameter="--horizon")
    msg = str(e.value)
    assert "--horizon" in msg and "saved time series" in msg and "TiB" in msg
    with pytest.raises(ParameterError):
        check_memory(200, what="x", parameter="--points", limit=1000)


def test_available_memory_positive():
    assert available_memory() > 0


def test_huge_sweep_refused_before_any_work():
    from inerterlab.studies.spec import sweep_spec

    with pytest.raises(ParameterError, match="sweep result grid"):
        sweep_spec(
            "synthetic",
            parameters={
                "changing_ratio": {"start": 0.01, "stop": 0.99, "num": 100000},
                "sprung_mass": {"start": 300, "stop": 400, "num": 100000},
            },
        )


def test_huge_saved_series_refused_up_front():
    from inerterlab import quarter_car
    from inerterlab.excitation import sine
    from inerterlab.simulate import SimulationOptions, simulate

    # 0.5 Hz: within the step budget's up-front bound (4 steps per period), not in memory
    with pytest.raises(ParameterError, match="sampled time series"):
        simulate(
            quarter_car("traditional"),
            sine(0.05, 0.5),
            1e6,
            options=SimulationOptions(sample_rate=1e6),
        )
