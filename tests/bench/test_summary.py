"""The calibration of a method's stated probability: the binned gap between what it states and how
often it is right, against sums written out by hand."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bench.summary import FULL_BIN, RELIABILITY_BINS, calibration, quantile


def rows(*groups):
    """Rows of the reactive method: for each (stated mass, trials, right), that many trials."""
    out = []
    for mass, n, right in groups:
        out += [{"reactive_mass": repr(mass), "reactive_success": str(int(i < right))} for i in range(n)]
    return out


def test_a_promise_kept_in_every_bin_has_no_calibration_error():
    cal = calibration("reactive", rows((0.25, 100, 25), (0.96, 100, 96)))
    assert cal["error"] == pytest.approx(0.0, abs=1e-12)
    assert cal["worst_gap"] == pytest.approx(0.0, abs=1e-12)
    assert [b["trials"] for b in cal["bins"]] == [100, 100]


def test_an_under_confident_method_is_off_by_its_gap_weighted_by_trials():
    # 50 trials said 0.6 and were all right (gap 0.4); 150 said 0.96 and 144 were right (gap 0)
    cal = calibration("reactive", rows((0.6, 50, 50), (0.96, 150, 144)))
    assert cal["error"] == pytest.approx(0.4 * 50 / 200)
    assert cal["worst_gap"] == pytest.approx(0.4)
    assert cal["bins"][0]["ci95"][0] < 1.0 == cal["bins"][0]["actual"]


def test_a_bin_of_few_trials_counts_in_the_error_but_is_not_held_to_its_promise_alone():
    cal = calibration("reactive", rows((0.6, FULL_BIN - 1, FULL_BIN - 1), (0.96, 100, 96)))
    assert cal["worst_gap"] == pytest.approx(0.0, abs=1e-12)
    assert cal["error"] == pytest.approx(0.4 * (FULL_BIN - 1) / (FULL_BIN - 1 + 100))


def test_a_method_that_states_nothing_has_no_calibration():
    assert calibration("reactive", [{"reactive_mass": "", "reactive_success": "1"}] * 5) is None


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0.0, 1.0), st.booleans()), min_size=1, max_size=60))
def test_the_error_is_the_trial_weighted_gap_of_the_bins(trials):
    data = [{"reactive_mass": repr(m), "reactive_success": str(int(ok))} for m, ok in trials]
    cal = calibration("reactive", data)
    expected = 0.0
    for lo, hi in zip(RELIABILITY_BINS[:-1], RELIABILITY_BINS[1:]):
        sel = [(m, ok) for m, ok in trials if lo <= m < hi]
        if sel:
            expected += abs(sum(m for m, _ in sel) / len(sel) - sum(ok for _, ok in sel) / len(sel)) * len(sel)
    assert cal["error"] == pytest.approx(expected / len(trials), abs=1e-12)
    assert cal["trials"] == len(trials) == sum(b["trials"] for b in cal["bins"])


def test_the_calibration_table_pools_studies_level_by_level(tmp_path, capsys):
    import csv

    from bench.calibration import calibration_table, main
    from bench.columns import TRIAL_COLUMNS

    for name, groups in (("a", [(0.6, 40, 40)]), ("b", [(0.6, 40, 20)])):
        (tmp_path / name).mkdir()
        with open(tmp_path / name / "trials.csv", "w", newline="") as f:
            fields = [*TRIAL_COLUMNS, "reactive_mass", "reactive_success", "reactive_stopped"]
            w = csv.DictWriter(f, fieldnames=fields, restval="")
            w.writeheader()
            for i, r in enumerate(rows(*groups)):
                w.writerow({"level": 0, "trial": i, "value": "x1", "success": r["reactive_success"], **r})
    recs = calibration_table([tmp_path / "a", tmp_path / "b"])
    by = {(r["study"], r["level"]): r for r in recs}
    assert by[("a", "x1")]["calibration"]["error"] == pytest.approx(0.4)
    assert by[("b", "x1")]["calibration"]["error"] == pytest.approx(0.1)
    assert by[("pooled", "x1")]["calibration"]["error"] == pytest.approx(0.15)  # 60 of 80 right at 0.6
    assert by[("pooled", "all")]["trials"] == 80
    assert main([str(tmp_path / "nothing")]) == 2 and "no trials.csv" in capsys.readouterr().err


def test_the_calibration_along_the_rolling_takes_every_mark_of_every_trial(tmp_path):
    import csv

    from bench.calibration import calibration_table
    from bench.columns import TRIAL_COLUMNS

    fields = [*TRIAL_COLUMNS, "reactive_mass", "reactive_success", "reactive_rotation_deg"]
    fields += ["reactive_curve", "reactive_mass_curve"]
    with open(tmp_path / "trials.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, restval="")
        w.writeheader()
        for i in range(10):
            # stated 0.9 at both marks; within the 0.3 mm radius at 5°, not at 10° (0.3 is not within)
            # the rolling stopped at 8°: the 15° mark repeats the 10° one and is not a statement of its own
            curve, masses = "5:0.1000 10:0.3000 15:0.3000", "5:0.9 10:0.9 15:0.9"
            cells = {"reactive_rotation_deg": 8.0, "reactive_curve": curve, "reactive_mass_curve": masses}
            w.writerow({"level": 0, "trial": i, "success": 0, "reactive_mass": "0.9", "reactive_success": 0, **cells})
    (tmp_path / "study.json").write_text('{"success_radius": 0.3}')
    rec = calibration_table([tmp_path])[0]
    assert rec["along"]["trials"] == 20
    assert rec["along"]["error"] == pytest.approx(0.4)
    assert rec["calibration"]["error"] == pytest.approx(0.9)
    (tmp_path / "study.json").unlink()  # without the radius, nothing along the rolling can be judged
    assert calibration_table([tmp_path])[0]["along"] is None


def test_sure_against_rotation_counts_each_trial_from_the_mark_it_is_sure_at():
    from bench.study import load_study
    from bench.summary import sure_by_rotation

    study = load_study("bench/studies/reactive.toml")  # confidence 0.95, 0.3 mm
    rows = [
        # sure from 10° on, and right there
        {"reactive_mass_curve": "5:0.5 10:0.96", "reactive_curve": "5:1.0000 10:0.0100"},
        # sure from 5° on, and wrong
        {"reactive_mass_curve": "5:0.97 10:0.97", "reactive_curve": "5:0.5000 10:0.5000"},
        # states nothing
        {"reactive_mass_curve": "", "reactive_curve": ""},
    ]
    by = sure_by_rotation(study, "reactive", rows)
    assert by["5"] == {"sure": pytest.approx(1 / 3), "sure_wrong": pytest.approx(1 / 3)}
    assert by["10"] == by["240"] == {"sure": pytest.approx(2 / 3), "sure_wrong": pytest.approx(1 / 3)}
    assert sure_by_rotation(study, "reactive", rows[2:]) is None


def test_a_quantile_among_failed_trials_is_infinite_not_nan():
    """Two of ten trials failed (infinite error): the 90% quantile lies between them."""
    err = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, np.inf, np.inf])
    assert quantile(err, 0.9) == np.inf
    assert quantile(err[:8], 0.5) == pytest.approx(np.quantile(err[:8], 0.5))
    assert quantile(np.array([0.1, np.inf]), 0.5) == np.inf
    assert np.isnan(quantile(np.array([0.1, np.nan]), 0.5))  # an unknown error stays unknown


def _mismatch_row(interval: str, centres: str, lengths: str, stopped: str = "mismatch") -> dict[str, str]:
    return {
        "part": "trefoil.json",
        "world_defect_arc": centres,
        "world_defect_length_mm": lengths,
        "reactive_stopped": stopped,
        "reactive_mismatch_arc": interval,
    }


def test_a_mismatch_interval_is_near_a_defect_within_two_millimetres_of_its_stretch_across_the_seam():
    from pathlib import Path

    from bench.study import Study
    from bench.summary import NEAR_DEFECT_MM, mismatch_near
    from localizer import load_part

    path = str(Path(__file__).resolve().parents[2] / "parts" / "trefoil.json")
    per = load_part(path).perimeter
    study = Study(name="near", parts=(path,), rolls_deg=(20.0,))
    assert NEAR_DEFECT_MM == 2.0

    def near(*rows: dict[str, str]) -> int | None:
        return mismatch_near(study, "reactive", rows)

    # (interval, centre, length, near?): the defect's stretch is its centre ± half its length
    cases = [
        ("10.00-20.00", 15.0, 4.0, True),  # inside
        ("10.00-20.00", 23.9, 4.0, True),  # 3.9 mm past the end: 1.9 mm from the stretch
        ("10.00-20.00", 24.1, 4.0, False),
        ("10.00-20.00", 7.1, 2.0, True),  # 2.9 mm before the start, 1 mm half-length
        ("10.00-20.00", 6.9, 2.0, False),
        (f"{per - 5:.2f}-3.00", 1.0, 2.0, True),  # the interval runs across the seam
        (f"{per - 5:.2f}-3.00", per - 7.9, 2.0, True),
        (f"{per - 5:.2f}-3.00", per - 8.1, 2.0, False),
        ("1.00-3.00", per - 1.9, 2.0, True),  # the defect across the seam from the interval
        ("1.00-3.00", per - 2.1, 2.0, False),
    ]
    for interval, centre, length, expected in cases:
        assert near(_mismatch_row(interval, f"{centre:.3f}", f"{length:.3f}")) == int(expected), (interval, centre)
    # several defects: near one of them counts once
    assert near(_mismatch_row("10.00-20.00", "100.000 15.000", "4.000 4.000")) == 1
    # a run that did not end mismatch, or could not tell where, is not near
    assert near(_mismatch_row("10.00-20.00", "15.000", "4.000", stopped="budget")) == 0
    assert near(_mismatch_row("unknown", "15.000", "4.000")) == 0
    # no defect in the study's worlds, or a table written before the lengths: nothing to count
    assert near(_mismatch_row("10.00-20.00", "", "")) is None
    old = _mismatch_row("10.00-20.00", "15.000", "4.000")
    del old["world_defect_length_mm"]
    assert near(old) is None
