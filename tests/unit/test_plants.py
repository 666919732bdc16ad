"""Each plant described once (`quadcruise.sim.plants`): a vehicle's plant is the one its preset file
names, the descriptions agree with the layouts the compiled plants read, and a refusal is one line
with the plant's reason."""

import numpy as np
import pytest

from quadcruise.errors import InputError
from quadcruise.layout import PARAMS, STATE
from quadcruise.model.rotor_plant import ROTOR_BODY, ROTOR_PARAMS, ROTOR_W1
from quadcruise.model.vehicle import Vehicle
from quadcruise.model.vehicle_files import PRESETS, preset_plant
from quadcruise.sim import plants


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_a_presets_plant_is_the_one_its_file_names(name):
    vehicle = Vehicle.preset(name)
    plant = plants.of(vehicle)
    assert plant.name == preset_plant(name)  # the file's own `plant` key, read by vehicle_files
    assert plants.named(plant.name) is plant and plants.of((vehicle,)) is plant
    assert plant.n_rotors(vehicle) == (4 if plant.name == "paper" else len(vehicle.rotors))
    assert plant.log_width(plant.vehicles(vehicle)) == (0 if plant.name == "paper" else ROTOR_W1 + len(vehicle.rotors))


def test_the_descriptions_hold_the_rows_the_compiled_plants_read():
    assert plants.PAPER.state is STATE and plants.PAPER.params is PARAMS
    assert plants.ROTOR.state is ROTOR_BODY and plants.ROTOR.params is ROTOR_PARAMS
    assert plants.ROTOR.carry.names[0] == "psi" and plants.PAPER.carry is None
    assert plants.of_arrays(None) is plants.PAPER and plants.of_arrays(np.zeros(17)) is plants.ROTOR
    assert plants.named(None) is plants.PAPER


def test_what_is_not_a_vehicle_has_no_plant():
    for thing in ("iris", 3.5, None, object()):
        with pytest.raises(InputError, match="must be a Vehicle or a RotorVehicle"):
            plants.of(thing)


def test_a_refusal_is_one_line_with_the_plants_reason_and_only_where_it_applies():
    with pytest.raises(
        InputError, match=r"^fly\(\) argument full_dynamics: not for a rotor-plant vehicle \(.*quaternion\)$"
    ):
        plants.ROTOR.refuse("fly()", "full_dynamics", True)
    with pytest.raises(InputError, match=r"^population field 'aero_spread': perturbs a rotor-plant"):
        plants.PAPER.refuse("population", "aero_spread", True, label="field")
    plants.ROTOR.refuse("fly()", "full_dynamics", False)  # not given: nothing to refuse
    plants.PAPER.refuse("fly()", "full_dynamics", True)  # the paper plant takes it
    plants.ROTOR.refuse("population", "aero_spread", True, label="field")  # a rotor vehicle has coefficients


def test_a_controller_vehicle_of_the_other_plant_is_refused_both_ways():
    iris, paper = Vehicle.preset("iris"), Vehicle.paper()
    with pytest.raises(InputError, match="must be of one plant"):
        plants.ROTOR.check_controller_vehicle((iris,), paper)
    with pytest.raises(InputError, match="must be of one plant"):
        plants.PAPER.check_controller_vehicle((paper,), iris)
    with pytest.raises(InputError, match="6 rotors, the flown vehicle 4"):
        plants.ROTOR.check_controller_vehicle((iris,), _hexa(iris))
    plants.ROTOR.check_controller_vehicle((iris,), iris.replace(m=1.4))
    plants.PAPER.check_controller_vehicle((paper,), paper.replace(m=3.0))


def _hexa(v):
    """A six-rotor vehicle of v's arms."""
    import math

    rotors = tuple(
        (0.25 * math.cos(k * math.pi / 3), 0.25 * math.sin(k * math.pi / 3), 0.0, 1 if k % 2 else -1) for k in range(6)
    )
    return v.replace(rotors=rotors)
