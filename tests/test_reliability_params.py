"""Property-based checks: every invalid parameter gives the documented error type.

For each parameter object, any non-finite, non-numeric or out-of-range value of any
numeric field must raise :class:`inerterlab.ParameterError` (never another exception,
never a silently built object), and the message must name the field.
"""

import dataclasses
import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from inerterlab import ParameterError
from inerterlab.flywheels import AdaptiveFlywheel, MetalFlywheelGeometry, NylonFlywheelGeometry
from inerterlab.slider_dynamics import SliderDynamics
from inerterlab.transmissions import Transmission

VALID = {
    AdaptiveFlywheel: dict(
        rest_inertia=1e-4,
        slider_mass=0.02,
        spring_stiffness=100.0,
        slider_min=0.02,
        slider_max=0.04,
    ),
    MetalFlywheelGeometry: {},
    NylonFlywheelGeometry: {},
    SliderDynamics: {},
    Transmission: dict(ratio=900.0),
}

# fields that must be strictly positive (anything <= 0 is invalid)
POSITIVE = {
    AdaptiveFlywheel: ["slider_mass", "spring_stiffness", "slider_min", "slider_max"],
    MetalFlywheelGeometry: [f.name for f in dataclasses.fields(MetalFlywheelGeometry)],
    NylonFlywheelGeometry: [f.name for f in dataclasses.fields(NylonFlywheelGeometry)],
    SliderDynamics: ["contact_stiffness", "restitution"],
    Transmission: ["ratio"],
}

NOT_A_NUMBER = st.one_of(
    st.just(math.nan),
    st.just(math.inf),
    st.just(-math.inf),
    st.text(max_size=5),
    st.none(),
    st.lists(st.floats(), max_size=2),
    st.booleans(),
)


def _numeric_fields(cls):
    base = cls(**VALID[cls])
    return [f.name for f in dataclasses.fields(cls) if isinstance(getattr(base, f.name), float)]


CASES = [(cls, name) for cls in VALID for name in _numeric_fields(cls)]


@pytest.mark.parametrize("cls, name", CASES, ids=[f"{c.__name__}.{n}" for c, n in CASES])
@settings(
    max_examples=15, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow]
)
@given(bad=NOT_A_NUMBER)
def test_non_numbers_rejected(cls, name, bad):
    kwargs = dict(VALID[cls])
    kwargs[name] = bad
    with pytest.raises(ParameterError) as e:
        cls(**kwargs)
    assert name in str(e.value)


POS_CASES = [(cls, name) for cls, names in POSITIVE.items() for name in names]


@pytest.mark.parametrize("cls, name", POS_CASES, ids=[f"{c.__name__}.{n}" for c, n in POS_CASES])
@settings(max_examples=10, deadline=None, derandomize=True)
@given(bad=st.floats(max_value=0.0, allow_nan=False, allow_infinity=False))
def test_non_positive_rejected(cls, name, bad):
    kwargs = dict(VALID[cls])
    kwargs[name] = bad
    with pytest.raises(ParameterError) as e:
        cls(**kwargs)
    assert name in str(e.value)


@settings(max_examples=50, deadline=None, derandomize=True)
@given(
    lo=st.floats(1e-4, 0.1),
    hi=st.floats(1e-4, 0.1),
)
def test_slider_travel_consistency(lo, hi):
    kwargs = dict(VALID[AdaptiveFlywheel], slider_min=lo, slider_max=hi)
    if lo < hi:
        fw = AdaptiveFlywheel(**kwargs)
        assert fw.inertia_max > fw.inertia_min > 0
    else:
        with pytest.raises(ParameterError, match="slider_min"):
            AdaptiveFlywheel(**kwargs)


def test_frozen_and_hashable():
    fw = AdaptiveFlywheel(**VALID[AdaptiveFlywheel])
    assert hash(fw) == hash(AdaptiveFlywheel(**VALID[AdaptiveFlywheel]))
    with pytest.raises(dataclasses.FrozenInstanceError):
        fw.slider_mass = 1.0  # type: ignore[misc]


@pytest.mark.parametrize("cls, name", CASES, ids=[f"{c.__name__}.{n}" for c, n in CASES])
def test_numeric_text_is_not_a_number(cls, name):
    """A number written as text ("1") is refused at the Python interface, naming the
    field (it used to pass the check and fail later in arithmetic)."""
    kwargs = dict(VALID[cls])
    kwargs[name] = "1"
    with pytest.raises(ParameterError) as e:
        cls(**kwargs)
    assert name in str(e.value)
