"""The arm's force servo with and without the passivity guard, on the simulated and the serial rig."""

import json
from pathlib import Path

import pytest

from driver.jaw import PressSettings, ServoSettings, establish_contact, hold_force
from driver.link import Emulator, SerialRig
from driver.rig import RigError
from localizer import load_part
from sim2d import SimError, SimRig

ROOT = Path(__file__).resolve().parents[2]
PART = load_part(ROOT / "parts" / "trefoil.json")


def pressed_rig(seed=1, noise="paper"):
    rig = SimRig(PART, noise=noise, seed=seed)
    establish_contact(rig, rig.approach_pose(120.0, jaw_position=0.0, standoff=1.0))
    return rig


def test_guarded_servo_holds_the_paper_target_where_the_bare_one_loses_the_part():
    bare = pressed_rig().servo(0.4, 20.0, guard=False, duration=0.4, seed=5)
    guarded_rig = pressed_rig()
    guarded = guarded_rig.servo(0.4, 20.0, guard=True, duration=0.4, seed=5)
    assert bare["contact_lost"] > 20
    assert guarded["contact_lost"] == 0
    assert guarded["dv1"] == pytest.approx(0.4, abs=0.01) and guarded["dv1_std"] < 0.05
    # the hand is left where the servo held it: a plain read agrees
    assert guarded_rig.truth()["force"] * 0.4 == pytest.approx(guarded["dv1"], abs=0.03)


def test_hold_force_refuses_a_ringing_or_contact_losing_loop():
    with pytest.raises(RigError, match="lost the part .* gain 20 \\(guard off\\)"):
        hold_force(pressed_rig(), gain=20.0, guard=False, duration=0.3)
    report = hold_force(pressed_rig(), gain=20.0, guard=True, duration=0.3, max_std=0.05)
    assert report["guard"] is True


def test_servo_needs_contact():
    rig = SimRig(PART, seed=0)
    rig.move(*rig.approach_pose(120.0, standoff=3.0))
    with pytest.raises(SimError, match="not touching"):
        rig.servo(0.4, 2.0)


def test_hold_force_on_a_rig_without_a_servo():
    class Bare:
        def move(self, x, y, phi): ...
        def pose(self):
            return (0.0, 0.0, 0.0)

        def read(self, n=32):
            return (0.0, 0.0)

    with pytest.raises(RigError, match="Bare has no force servo"):
        hold_force(Bare())


def test_the_serial_servo_gives_the_simulated_result():
    direct = pressed_rig().servo(0.4, 20.0, guard=True, duration=0.3, seed=9)
    rig = pressed_rig()
    original = rig.servo
    rig.servo = lambda *a, **k: original(*a, **dict(k, seed=9))  # the same sensor noise as `direct`
    emu = Emulator(rig)
    arm, daq = emu.serve_tcp(0)
    try:
        with SerialRig(arm, daq) as serial_rig:
            over_serial = serial_rig.servo(0.4, 20.0, guard=True, duration=0.3)
            bare = serial_rig.servo(0.4, 20.0, guard=False, duration=0.3)
    finally:
        emu.close()
    for key in ("dv1", "dv1_std", "min_energy"):
        assert over_serial[key] == pytest.approx(direct[key], rel=1e-6, abs=1e-9)
    assert over_serial["contact_lost"] == 0 and bare["contact_lost"] > 20


def test_serial_servo_rejects_bad_arguments():
    emu = Emulator(pressed_rig())
    arm, daq = emu.serve_tcp(0)
    try:
        with SerialRig(arm, daq) as serial_rig, pytest.raises(RigError, match="refused SERVO"):
            serial_rig.servo(0.4, -1.0)
    finally:
        emu.close()


def test_simulate_with_an_aggressive_servo_needs_the_guard(tmp_path, capsys):
    from driver.cli import main

    args = [
        "simulate",
        str(ROOT / "parts" / "trefoil.json"),
        "--start",
        "120",
        "--roll",
        "20",
        "--roll",
        "15",
        "--engine",
        "kinematic",
        "--servo-gain",
        "20",
        "--out",
        str(tmp_path / "t.npz"),
        "--json",
    ]
    assert main(args + ["--no-guard"]) == 2
    err = capsys.readouterr().err
    assert "lost the part" in err or "the force servo rings" in err
    assert main(args) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["error_mm"] < 0.3


def test_a_serial_run_holds_every_press_with_the_guarded_servo(tmp_path):
    import math

    from driver.jaw import run_from_here
    from driver.records import RunLog

    rig = SimRig(PART, noise="paper", seed=3)
    emu = Emulator(rig, start_pose=rig.approach_pose(120.0, jaw_position=0.0, standoff=1.0))
    arm, daq = emu.serve_tcp(0)
    log = RunLog(tmp_path / "run.jsonl", {})
    try:
        with SerialRig(arm, daq, log=log) as serial_rig:
            run, _ = run_from_here(
                serial_rig,
                PART,
                [math.radians(10)],
                observer=log,
                pressing=PressSettings(servo=ServoSettings(gain=20.0, guard=True, duration=0.3, max_std=0.05)),
            )
    finally:
        emu.close()
        log.close()
    events = [json.loads(line) for line in (tmp_path / "run.jsonl").read_text().splitlines()]
    servos = [e for e in events if e.get("event") == "servo"]
    assert len(servos) > 50 and all(e["contact_lost"] == 0 and e["guard"] for e in servos)
    assert run.localization.best is not None
