"""The wheel's Monte Carlo trial: its columns, the study's world reaching its rigs, and recorded held-out
failures that must not come back."""

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


def test_rolling_on_past_a_dent_is_not_taken_for_the_rims_slip():
    # world-wheel-s-defect, trial 31 (glyph-06, a dent 0.35 mm deep and 3.8 mm long under the start): nothing fit
    # either way, the wheel rolled on 6 mm past it and localized beyond; the axle's path over the dent, sharper
    # than the rim, disagreed with rolling by 0.11 mm, which, summed with the slip of the steps after, stopped the
    # run as a slipping rim (WheelSlip) instead of ending it "mismatch" with the place
    study = load_study("bench/studies/world-wheel-s-defect.toml")
    row = run_trial(TrialSpec(study, 0, 31))
    assert row["failure"] == "" and row["reactive_failure"] == ""
    assert row["reactive_stopped"] == "mismatch" and row["reactive_success"] == 1
    lo, hi = (float(v) for v in row["reactive_mismatch_arc"].rsplit("-", 1))
    assert lo - 2.0 <= float(row["world_defect_arc"]) <= hi + 2.0


def test_the_studys_engine_is_the_wheels_world(monkeypatch):
    """A study's ``engine`` reaches both of a wheel trial's rigs (the calibration's and the localizing one):
    before, a wheel study said pymunk and rolled in the kinematic world."""
    from dataclasses import replace

    import sim2d

    engines = []

    class Recorded(sim2d.WheelRig):
        def __init__(self, *args, **kwargs):
            engines.append(kwargs.get("engine", "kinematic"))
            if len(engines) == 2:
                raise RuntimeError("both rigs made")  # the trial's failure: nothing needs to roll
            super().__init__(*args, **kwargs)

    monkeypatch.setattr(sim2d, "WheelRig", Recorded)
    study = load_study("bench/studies/wheel-heldout.toml")
    for engine in ("pymunk", "kinematic"):
        engines.clear()
        row = run_trial(TrialSpec(replace(study, engine=engine), 0, 86))
        assert "both rigs made" in row["reactive_failure"] or "both rigs made" in row["failure"]
        assert engines == [engine, engine]
