"""rolltouch simulate / locate, and the trace format."""

import json
from pathlib import Path

import numpy as np
import pytest

from driver.cli import main
from driver.records import COLUMNS, Trace
from driver.rig import RigError
from localizer import CircularArc, load_part

PARTS = Path(__file__).resolve().parents[2] / "parts"


@pytest.fixture(scope="module")
def trace_file(tmp_path_factory):
    out = tmp_path_factory.mktemp("sim") / "t.npz"
    rc = main(
        [
            "simulate",
            str(PARTS / "trefoil.json"),
            "--start",
            "120",
            "--roll",
            "20",
            "--roll",
            "15",
            "--noise",
            "none",
            "--engine",
            "kinematic",
            "--out",
            str(out),
        ]
    )
    assert rc == 0
    return out


def test_simulate_then_locate_json_contract(trace_file, capsys):
    capsys.readouterr()
    rc = main(["locate", str(trace_file), "--part", str(PARTS / "trefoil.json"), "--json"])
    assert rc == 0
    doc = json.loads(capsys.readouterr().out)
    for key in ("estimate_arc", "candidates", "true_arc", "error_mm"):
        assert key in doc
    assert doc["error_mm"] < 0.3
    assert abs(doc["true_arc"] - doc["estimate_arc"]) < 0.3 or doc["error_mm"] < 0.3


def test_trace_roundtrip_and_recomputed_estimates(trace_file):
    tr = Trace.load(trace_file)
    assert set(COLUMNS) <= set(tr.columns)
    assert tr.metadata["start_arc"] == 120.0 and tr.metadata["engine"] == "kinematic"
    assert tr.true_start_arc == pytest.approx(120.0, abs=0.05)
    # locate recomputes exactly what the run estimated
    assert np.allclose(tr.estimates(), tr.metadata["estimates"], atol=1e-9)
    raw = np.load(trace_file, allow_pickle=False)  # no pickles anywhere
    assert "metadata" in raw.files


def test_simulate_json_and_plot(tmp_path, capsys):
    out, png = tmp_path / "t.npz", tmp_path / "t.png"
    rc = main(
        [
            "simulate",
            str(PARTS / "cam.json"),
            "--start",
            "60",
            "--roll",
            "25",
            "--roll",
            "20",
            "--noise",
            "paper",
            "--engine",
            "kinematic",
            "--seed",
            "3",
            "--out",
            str(out),
            "--plot",
            str(png),
            "--json",
        ]
    )
    assert rc == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["trace"] == str(out) and "error_mm" in doc
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_simulate_errors(tmp_path, capsys):
    rc = main(
        [
            "simulate",
            str(PARTS / "cam.json"),
            "--start",
            "9999",
            "--roll",
            "20",
            "--noise",
            "none",
            "--engine",
            "kinematic",
            "--out",
            str(tmp_path / "x.npz"),
        ]
    )
    assert rc == 2 and "--start 9999.0 mm must be in" in capsys.readouterr().err
    rc = main(
        [
            "simulate",
            str(PARTS / "cam.json"),
            "--start",
            "10",
            "--roll",
            "20",
            "--noise",
            "lab",
            "--engine",
            "kinematic",
            "--out",
            str(tmp_path / "x.npz"),
        ]
    )
    assert rc == 2 and "use a preset" in capsys.readouterr().err
    # a start in a concavity: refused before anything moves (the jaw's reach)
    from localizer import load_part

    part = load_part(PARTS / "trefoil.json")
    t = np.linspace(0, part.n_knots, 9000, endpoint=False)
    concave = float(part.arc_at_param(t[np.argmin(part.curvature(t))]))
    rc = main(
        [
            "simulate",
            str(PARTS / "trefoil.json"),
            "--start",
            f"{concave:.3f}",
            "--roll",
            "10",
            "--noise",
            "none",
            "--engine",
            "kinematic",
            "--out",
            str(tmp_path / "x.npz"),
        ]
    )
    err = capsys.readouterr().err
    assert rc == 2 and "no place on the jaw touches there" in err


def test_locate_bad_trace(tmp_path, capsys):
    bad = tmp_path / "bad.npz"
    np.savez(bad, x=np.zeros(3))
    rc = main(["locate", str(bad), "--part", str(PARTS / "cam.json")])
    assert rc == 2 and "not a rolltouch trace" in capsys.readouterr().err
    with pytest.raises(RigError, match="no such file"):
        Trace.load(tmp_path / "missing.npz")


START = {"event": "start", "format": "rolltouch-log/1", "calibration": {"positions": [0], "ratios": [1], "target": 1}}
ROLL = {"event": "roll", "roll": 0, "step": 0.1, "offset": 1.0}


def reading(**change):
    return {"event": "reading", "roll": 0, "step": 0, "dv1": 1.0, "dv2": 0.5, "phi": 0.0, **change}


@pytest.mark.parametrize(
    "events, jaw, match",
    [
        ([START, {**ROLL, "roll": [1]}], "straight", r"event 2 \(roll\) has roll=\[1\], not a whole number"),
        (
            [START, ROLL, reading(dv1="x"), reading(step=1)],
            "straight",
            "event 3 \\(reading\\) has dv1='x', not a number",
        ),
        ([{**START, "calibration": {"positions": [0]}}], "straight", "its calibration has no ratios, target"),
        (
            [{**START, "calibration": {"positions": "x", "ratios": [1], "target": 1}}],
            "straight",
            "positions='x' is not",
        ),
        ([{**START, "jaw": "wheel:5", "calibration": "x"}], "wheel", "its calibration is str, not a JSON object"),
        (
            [{**START, "jaw": "wheel:5"}, {"event": "reading", "length": 1.0, "turn": 0.1, "segment": "a"}],
            "wheel",
            "has segment='a', not a whole number",
        ),
    ],
)
def test_a_malformed_run_log_is_refused_naming_the_event_and_field(tmp_path, events, jaw, match):
    from driver.records import WheelTrace

    log = tmp_path / "bad.jsonl"
    log.write_text("".join(json.dumps(e) + "\n" for e in events))
    with pytest.raises(RigError, match=match):
        (WheelTrace if jaw == "wheel" else Trace).load(log)


def test_a_start_the_jaw_cannot_be_laid_on_is_refused_before_anything_moves(tmp_path, capsys):
    from localizer import load_part

    kidney = load_part(PARTS / "kidney.csv")
    s = np.arange(0, kidney.perimeter, 0.5)
    deepest = float(s[np.argmin(np.asarray(kidney.curvature_at_arc(s)))])  # inside the concavity
    rc = main(
        [
            "simulate",
            str(PARTS / "kidney.csv"),
            "--start",
            f"{deepest}",
            "--roll",
            "20",
            "--noise",
            "none",
            "--engine",
            "kinematic",
            "--out",
            str(tmp_path / "x.npz"),
        ]
    )
    assert rc == 2
    err = capsys.readouterr().err
    assert f"--start {deepest} mm" in err and "no place on the jaw touches there" in err
    assert not (tmp_path / "x.npz").exists()


def test_simulate_reactively_on_a_dxf_outline_with_its_plot(tmp_path, capsys):
    # a CAD drawing runs on the kinematic world by default (the pymunk world takes splines only)
    out, png = tmp_path / "b.npz", tmp_path / "b.png"
    rc = main(
        [
            "simulate",
            str(PARTS / "bracket.dxf"),
            "--start",
            "75",
            "--reactive",
            "--noise",
            "none",
            "--out",
            str(out),
            "--plot",
            str(png),
            "--json",
        ]
    )
    doc = json.loads(capsys.readouterr().out)
    assert rc == 0 and doc["stopped"] == "confident" and doc["error_mm"] < 0.3
    assert png.stat().st_size > 10_000 and out.exists()
    # seeking information by default: from the fillet it rolls on to the face that tells it from its mirror twin.
    # The baseline's direction rule turns round over the fillet, which reads the same as the twin's
    assert doc["policy"] == "seek" and doc["reversals"] == 0
    rc = main(
        ["simulate", str(PARTS / "bracket.dxf"), "--start", "75", "--reactive", "--noise", "none"]
        + ["--policy", "spread", "--out", str(out), "--json"]
    )
    spread = json.loads(capsys.readouterr().out)
    assert rc == 0 and spread["policy"] == "spread" and spread["reversals"] > 0
    assert spread["rotation_deg"] > doc["rotation_deg"]


def test_the_direction_rule_is_the_straight_jaws(tmp_path, capsys):
    with pytest.raises(SystemExit) as refused:
        main(
            ["simulate", str(PARTS / "kidney.csv"), "--jaw", "wheel:5", "--start", "66", "--reactive"]
            + ["--policy", "spread", "--out", str(tmp_path / "w.npz")]
        )
    assert refused.value.code == 2 and "--policy spread is the straight jaw's" in capsys.readouterr().err
    assert not (tmp_path / "w.npz").exists()


def test_the_two_roll_rule_runs_on_outlines(capsys, tmp_path):
    """Fixed rolls on a CAD outline, simulated and localized; and the offline rule on the bracket from
    the outline's own turns (a roll over a fillet, then along a face: the truth among the candidates)."""
    rc = main(
        ["simulate", str(PARTS / "profile.svg"), "--start", "140", "--roll", "20", "--roll", "15"]
        + ["--noise", "none", "--out", str(tmp_path / "p.npz"), "--json"]
    )
    doc = json.loads(capsys.readouterr().out)
    assert rc == 0 and doc["error_mm"] < 0.3
    bracket = load_part(PARTS / "bracket.dxf")
    fillet = next(i for i, p in enumerate(bracket.pieces) if isinstance(p, CircularArc))
    s0 = float(bracket.starts[fillet]) + 1.0
    pos = s0 + np.array([0.0, 6.0, 14.0])
    turns = np.degrees(np.diff(bracket.tangent_angle_at_arc(pos)))
    rc = main(
        ["localize", str(PARTS / "bracket.dxf"), "--length", "6", "--turn", repr(float(turns[0]))]
        + ["--then", "8", repr(float(turns[1])), "--sd-length", "0.02", "--json"]
    )
    doc = json.loads(capsys.readouterr().out)
    ends = [c["end_arc"] for c in doc["candidates"]]
    assert rc == 0 and min(abs(bracket.arc_offset(e, pos[-1] % bracket.perimeter)) for e in ends) < 0.5


def test_a_world_that_is_not_its_model_ends_in_a_mismatch(tmp_path, capsys):
    # issue 29: --world draws a burr near --start; the ending names where and exits 2; the JSON says it too
    world = tmp_path / "burr.toml"
    world.write_text("[world]\ndefects = 1\ndefect_height_mm = 0.3\ndefect_length_mm = 4.0\ndefect_near_mm = 5.0\n")
    out = tmp_path / "r.npz"
    args = ["simulate", str(PARTS / "kidney.csv"), "--start", "40", "--reactive", "--noise", "paper"]
    args += ["--engine", "kinematic", "--seed", "1", "--world", str(world), "--out", str(out)]
    assert main(args) == 2
    text = capsys.readouterr().out
    assert "MODEL MISMATCH" in text
    assert main([*args, "--json"]) == 2
    doc = json.loads(capsys.readouterr().out)
    assert doc["stopped"] == "mismatch" and doc["mismatch"] is not None
    assert doc["world"]["defects"][0]["height_mm"] == 0.3 and abs(doc["world"]["defects"][0]["arc"] - 40) <= 5
    meta = json.loads(str(np.load(out)["metadata"]))
    assert meta["world"]["describe"].startswith("a 0.3 mm bump")
    # the world's own part, and the two flags together refused by argparse
    with pytest.raises(SystemExit):
        main([*args, "--world-part", str(PARTS / "kidney.csv")])
    capsys.readouterr()
