"""The registry of methods: every method a study may name is scored by one entry of it."""

from bench.columns import METHODS
from bench.methods import SCORERS


def test_the_registry_scores_exactly_the_methods_a_study_may_name():
    assert tuple(SCORERS) == METHODS


def test_only_the_reactive_method_rolls_on_its_own():
    assert {m for m, s in SCORERS.items() if not s.fixed_rolls} == {"reactive"}


def test_the_rotation_curve_states_the_last_checks_belief_at_each_mark_then_the_final_one():
    import math

    from bench.reactive_method import rotation_curve
    from localizer import load_part

    part = load_part("parts/cam.json")
    rad = math.radians
    # checks at 3°, 7° and 12° (rotation, map_arc, mass, true_arc); the rolling stopped at 13°
    history = [(rad(3.0), 10.0, 0.2, 10.5), (rad(7.0), 20.0, 0.6, 20.1), (rad(12.0), 30.0, 0.9, 30.0)]
    curve = rotation_curve(part, history, 13.0, 0.05, 20.0, final_mass=0.97)
    assert [k for k, _, _ in curve] == [5.0, 10.0, 15.0, 20.0]
    assert [p for _, _, p in curve] == [0.2, 0.6, 0.97, 0.97]
    assert [round(e, 6) for _, e, _ in curve] == [0.5, 0.1, 0.05, 0.05]
    # before the first check nothing is stated
    assert math.isnan(rotation_curve(part, history[1:], 13.0, 0.05, 5.0)[0][2])
