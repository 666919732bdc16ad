"""`benchmarks/plant_forks.py` counts the plant forks outside `sim/plants/` as its docstring says,
and the package keeps fewer than ten (issue 31: each plant described once, asked, not forked on)."""

import importlib.util
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "plant_forks.py"
_spec = importlib.util.spec_from_file_location("plant_forks", SCRIPT)
plant_forks = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(plant_forks)

COUNTED = """
def f(vehicle, spec, rotor, result, plant):
    if isinstance(vehicle, RotorVehicle):
        pass
    x = 1 if spec.rotor else 2
    if not rotor:
        pass
    if result.rotor_states is not None:
        pass
    if plant == "paper":
        pass
    y = f"{'a' if rotor else 'b'}"
"""

NOT_COUNTED = """
def g(vehicle, plant, rotor, loss):
    '''if rotor: a docstring's words are not code'''
    checks(isinstance(vehicle, (Vehicle, RotorVehicle)))  # a check that takes either plant's vehicle
    if plant.designs_gains:  # the plant asked
        pass
    who = "a rotor" if rotor is None else "rotor 2"  # a rotor's index
    if loss.rotor_loss:
        pass
    text = "if rotor and not paper"
"""


def _count(tmp_path, source):
    folder = tmp_path / "quadcruise"
    folder.mkdir(exist_ok=True)
    (folder / "m.py").write_text(source)
    return [f[1] for f in plant_forks.forks(tmp_path)]


def test_each_kind_of_fork_is_counted_once_a_line(tmp_path):
    assert _count(tmp_path, COUNTED) == [3, 5, 6, 8, 10, 12]


def test_a_plant_asked_a_type_check_and_words_are_not_forks(tmp_path):
    assert _count(tmp_path, NOT_COUNTED) == []


def test_the_plant_modules_are_left_out(tmp_path):
    folder = tmp_path / "quadcruise" / "sim" / "plants"
    folder.mkdir(parents=True)
    (folder / "rotor.py").write_text(COUNTED)
    assert plant_forks.forks(tmp_path) == []


def test_fewer_than_ten_plant_forks_outside_the_plant_modules():
    found = plant_forks.forks(plant_forks.ROOT)
    assert len(found) < 10, "\n".join(f"{rel}:{line}: {code.strip()}" for rel, line, _, code in found)
