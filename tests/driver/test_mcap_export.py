"""rolltouch export: a run's record as MCAP, read back with the mcap library's own reader."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from driver.cli import main
from driver.records import TOPICS, RunLog, Trace

PARTS = Path(__file__).resolve().parents[2] / "parts"


def read_back(path):
    """{topic: [(log time s, message)]}, the schemas' encodings and the metadata, as the mcap reader reads them."""
    out, encodings = {}, set()
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages():
            encodings.add((schema.encoding, channel.message_encoding))
            out.setdefault(channel.topic, []).append((message.log_time / 1e9, json.loads(message.data)))
        meta = {m.name: m.metadata for m in reader.iter_metadata()}
    return out, encodings, meta


def simulate(tmp_path, *extra):
    out = tmp_path / "t.npz"
    args = ["simulate", str(PARTS / "trefoil.json"), "--start", "120", "--noise", "paper", "--engine", "kinematic"]
    assert main([*args, "--out", str(out), *extra]) == 0
    return out


def test_a_two_roll_trace_reads_back_reading_by_reading(tmp_path, capsys):
    trace_file = simulate(tmp_path, "--roll", "20", "--roll", "15")
    out = tmp_path / "run.mcap"
    assert main(["export", str(trace_file), "--mcap", str(out)]) == 0
    assert "messages written to" in capsys.readouterr().out
    topics, encodings, meta = read_back(out)
    assert encodings == {("jsonschema", "json")}
    trace = Trace.load(trace_file)
    c = trace.columns
    n = c["time"].size
    assert n > 100
    for name in ("wrist", "arm", "truth"):
        assert len(topics[TOPICS[name]]) == n
    wrist, arm, truth = (topics[TOPICS[k]] for k in ("wrist", "arm", "truth"))
    assert [t for t, _ in wrist] == pytest.approx(list(c["time"]), abs=1e-9)
    assert [m["dv2"] for _, m in wrist] == pytest.approx(list(c["dv2"]))
    assert [m["jaw_position"] for _, m in wrist] == pytest.approx(list(trace.jaw_positions()))
    assert [m["phi"] for _, m in arm] == pytest.approx(list(c["phi"]))
    assert [m["true_arc"] for _, m in truth] == pytest.approx(list(c["true_arc"]))
    assert json.loads(meta["rolltouch"]["format"]) == "rolltouch-trace/1"


def test_a_reactive_trace_has_its_belief_at_each_check(tmp_path):
    trace_file = simulate(tmp_path, "--reactive", "--seed", "3")
    out = tmp_path / "run.mcap"
    assert main(["export", str(trace_file), "--mcap", str(out)]) == 0
    topics, _, _ = read_back(out)
    with np.load(trace_file) as data:
        arcs, history = data["arcs"], data["history"]
    assert len(topics[TOPICS["wrist"]]) == len(topics[TOPICS["arm"]]) == arcs.size
    assert [m["arc"] for _, m in topics[TOPICS["wrist"]]] == pytest.approx(list(arcs))
    belief = topics[TOPICS["belief"]]
    assert len(belief) == len(history) > 0
    assert [m["mass"] for _, m in belief] == pytest.approx(list(history[:, 2]))
    times = [t for t, _ in belief]
    assert times == sorted(times)


def test_a_run_log_keeps_every_event_on_its_topic(tmp_path):
    log_file = tmp_path / "run.jsonl"
    log = RunLog(log_file, {"part": "cam", "calibration": {"positions": [0.0], "ratios": [1.0], "target": 1.0}})
    log({"event": "roll", "roll": 0, "angle": 0.35, "step": 0.0035, "steps": 100, "offset": 1.2, "time": 1.0})
    for k in range(3):
        reading = {"event": "reading", "roll": 0, "step": k, "time": 1.5 + k, "x": 10.0 + k, "y": 2.0, "phi": 0.1 * k}
        log({**reading, "phi_command": 0.1 * k, "dv1": 1.0, "dv2": 0.5 + k, "jaw_position": -40.0 + k})
    log({"event": "sample", "v1": 0.25, "v2": math.nan, "n": 32, "time": 4.0})
    log({"event": "belief", "rotation": 0.2, "map_arc": 33.0, "mass": 0.4, "modes": [[33.0, 0.4], [90.0, 0.3]]})
    log({"event": "result", "stopped": "confident", "time": 9.0})
    log.close()
    out = tmp_path / "run.mcap"
    assert main(["export", str(log_file), "--mcap", str(out)]) == 0
    topics, _, meta = read_back(out)
    wrist = topics[TOPICS["wrist"]]
    assert [m.get("dv2") for _, m in wrist] == [0.5, 1.5, 2.5, None]  # three readings, then the raw sample
    assert wrist[3][1] == {"v1": 0.25, "v2": None}  # NaN is written as null
    assert [t for t, _ in wrist] == pytest.approx([1.5, 2.5, 3.5, 4.0], abs=1e-6)  # the log's own clock
    assert [m["x"] for _, m in topics[TOPICS["arm"]]] == [10.0, 11.0, 12.0]
    assert TOPICS["truth"] not in topics  # a real rig knows no truth
    ((_, belief),) = topics[TOPICS["belief"]]
    assert belief["modes"] == [{"arc": 33.0, "mass": 0.4}, {"arc": 90.0, "mass": 0.3}]
    assert [m["event"] for _, m in topics[TOPICS["event"]]] == ["result"]
    assert topics[TOPICS["roll"]][0][1]["offset"] == 1.2
    assert json.loads(meta["rolltouch"]["part"]) == "cam"


def test_what_is_not_a_record_is_refused_by_name(tmp_path, capsys):
    bad = tmp_path / "x.npz"
    np.savez(bad, metadata=np.array(json.dumps({"format": "something-else/1"})))
    assert main(["export", str(bad), "--mcap", str(tmp_path / "o.mcap")]) == 2
    assert "format 'something-else/1' is none of a run's records" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["export", str(bad), "--mcap", str(tmp_path / "o.bag")])
    assert "must end in .mcap" in capsys.readouterr().err


def test_a_wheel_trace_reads_back_reading_by_reading(tmp_path):
    trace_file = tmp_path / "w.npz"
    args = ["simulate", str(PARTS / "kidney.csv"), "--jaw", "wheel:5", "--start", "66", "--reactive", "--seed", "2"]
    assert main([*args, "--noise", "paper", "--max-rotation", "30", "--out", str(trace_file)]) in (0, 2)
    out = tmp_path / "w.mcap"
    assert main(["export", str(trace_file), "--mcap", str(out)]) == 0
    topics, _, meta = read_back(out)
    with np.load(trace_file) as data:
        length, turn, true_arc = data["length"], data["turn"], data["true_arc"]
    assert length.size > 20
    assert [m["arc"] for _, m in topics[TOPICS["wrist"]]] == pytest.approx(list(length))
    assert [m["turn"] for _, m in topics[TOPICS["arm"]]] == pytest.approx(list(turn))
    assert [m["true_arc"] for _, m in topics[TOPICS["truth"]]] == pytest.approx(list(true_arc))
    assert json.loads(meta["rolltouch"]["jaw"]) == "wheel:5"


def test_a_malformed_run_log_is_refused_naming_the_event_and_field(tmp_path, capsys):
    log_file = tmp_path / "bad.jsonl"
    log = RunLog(log_file, {"part": "cam"})
    log({"event": "reading", "roll": 0, "step": 0, "dv1": "high", "dv2": 0.5})
    log.close()
    assert main(["export", str(log_file), "--mcap", str(tmp_path / "o.mcap")]) == 2
    assert "event 2 (reading) has dv1='high', not a number" in capsys.readouterr().err
