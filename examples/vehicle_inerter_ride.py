"""Full car on an ISO 8608 class C road: what a 30 kg inerter per strut does to ride.

Loads the packaged example car, adds an inerter to every strut, and prints the
spectral RMS of the Wk-weighted seat acceleration [m/s^2], the front-left suspension
deflection [mm] and the rear-left dynamic tyre load [N] at three speeds.
"""

from dataclasses import replace

from inerterlab.vehicles import (
    example_vehicle_path,
    linear_vehicle,
    load_vehicle,
    road_spectrum,
    spectral_response,
)

car = load_vehicle(example_vehicle_path())


def with_inertance(b):
    def corner(c):
        return replace(c, strut=replace(c.strut, inertance=b))

    return replace(car, front=corner(car.front), rear=corner(car.rear))


road = road_spectrum("C")
print(f"{'speed':>6s} {'inertance':>10s} {'seat Wk':>9s} {'defl FL':>8s} {'tyre RL':>8s}")
print(f"{'[m/s]':>6s} {'[kg]':>10s} {'[m/s^2]':>9s} {'[mm]':>8s} {'[N]':>8s}")
for speed in (10.0, 20.0, 30.0):
    for b in (0.0, 30.0):
        res = spectral_response(linear_vehicle(with_inertance(b)), road, speed)
        r = res.rms
        print(
            f"{speed:6.0f} {b:10.0f} {r['seat_acc_wk']:9.3f} "
            f"{1e3 * r['front_left_deflection']:8.2f} {r['rear_left_tyre_load']:8.0f}"
        )
