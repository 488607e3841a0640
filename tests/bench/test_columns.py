"""The typed parts of a trial's row are the columns of trials.csv, each exactly once."""

import math
from typing import get_type_hints

import pytest

from bench.columns import (
    FINGER_COLUMNS,
    METHOD_COLUMNS,
    TRIAL_COLUMNS,
    WORLD_COLUMNS,
    FingerCells,
    MethodCells,
    RollCells,
    ScoreCells,
    Scored,
    TrialHead,
    WorldCells,
    trial_row,
)
from bench.study import load_study


def keys(typed):
    return list(get_type_hints(typed))


def test_the_trial_parts_are_the_trial_columns_each_once():
    parts = keys(TrialHead) + keys(RollCells) + keys(ScoreCells) + ["time_s"]
    assert sorted(parts) == sorted(TRIAL_COLUMNS)
    assert len(parts) == len(set(parts))


@pytest.mark.parametrize(
    ("typed", "columns"), [(MethodCells, METHOD_COLUMNS), (FingerCells, FINGER_COLUMNS), (WorldCells, WORLD_COLUMNS)]
)
def test_each_typed_part_is_its_columns_in_order(typed, columns):
    assert tuple(keys(typed)) == columns


class _Rolled:
    def __init__(self, finger):
        self.cells = {"start_arc": 1.0, "restarts": 0, "lengths": "", "turns": ""}
        self.finger = finger
        self.change = None


def _method(i):
    return dict(zip(METHOD_COLUMNS, [i] * len(METHOD_COLUMNS), strict=True))


@pytest.mark.parametrize("name", ["wheel-heldout", "world-heldout-g-defect", "reactive"])
def test_a_row_of_a_study_has_exactly_its_columns(name):
    # a wheel's study names its finger, a world study has a [world] table: every column, and no other
    study = load_study(f"bench/studies/{name}.toml")
    head = {"level": 0, "trial": 3, "parameter": "", "value": None, "part": "p.json"}
    score = dict.fromkeys(keys(ScoreCells), 0)
    finger = dict.fromkeys(FINGER_COLUMNS, 0) if study.fingers else None
    scored = Scored(score, {m: _method(k) for k, m in enumerate(study.methods)}, 2)
    row = trial_row(head, _Rolled(finger), scored, 0.5, world=study.world is not None)
    assert set(row) == set(study.columns)
    assert (study.world is not None) == (set(WORLD_COLUMNS) <= set(row))
    assert row["time_s"] == 0.5 and row["trial"] == 3
    for k, m in enumerate(study.methods):
        assert all(row[f"{m}_{c}"] == k for c in METHOD_COLUMNS)
    assert not any(isinstance(v, float) and math.isnan(v) for v in row.values())
