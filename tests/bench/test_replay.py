"""Replaying one trial's reactive filter with other settings (bench.replay)."""

import math
from pathlib import Path

import pytest

from bench.replay import log_columns, main, record_trial, replay
from driver.records import replay_log
from localizer import ContactFilter

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    f = tmp_path_factory.mktemp("replay") / "s.toml"
    f.write_text(f'''
name = "replay"
parts = ["{ROOT / "parts" / "trefoil.json"}"]
rolls_deg = [20.0, 15.0]
methods = ["reactive"]
trials = 1
seed = 3
noise = "paper"
[reactive]
max_rotation_deg = 60.0
''')
    return f, record_trial(f, 0, 0)


@pytest.fixture(scope="module")
def as_run_replay(recorded):
    """``replay`` of the fixture's recording with the settings it ran with, to the end (None) or part-way
    (degrees), each made once for the module: a replay is deterministic, and its result is only read."""
    _, rec = recorded
    done = {}

    def replayed(at_deg=None):
        if at_deg not in done:
            done[at_deg] = replay(rec, at_deg)
        return done[at_deg]

    return replayed


@pytest.fixture
def recorded_once(recorded, as_run_replay, monkeypatch):
    """The command line given the fixture's recording of level 0, trial 0 instead of running the trial again
    for each command (a trial is deterministic: ``test_a_trial_records_the_same_calls_twice``), and that
    recording's replays as run from ``as_run_replay`` (the same call; variants are replayed anew)."""
    import bench.replay

    f, rec = recorded
    record, replay_one = bench.replay.record_trial, bench.replay.replay

    def once(study, level, trial):
        return rec if (Path(study), level, trial) == (f, 0, 0) else record(study, level, trial)

    def replayed(r, at_deg=None, **changes):
        return as_run_replay(at_deg) if r is rec and not changes else replay_one(r, at_deg, **changes)

    monkeypatch.setattr(bench.replay, "record_trial", once)
    monkeypatch.setattr(bench.replay, "replay", replayed)
    return recorded


def test_a_trial_records_the_same_calls_twice(recorded):
    f, rec = recorded
    import pickle

    again = record_trial(f, 0, 0)
    # byte for byte (NaN, which the calls and the row hold, is not equal to itself); all but the time it took
    assert pickle.dumps(again.calls) == pickle.dumps(rec.calls)
    assert [(k, pickle.dumps(v)) for k, v in again.row.items() if k != "time_s"] == [
        (k, pickle.dumps(v)) for k, v in rec.row.items() if k != "time_s"
    ]


def test_the_recorded_calls_give_back_the_run_belief(recorded, as_run_replay):
    _, rec = recorded
    names = {c[0] for c in rec.calls}
    assert {"touch", "update", "belief"} <= names and len(rec.calls) > 20
    as_run = as_run_replay()
    assert as_run.mass == pytest.approx(float(rec.row["reactive_mass"]), abs=1e-6)
    assert as_run.error_mm == pytest.approx(float(rec.row["reactive_error_mm"]), abs=0.06)
    assert as_run.margin > 0  # it localized: the true start leads


def test_the_recorded_calls_as_a_kept_log_give_back_the_run_belief(recorded_once, tmp_path, capsys):
    f, rec = recorded_once
    b = replay_log(ContactFilter(rec.part, **rec.settings), log_columns(rec.calls))
    assert b.mass == pytest.approx(float(rec.row["reactive_mass"]), abs=1e-6)
    out = tmp_path / "t.png"
    assert main([str(f), "--level", "0", "--trial", "0", "--show", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and "drawn to" in capsys.readouterr().out


def test_a_variant_changes_only_the_filter(recorded, as_run_replay):
    _, rec = recorded
    told_ten_times = replay(rec, sd_position=0.4, noise_scales=(1.0,))
    as_run = as_run_replay()
    assert told_ten_times.mass < as_run.mass
    assert told_ten_times.settings == {"sd_position": 0.4, "noise_scales": (1.0,)}


def test_the_command_line(recorded_once, capsys):
    f, _ = recorded_once
    assert main([str(f), "--level", "0", "--trial", "0", "--set", "temper=1", "--set", "nonsense=2"]) == 0
    out, err = capsys.readouterr()
    assert "as run" in out and "{'temper': 1}" in out
    assert "nonsense" in err
    with pytest.raises(ValueError, match="level=5"):
        record_trial(f, 5, 0)


def test_the_belief_part_way_is_that_of_the_calls_made_before_that_turn(recorded):
    import math

    from bench.replay import calls_until

    _, rec = recorded
    early = calls_until(rec.calls, 10.0)
    assert 0 < len(early) < len(rec.calls)
    assert all(abs(c[1][1]) < math.radians(10.0) for c in early if c[0] == "update")
    assert calls_until(rec.calls, None) == list(rec.calls) == calls_until(rec.calls, 1e6)
    # the robustness checks only lower what the model alone states
    alone = replay(rec, 10.0, defect_window=0.0, slope_envelope=(), lookalike_slope=0.0)
    assert alone.mass >= replay(rec, 10.0).mass
    assert alone.settings == {"defect_window": 0.0, "slope_envelope": (), "lookalike_slope": 0.0}


def test_a_variant_of_several_settings_on_the_command_line(recorded_once, capsys):
    f, _ = recorded_once
    assert main([str(f), "--level", "0", "--trial", "0", "--at", "20", "--set", "temper=1 defect_window=0"]) == 0
    assert main([str(f), "--level", "0", "--trial", "0", "--set", "corner_ends=false"]) == 0
    out, _ = capsys.readouterr()
    assert "after 20 degrees" in out and "{'temper': 1, 'defect_window': 0}" in out
    assert "{'corner_ends': False}" in out


def test_without_the_margin_the_belief_is_the_same(recorded, as_run_replay):
    import math

    _, rec = recorded
    quick, whole = replay(rec, 20.0, margin=False), as_run_replay(20.0)
    assert quick.mass == whole.mass and quick.error_mm == pytest.approx(whole.error_mm)
    assert quick.mismatch == whole.mismatch
    assert math.isnan(quick.margin) and math.isnan(quick.noise_scale)


def test_a_run_that_started_its_filter_again_is_replayed_whole():
    # world-tuning trial 7: a 0.3 mm burr near the start; the rolling left the model behind and started its
    # filter again from the contact it then touched, three times, before it stopped sure and right
    import math

    rec = record_trial(ROOT / "bench" / "studies" / "world-tuning.toml", 0, 7)
    names = [c[0] for c in rec.calls]
    assert "reset" in names[names.index("update") :]
    as_run = replay(rec)
    assert as_run.mass == pytest.approx(float(rec.row["reactive_mass"]), abs=1e-9)
    assert math.isnan(as_run.error_mm)  # the trial's start is no longer the filter's


def test_a_run_that_ended_on_a_mismatch_says_so_in_every_replay():
    # world-tuning trial 0: the burr's readings did not fit the part; the run ended "mismatch"
    rec = record_trial(ROOT / "bench" / "studies" / "world-tuning.toml", 0, 0)
    assert rec.row["reactive_stopped"] == "mismatch"
    assert replay(rec).mismatch and replay(rec, margin=False).mismatch


def test_a_bridge_recorded_without_its_jump_is_kept_with_the_default_one():
    from bench.replay import log_columns
    from driver.records import CALLS
    from localizer import BRIDGE_JUMP

    columns = log_columns([("bridged", (0.1,), {}), ("bridged", (0.2, 3.0), {"jump": 0.7}), ("belief", (), {})])
    assert list(columns["call"]) == [CALLS.index("bridged")] * 2 + [CALLS.index("belief")]
    assert columns["value"][0] == BRIDGE_JUMP and columns["value"][1] == 0.7
    assert columns["jaw"][1] == 3.0 and math.isnan(columns["jaw"][0]) and math.isnan(columns["value"][2])
