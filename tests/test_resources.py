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
