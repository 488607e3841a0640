import json
from pathlib import Path

import numpy as np
import pytest

from driver.cli import main
from localizer import load_part

PARTS = Path(__file__).resolve().parents[2] / "parts"


def test_localize_json_names_the_truth(capsys):
    part = load_part(PARTS / "trefoil.json")
    pos = 120.0 + np.cumsum([0.0, 25.0, 20.0])
    turns = np.degrees(np.diff(part.tangent_angle_at_arc(pos)))
    rc = main(
        [
            "localize",
            str(PARTS / "trefoil.json"),
            "--length",
            "25",
            "--turn",
            repr(float(turns[0])),
            "--then",
            "20",
            repr(float(turns[1])),
            "--json",
            "--rule",
            "paper",
        ]
    )
    assert rc == 0
    doc = json.loads(capsys.readouterr().out)
    best = doc["candidates"][doc["best"]]
    assert best["end_arc"] == pytest.approx(165.0, abs=1e-6)
    assert best["start_arc"] == pytest.approx(120.0, abs=1e-6)
    assert np.allclose(best["end_xy"], part.point_at_arc(165.0), atol=1e-6)
    for key in ("start_arc", "end_arc", "start_param", "end_param", "start_xy", "end_xy"):
        assert key in doc["segments"][0] and key in best
    assert len(doc["segments"]) >= 2 and doc["ambiguous"] is False


def test_localize_text_and_plot(tmp_path, capsys):
    png = tmp_path / "loc.png"
    rc = main(
        [
            "localize",
            str(PARTS / "cam.json"),
            "--length",
            "25",
            "--turn",
            "35.89",
            "--then",
            "20",
            "23.59",
            "--plot",
            str(png),
        ]
    )
    assert rc == 0
    out = capsys.readouterr().out
    assert "contact now at arc" in out and "feasible segment" in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000


def test_errors_exit_2_with_a_message(capsys):
    rc = main(["localize", str(PARTS / "cam.json"), "--length", "1000", "--turn", "10"])
    assert rc == 2
    assert "length=1000.0 mm must be in (0, perimeter=252.9" in capsys.readouterr().err
    rc = main(["localize", "no/such/part.json", "--length", "10", "--turn", "10"])
    assert rc == 2
    assert "cannot read part file" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["localize", str(PARTS / "cam.json"), "--length", "10", "--turn", "10", "--sd-turn", "-1"])


def test_shipped_parts_load():
    names = {p.name for p in PARTS.iterdir()}
    assert {"cam.json", "ellipse.json", "trefoil.json", "kidney.csv"} <= names
    for f in ("cam.json", "ellipse.json", "trefoil.json", "kidney.csv"):
        part = load_part(PARTS / f)
        assert part.perimeter > 0
    k = load_part(PARTS / "trefoil.json").curvature(np.linspace(0, 90, 9000))
    assert (np.diff(np.sign(k)) != 0).sum() >= 6  # several inflections


def test_the_command_line_is_built_from_its_registry(capsys):
    from importlib import metadata

    from driver.cli import COMMAND_GROUPS, ENTRY_POINT_GROUP, build_parser

    sub = build_parser()._subparsers._group_actions[0]  # test only: which commands the parser holds
    names = set(sub.choices)
    assert {"localize", "locate", "simulate", "emulate", "calibrate", "run"} <= names
    # bench's command comes through the entry-point group, not by patching driver's parser
    assert "montecarlo" in {ep.name for ep in metadata.entry_points(group=ENTRY_POINT_GROUP)}
    assert "montecarlo" in names
    assert all(name.startswith("driver.cli.") for name in COMMAND_GROUPS)
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0 and capsys.readouterr().out.startswith("rolltouch ")


def test_flags_that_do_not_go_together_are_argparse_errors(capsys):
    with pytest.raises(SystemExit) as info:
        main(["simulate", "parts/cam.json", "--start", "10", "--out", "x.npz", "--noise", "none"])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert "usage: rolltouch simulate" in err and "give the rolls" in err
    with pytest.raises(SystemExit) as info:
        main(["simulate", "parts/cam.json", "--start", "10", "--out", "x.npz", "--reactive", "--confidence", "1.5"])
    assert info.value.code == 2 and "must be between 0 and 1" in capsys.readouterr().err
