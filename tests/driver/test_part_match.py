"""A trace or a run log is scored only on the part it was made on (driver.records.part_match, locate)."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from driver import PartMismatch, check_same_part, part_record
from driver.cli import main
from localizer import load_part

PARTS = Path(__file__).resolve().parents[2] / "parts"


@pytest.fixture(scope="module")
def kidney_trace(tmp_path_factory):
    out = tmp_path_factory.mktemp("pm") / "k.npz"
    args = ["simulate", str(PARTS / "kidney.csv"), "--start", "100", "--roll", "20", "--roll", "15"]
    assert main(args + ["--noise", "none", "--engine", "kinematic", "--out", str(out)]) == 0
    return out


def test_a_trace_on_another_part_is_refused_by_name(kidney_trace, capsys):
    capsys.readouterr()
    assert main(["locate", str(kidney_trace), "--part", str(PARTS / "trefoil.json")]) == 2
    err = capsys.readouterr().err
    assert "was made on part 'kidney'" in err and "trefoil.json is another part" in err and "--same-part" in err


def test_the_same_part_under_another_name_is_accepted(kidney_trace, tmp_path, capsys):
    copy = tmp_path / "my-kidney.csv"
    shutil.copy(PARTS / "kidney.csv", copy)
    assert main(["locate", str(kidney_trace), "--part", str(copy), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["error_mm"] < 0.3


def test_same_part_overrides(kidney_trace, capsys):
    capsys.readouterr()
    assert main(["locate", str(kidney_trace), "--part", str(PARTS / "trefoil.json"), "--same-part", "--json"]) in (0, 2)
    assert "estimate_arc" in json.loads(capsys.readouterr().out)


def test_records_without_a_fingerprint_are_checked_by_perimeter():
    kidney, trefoil = load_part(PARTS / "kidney.csv"), load_part(PARTS / "trefoil.json")
    old = {k: v for k, v in part_record(kidney, "kidney.csv").items() if k != "fingerprint"}
    check_same_part(old, kidney, "kidney.csv", "trace t.npz")
    with pytest.raises(PartMismatch, match=r"perimeter 234\.470087 mm; trefoil\.json is \d+\.\d+ mm around"):
        check_same_part(old, trefoil, "trefoil.json", "trace t.npz")
    check_same_part("kidney", trefoil, "trefoil.json", "trace t.npz")  # a bare name: nothing to check against
    check_same_part(None, trefoil, "trefoil.json", "trace t.npz")


def test_every_trace_kind_records_its_part(kidney_trace, tmp_path):
    from driver.records import Trace

    mark = part_record(load_part(PARTS / "kidney.csv"), "x")["fingerprint"]
    assert Trace.load(kidney_trace).metadata["part"]["fingerprint"] == mark
    out = tmp_path / "r.npz"
    args = ["simulate", str(PARTS / "kidney.csv"), "--start", "100", "--reactive", "--max-rotation", "30"]
    assert main(args + ["--noise", "none", "--engine", "kinematic", "--out", str(out)]) in (0, 1, 2)
    meta = json.loads(str(np.load(out)["metadata"]))
    assert meta["part"]["fingerprint"] == mark and meta["part"]["name"] == "kidney"
