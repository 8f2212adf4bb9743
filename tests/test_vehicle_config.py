"""Vehicle TOML files: units, layout, and errors naming file, key and line."""

from __future__ import annotations

import pytest

from inerterlab.errors import DataFileError, ParameterError
from inerterlab.vehicles import FullCar, HalfCar
from inerterlab.vehicles.config import (
    example_vehicle_path,
    load_vehicle,
    loads_vehicle,
    parse_quantity,
    parse_unit,
)

HALF = """model = "half"
sprung_mass = "1.2 t"
pitch_inertia = { value = 1800, unit = "kg m^2" }
cg_to_front = "115 cm"
cg_to_rear = "1.45 m"

[front]
unsprung_mass = "80 kg"
stiffness = "56 N/mm"
damping = "4.4 kN s/m"
inertance = "100 kg"
tyre_stiffness = "400 kN/m"

[rear]
unsprung_mass = "76 kg"
stiffness = "50 kN/m"
damping = "4000 Ns/m"
tyre_stiffness = "400 kN/m"
tyre_damping = "100 N*s/m"
"""


@pytest.mark.parametrize(
    "text,si,dim",
    [
        ("kN/m", 1e3, "stiffness"),
        ("N/mm", 1e3, "stiffness"),
        ("N s/m", 1.0, "damping"),
        ("kN·s/m", 1e3, "damping"),
        ("kg m²", 1.0, "inertia"),
        ("kg*m^2", 1.0, "inertia"),
        ("t", 1e3, "mass"),
        ("mm", 1e-3, "length"),
    ],
)
def test_units(text, si, dim):
    from inerterlab.vehicles.config import DIMENSIONS

    f, d = parse_unit(text)
    assert f == pytest.approx(si)
    assert d == DIMENSIONS[dim]


def test_quantity_errors():
    with pytest.raises(ParameterError, match="unit of stiffness"):
        parse_quantity("20 kg", "stiffness")
    with pytest.raises(ParameterError, match="with a unit"):
        parse_quantity(20, "mass")
    with pytest.raises(ParameterError, match="furlong"):
        parse_quantity("3 furlong", "length")


def test_half_car_file():
    car = loads_vehicle(HALF)
    assert isinstance(car, HalfCar)
    assert car.sprung_mass == 1200.0
    assert car.cg_to_front == pytest.approx(1.15)
    assert car.front.strut.stiffness == pytest.approx(56e3)
    assert car.front.strut.damping == pytest.approx(4400.0)
    assert car.front.strut.inertance == 100.0
    assert car.rear.tyre.damping == 100.0
    assert car.seat is None


def test_example_file_loads():
    car = load_vehicle(example_vehicle_path())
    assert isinstance(car, FullCar)
    assert car.rear_anti_roll == 4000.0
    assert car.seat.y == pytest.approx(0.37)


@pytest.mark.parametrize(
    "old,new,match",
    [
        ('damping = "4.4 kN s/m"', 'damping = "4.4 kN/m"', r"car.toml, line 10: \[front\] damping"),
        ('cg_to_rear = "1.45 m"', 'cg_to_rear = "-1 m"', r"line 5: cg_to_rear: .*> 0 m"),
        (
            'stiffness = "50 kN/m"',
            'stiffnes = "50 kN/m"',
            r"line 16: \[rear\] stiffnes: unknown key",
        ),
        ('unsprung_mass = "80 kg"', 'unsprung_mass = "0 kg"', r"line 8: \[front\] unsprung_mass"),
        ('sprung_mass = "1.2 t"', "sprung_mass = 1200", r"line 2: sprung_mass: .*unit of mass"),
        ('tyre_stiffness = "400 kN/m"\n\n', "\n\n", r"line 7: \[front\] tyre_stiffness: missing"),
        ('model = "half"', 'model = "bus"', r"line 1: model"),
        ("[rear]", "[rear", r"car.toml, line 14: not valid TOML"),
    ],
)
def test_errors_name_file_key_and_line(old, new, match):
    assert old in HALF
    with pytest.raises(DataFileError, match=match):
        loads_vehicle(HALF.replace(old, new, 1), "car.toml")


def test_missing_file(tmp_path):
    with pytest.raises(DataFileError, match="cannot read"):
        load_vehicle(tmp_path / "none.toml")
