"""The reactive rolling's leave on whole study trials (a part that is not its model, or readings that jump)."""

from dataclasses import replace
from pathlib import Path

from bench.study import load_study
from bench.trial import run_trial
from bench.trial_context import TrialSpec

STUDIES = Path(__file__).resolve().parents[2] / "bench" / "studies"


def spread_rule(study):
    """``study`` rolled by the baseline direction rule (``seek = false``): the trials below that met their case
    on the way that rule rolls (seeking information, the jaw rolls elsewhere and the case does not arise)."""
    return replace(study, reactive=replace(study.reactive, seek=False))


def reported_near_the_defect(row, length=4.0):
    """Whether the trial's reported stretch (arc mm, not across the seam) lies within 2 mm of its defect's
    stretch (the issue's measure) and is no wider than the fit test's window (12 mm)."""
    lo, hi = map(float, row["reactive_mismatch_arc"].split("-"))
    defect = float(row["world_defect_arc"])
    return lo - 0.5 * length - 2.0 <= defect <= hi + 0.5 * length + 2.0 and hi - lo <= 12.0


def test_a_jump_that_does_not_come_again_is_not_left_through():
    # the part is its model, 1% of the wrist's readings spiked: on a filleted plate the jaw's contact place
    # jumps 3.3 mm one way while the contact stays, and the jaw then bridges the other way beyond its span.
    # It rolls back towards the first jump, which does not come again, returns and leaves through the second:
    # sure and right, nothing reported; staying on the way back it ended "mismatch" near the first
    row = run_trial(TrialSpec(load_study(STUDIES / "world-heldout-g-spikes.toml"), 0, 81))
    assert row["reactive_stopped"] == "confident" and row["reactive_mismatch_arc"] == ""
    assert row["reactive_success"] == 1


def test_a_filter_that_rules_out_every_start_starts_again_from_where_the_jaw_is():
    # the tuning family, a 0.3 x 4 mm burr 1.7 mm behind the start on a filleted plate: its readings rule out
    # every start after 94 degrees (the run ended there, 150 mm off). The filter starts again from the present
    # contact and localizes; the run is right, ends "mismatch" and places the burr from the new start
    row = run_trial(TrialSpec(load_study(STUDIES / "world-tuning.toml"), 0, 58))
    assert row["reactive_stopped"] == "mismatch" and row["reactive_success"] == 1
    assert reported_near_the_defect(row)


def test_the_reported_stretch_is_the_one_that_stopped_fitting_not_the_one_taken_out():
    # the tuning family, a 0.3 x 4 mm dent 0.9 mm ahead of the start on a superellipse: the fit test finds the
    # dent's readings, but the stretch taken out of the likelihood (the one whose absence lets some start fit
    # best) lay 22 mm on, at the part's tight bend, and was what the run reported. The run is right; where it
    # reports is where the readings stopped fitting, placed by the start it ends with
    row = run_trial(TrialSpec(spread_rule(load_study(STUDIES / "world-tuning-dent.toml")), 0, 12))
    assert row["reactive_stopped"] == "mismatch" and row["reactive_success"] == 1
    assert reported_near_the_defect(row)


def test_a_stretch_found_again_after_its_quarantine_is_taken_out_itself():
    # the tuning family, a 0.3 x 4 mm burr 0.6 mm ahead of the start on a superellipse: the fit test finds the
    # burr's stretch, the stretch taken out for it is another (the part's tight bend), and the test finds the
    # burr's again. Taking out the same other stretch each time, the run rolled its whole budget and ended
    # 0.39 mm off; taking out the burr's own readings the second time, it is right and soon over
    row = run_trial(TrialSpec(load_study(STUDIES / "world-tuning.toml"), 0, 40))
    assert row["reactive_stopped"] == "mismatch" and row["reactive_success"] == 1
    assert row["reactive_rotation_deg"] < 200.0


def test_a_jaw_boxed_in_by_jumps_the_model_explains_soon_after_its_start_leaves_and_reports():
    # the tuning family, a 0.3 x 4 mm burr 2.6 mm behind the start on a star: within 17 degrees the jaw bridges
    # both ways, jumps some place of the belief explains, and the run ended there "ambiguous", 90 mm off, saying
    # nothing (no run on a part that is its model is boxed in so soon). It leaves through the last jump as from
    # a burr, and ends "mismatch" with the burr inside the stretch it reports
    row = run_trial(TrialSpec(load_study(STUDIES / "world-tuning.toml"), 0, 21))
    assert row["reactive_stopped"] == "mismatch"
    lo, hi = map(float, row["reactive_mismatch_arc"].split("-"))
    assert lo <= float(row["world_defect_arc"]) <= hi


def test_a_jaw_blocked_both_ways_after_it_left_a_burr_moves_on_and_localizes_there():
    # the tuning family, a 0.3 x 4 mm burr 4.4 mm ahead of the start on a star: the jaw leaves the burr and is
    # blocked both ways again, by the burr and by the star's next concavity, with a belief of 0.54 that ended
    # the run 0.32 mm off at 101 degrees. It moves on through the concavity away from the burr, localizes
    # afresh there with the budget left and is right; the stretch it reports is where the belief before the
    # move put the burr
    row = run_trial(TrialSpec(spread_rule(load_study(STUDIES / "world-tuning.toml")), 0, 20))
    assert row["reactive_stopped"] == "mismatch" and row["reactive_success"] == 1
    assert row["reactive_rotation_deg"] > 120.0
    assert reported_near_the_defect(row)


def test_a_move_on_that_fails_puts_the_jaw_back_where_it_was_blocked(monkeypatch):
    # the tuning family with a bump or dent, a 0.31 mm bump 2.8 mm ahead of the start on a star: blocked both
    # ways after leaving it, the jaw moves on, lands at its end, and slid along itself finds no contact on its
    # span. The jaw is put back and the run ends on the belief it had there, as it ends without moving on; it
    # ended "lost", 131 mm off, before the jaw was put back
    study = load_study(STUDIES / "world-tuning-defect.toml")
    row = run_trial(TrialSpec(study, 0, 42))
    monkeypatch.setattr("driver.jaw.reactive_moves.MAX_MOVES", 0)
    unmoved = run_trial(TrialSpec(study, 0, 42))
    assert row["reactive_stopped"] == unmoved["reactive_stopped"] == "mismatch"
    assert row["reactive_rotation_deg"] > unmoved["reactive_rotation_deg"]  # it tried
    assert abs(row["reactive_error_mm"] - unmoved["reactive_error_mm"]) < 0.05
    assert row["reactive_mismatch_arc"] == unmoved["reactive_mismatch_arc"]
