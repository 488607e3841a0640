"""The wheel's Monte Carlo trial: its columns, and a recorded held-out failure that must not come back."""

import math

from bench.columns import FINGER_COLUMNS
from bench.study import load_study
from bench.trial import TrialSpec, run_trial


def test_a_wheel_jammed_at_a_pockets_mouth_retraces_and_localizes():
    # wheel-heldout, x0.5, trial 86 (star-08): the 5 mm wheel jammed 1.8 mm after its start, and the
    # filter, normalising over starts that all fitted badly, stopped sure (0.99999) 366 mm off
    study = load_study("bench/studies/wheel-heldout.toml")
    row = run_trial(TrialSpec(study, 0, 86))
    assert row["failure"] == ""
    assert row["reactive_success"] == 1 and row["reactive_stopped"] == "confident"
    assert set(FINGER_COLUMNS) <= set(row) and row["jaw"] == "wheel:5" and math.isfinite(row["arc_mm"])
    assert set(study.columns) == set(row)
