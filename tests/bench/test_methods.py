"""The registry of methods: every method a study may name is scored by one entry of it."""

from bench.columns import METHODS
from bench.methods import SCORERS


def test_the_registry_scores_exactly_the_methods_a_study_may_name():
    assert tuple(SCORERS) == METHODS


def test_only_the_reactive_method_rolls_on_its_own():
    assert {m for m, s in SCORERS.items() if not s.fixed_rolls} == {"reactive"}
