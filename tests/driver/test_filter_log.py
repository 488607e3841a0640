"""A reactive rolling's trace holds its filter's calls: 'locate' has the run's belief again from them."""

import json
from pathlib import Path

import numpy as np
import pytest

from driver.cli import main
from driver.records import CALLS, LOG_COLUMNS, REACTIVE_FORMAT, LoggedFilter, replay_log
from localizer import ContactFilter, load_part

ROOT = Path(__file__).resolve().parents[2]
PARTS = ROOT / "parts"


@pytest.fixture(scope="module")
def burr_run(tmp_path_factory):
    """'simulate --reactive' on the kidney with a burr near the start (the fit test and its quarantine
    rebuild the filter from its calls: the log must hold the outer calls only)."""
    out = tmp_path_factory.mktemp("reactive") / "r.npz"
    args = ["simulate", str(PARTS / "kidney.csv"), "--start", "100", "--reactive", "--engine", "kinematic"]
    args += ["--world", str(PARTS / "burr.toml"), "--out", str(out), "--json"]
    return out, args


def test_locate_has_the_runs_belief_again(burr_run, capsys):
    out, args = burr_run
    main(args)
    ran = json.loads(capsys.readouterr().out)
    meta = json.loads(str(np.load(out)["metadata"]))
    assert meta["format"] == REACTIVE_FORMAT
    rc = main(["locate", str(out), "--part", str(PARTS / "kidney.csv"), "--json"])
    again = json.loads(capsys.readouterr().out)
    assert again["estimate_arc"] == ran["estimate_arc"] and again["mass"] == ran["mass"]
    assert again["mismatch"] == ran["mismatch"] and again["error_mm"] == pytest.approx(ran["error_mm"], abs=1e-12)
    assert rc == (2 if ran["mismatch"] else 0)
    # another part is refused, not scored
    assert main(["locate", str(out), "--part", str(PARTS / "trefoil.json")]) == 2
    assert "was made on part 'kidney'" in capsys.readouterr().err
    # a plot it cannot draw is said, not silently left out
    with pytest.raises(SystemExit):
        main(["locate", str(out), "--part", str(PARTS / "kidney.csv"), "--plot", str(out.with_suffix(".png"))])
    assert "a reactive trace's plot is drawn by the run itself" in capsys.readouterr().err


def test_the_log_keeps_outer_calls_in_order_and_replays_exactly():
    part = load_part(PARTS / "trefoil.json")
    flt = LoggedFilter(part)
    flt.touch(-30.0)
    rng = np.random.default_rng(5)
    z = 0.0
    for k in range(1, 61):
        turn = np.radians(0.2 * k)
        z += 0.2 * np.radians(0.2) * 30 + rng.normal(0, 0.03)
        flt.update(z, turn, -30.0 + z)
        if k % 10 == 0:
            flt.belief()
    flt.regrasp(z + 1.0, np.radians(12.0), -20.0)  # calls update itself: one row, not two
    flt.bridged(np.radians(12.2), -20.0, 3.0)
    end = flt.belief(0.5)
    log = flt.columns()
    assert set(log) == set(LOG_COLUMNS)
    names = [CALLS[c] for c in log["call"]]
    assert names[0] == "touch" and names.count("update") == 60 and names.count("regrasp") == 1
    assert names[-2:] == ["bridged", "belief"] and log["value"][-1] == 0.5
    again = replay_log(ContactFilter(part), log)
    assert again.map_arc == end.map_arc and again.mass == end.mass
