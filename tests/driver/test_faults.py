"""Issue 18: the host under device faults, signals and implausible readings. Each test is one
measured defect: the robot is stopped and the jaw off the part, the error is one clear line, and
no reading that cannot be is taken for a localization."""

import json
import math
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

from driver.cli import main
from driver.jaw import Hand, run_from_here
from driver.link import Emulator, Faults, SerialRig
from driver.records import RunLog
from driver.rig import ImplausibleReading, ProtocolError, RigError
from localizer import load_part
from sim2d import SimRig

from ..ctrl_c import CLI

ROOT = Path(__file__).resolve().parents[2]
PART = load_part(ROOT / "parts" / "trefoil.json")
ROLLS = [math.radians(20.0), math.radians(15.0)]
START = 120.0


def emulator(faults=Faults(), seed=3):
    rig = SimRig(PART, noise="paper", seed=seed)
    return Emulator(rig, start_pose=rig.approach_pose(START, jaw_position=0.0, standoff=1.0), faults=faults)


def run_against(faults, tmp_path):
    """run_from_here over TCP against an emulator with ``faults``: (the error, the log's events, the
    contact force after, N)."""
    emu = emulator(faults)
    arm, daq = emu.serve_tcp(0)
    log = RunLog(tmp_path / "run.jsonl", {"part": {"name": PART.name}})
    try:
        with SerialRig(arm, daq, timeout=0.5, log=log) as rig:
            run_from_here(rig, PART, ROLLS, observer=log)
        outcome = None
    except RigError as exc:
        outcome = exc
    finally:
        log.close()
    force = emu.rig.world.contact().force
    emu.close()
    events = [json.loads(line) for line in (tmp_path / "run.jsonl").read_text().splitlines()]
    return outcome, events, force


def test_a_stuck_encoder_stops_the_roll_instead_of_localizing(tmp_path):
    outcome, events, force = run_against(Faults(encoder_stuck=150), tmp_path)
    assert isinstance(outcome, ImplausibleReading), outcome
    assert "encoder is stuck or misread" in str(outcome) and "backed off" in str(outcome)
    assert force == 0.0
    assert not any(e["event"] == "result" for e in events)


def test_an_angle_of_1e308_is_refused():
    class Wild:
        """A rig whose arm reports φ = 1e308° after its first pose."""

        def __init__(self):
            self.inner = SimRig(PART, noise="none", seed=1)
            self.calls = 0

        def move(self, x, y, phi):
            self.inner.move(x, y, phi)

        def pose(self):
            self.calls += 1
            x, y, phi = self.inner.pose()
            return (x, y, math.radians(1e308) if self.calls > 1 else phi)

    rig = Wild()
    hand = Hand(rig, rig.inner.approach_pose(START, jaw_position=0.0, standoff=5.0))
    hand.measured_angle()
    with pytest.raises(ImplausibleReading, match="1e\\+308"):
        hand.measured_angle()


def test_an_arm_limit_mid_roll_is_named_and_the_host_says_what_it_could_do(tmp_path):
    outcome, events, _ = run_against(Faults(limit_after=150), tmp_path)
    assert isinstance(outcome, ProtocolError) and outcome.code == "LIMIT"
    assert "connection failed" not in str(outcome) and "refused MOVE" in str(outcome)
    # the arm refuses every MOVE now: the safe stop could stop it but not back off, and says so
    assert any("jog it clear" in note for note in outcome.__notes__)
    stop = [e for e in events if e["event"] == "safe_stop"][-1]
    assert stop["stop_problem"] == "" and "LIMIT" in stop["back_off_problem"]


def test_a_dead_daq_is_named_and_the_jaw_moved_back(tmp_path):
    outcome, _, force = run_against(Faults(daq_constant=0.5), tmp_path)
    assert "DAQ or strain-gauge amplifier is not reading" in str(outcome) and "moved back 15.0 mm" in str(outcome)
    assert force == 0.0


@pytest.mark.parametrize(
    "spec, words",
    [
        ("drop=2", "probability must be in [0, 1]"),
        ("garble=-0.1", "probability must be in [0, 1]"),
        ("delay=-1", "a delay must be in [0, 60] s"),
        ("saturate=-1", "positive voltage"),
        ("disconnect-after=-3", "whole number"),
        ("encoder-stuck=-1", "whole number"),
        ("daq-constant=nan", "finite"),
        ("drift=5", "within ±1 V/s"),
        ("fly=1", "use NAME=VALUE"),
    ],
)
def test_impossible_faults_are_refused(spec, words):
    with pytest.raises(RigError) as info:
        Faults.parse([spec])
    assert words in str(info.value) and spec.split("=")[0] in str(info.value)


def test_two_hosts_cannot_drive_one_arm():
    emu = emulator()
    arm, daq = emu.serve_tcp(0)
    try:
        with SerialRig(arm, daq) as first:
            with pytest.raises(RigError, match=f"in use by rolltouch pid {os.getpid()}"):
                SerialRig(arm, daq)
            first.pose()  # the first still works
        with SerialRig(arm, daq) as again:  # released when the first closed
            again.pose()
    finally:
        emu.close()


def test_a_device_refusal_is_not_a_connection_failure():
    emu = emulator()
    arm, daq = emu.serve_tcp(0)
    try:
        with SerialRig(arm, daq) as rig, pytest.raises(ProtocolError) as info:
            rig._transact("daq", "READ", 0)
        assert "connection failed" not in str(info.value) and "refused READ" in str(info.value)
    finally:
        emu.close()


def _run_cli(args, env=None):
    return subprocess.Popen(
        [*CLI, *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1", **(env or {})),
    )


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_stop_the_arm_and_back_off(tmp_path, signum):
    emu = emulator()
    arm, daq = emu.serve_tcp(0)
    log = tmp_path / "run.jsonl"
    proc = _run_cli(["run", str(ROOT / "parts" / "trefoil.json"), "--arm", arm, "--daq", daq, "--log", str(log)])
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:  # mid-roll: some readings logged
            if log.exists() and '"event": "reading"' in log.read_text():
                break
            time.sleep(0.05)
        proc.send_signal(signum)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
        force = emu.rig.world.contact().force
        emu.close()
    assert proc.returncode == 128 + signum, err
    name = signal.Signals(signum).name
    assert f"terminated by {name}: the arm was stopped; the jaw was backed off 5 mm" in err
    events = [json.loads(line) for line in log.read_text().splitlines()]
    assert any(e["event"] == "safe_stop" for e in events)
    assert events[-1]["event"] == "error" and events[-1]["message"] == name
    assert force == 0.0


def test_ctrl_c_while_connecting_says_nothing_was_sent(tmp_path):
    # STATUS is answered after a minute, the host's deadline as long: however loaded the machine, the host is
    # still connecting when the signal comes (the test waits for the STATUS, not for time to pass)
    emu = emulator(Faults(delay=60.0))
    asked = []
    handle = emu.handle
    emu.handle = lambda device, line: asked.append(line) or handle(device, line)
    arm, daq = emu.serve_tcp(0)
    proc = _run_cli(["run", str(ROOT / "parts" / "trefoil.json"), "--arm", arm, "--daq", daq, "--timeout", "60"])
    try:
        deadline = time.monotonic() + 60
        while not asked and time.monotonic() < deadline:  # the host has sent STATUS
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
        emu.close()
    assert proc.returncode == 130, err
    assert "interrupted: no motion had been sent to the arm (it was being connected)" in err
    assert "backed off" not in err


def test_readings_that_fit_no_place_are_not_a_localization(capsys):
    """The issue's case: a second roll of 1e9° (or one turning the wrong way) on the trefoil."""
    for turn in ("1e9", "-34.4"):
        rc = main(
            ["localize", str(ROOT / "parts" / "trefoil.json"), "--length", "25", "--turn", "31.78"]
            + ["--then", "20", turn]
        )
        out = capsys.readouterr().out
        assert rc == 2 and "NO CONSISTENT CONTACT" in out and "localized" not in out
    rc = main(
        ["localize", str(ROOT / "parts" / "trefoil.json"), "--length", "25", "--turn", "31.78"]
        + ["--sd-length", "1e-300"]
    )
    assert rc == 2 and "sd_length=1e-300" in capsys.readouterr().err


BOGUS = ["--arm", "socket://127.0.0.1:1", "--daq", "socket://127.0.0.1:1"]  # never reached: refused first
TREFOIL = str(ROOT / "parts" / "trefoil.json")


@pytest.mark.parametrize(
    "argv, words",
    [
        (["run", TREFOIL, *BOGUS, "--roll", "nan"], "'nan' is not a finite number"),
        (["run", TREFOIL, *BOGUS, "--roll", "20", "--roll", "-15"], "all rolls must turn the same way"),
        (["run", TREFOIL, *BOGUS, "--roll", "720"], "at most 180°"),
        (["run", TREFOIL, *BOGUS, "--step", "1e-7"], "must be between 0.01° and 5°"),
        (["run", TREFOIL, *BOGUS, "--reactive", "--confidence", "2"], "between 0 and 1"),
        (["run", TREFOIL, *BOGUS, "--reactive", "--max-rotation", "10000"], "at most 720°"),
        (["run", TREFOIL, *BOGUS, "--reactive", "--max-rotation", "720", "--step", "0.01"], "more than 20000"),
        (["run", TREFOIL, *BOGUS, "--plot", "/nonexistent/x.png"], "the folder /nonexistent does not exist"),
        (["calibrate", *BOGUS, "--out", "/nonexistent/c.json"], "the folder /nonexistent does not exist"),
        (["simulate", TREFOIL, "--start", "100", "--roll", "20", "--out", "noext"], "must end in .npz"),
        (["simulate", TREFOIL, "--start", "100", "--roll", "20", "--out", "t.npz", "--plot", "/tmp"], "end in .png"),
    ],
)
def test_arguments_are_refused_before_the_arm_moves(argv, words, capsys):
    """Each of these ran a whole calibration (89-100 arm commands) or a whole run before failing; now
    the command is refused first: the bogus device URLs are never opened."""
    with pytest.raises(SystemExit) as info:
        main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and words in err and "cannot open" not in err, err


def test_a_roll_of_too_many_steps_is_refused_by_the_procedure():
    from driver.jaw import roll

    rig = SimRig(PART, noise="none", seed=1)
    hand = Hand(rig, rig.approach_pose(START, jaw_position=0.0, standoff=5.0))
    moves_before = rig.pose()
    with pytest.raises(RigError, match="more than 20000"):
        roll(rig, hand, (0.0, 0.0), None, math.radians(20.0), step=math.radians(1e-7), offset=0.0)
    assert rig.pose() == moves_before


# ---------------------------------------------------------------- crafted files (items 7, 8, 9)
def _trace(path, **arrays):
    import numpy as np

    np.savez(path, **arrays)
    return path


def test_damaged_and_crafted_traces_are_one_clear_error(tmp_path, monkeypatch):
    import zipfile

    import numpy as np

    from driver.records import COLUMNS, Trace

    good = {name: np.zeros(3) for name in COLUMNS}
    meta = np.array(json.dumps({"format": "rolltouch-trace/1", "steps": [], "offsets": [], "calibration": {}}))
    cases = {
        "empty": b"",
        "truncated": _trace(tmp_path / "whole.npz", metadata=meta, **good).read_bytes()[:300],
        "random": os.urandom(4000),
    }
    for name, data in cases.items():
        (tmp_path / f"{name}.npz").write_bytes(data)
    paths = [tmp_path / f"{n}.npz" for n in cases] + [
        _trace(tmp_path / "no-column.npz", metadata=meta),
        _trace(tmp_path / "objects.npz", metadata=meta, **{**good, "dv1": np.array([{"a": 1}], dtype=object)}),
        _trace(tmp_path / "list-metadata.npz", metadata=np.array("[1, 2]"), **good),
    ]
    for path in paths:
        with pytest.raises(RigError) as info:
            Trace.load(path)
        text = str(info.value)
        assert str(path) in text and "pickle" not in text, text
    # a compressed bomb (here against a limit of 1 MB, so that the test writes little): refused from the
    # archive's directory, before anything is unpacked
    import driver.records.trace

    monkeypatch.setattr(driver.records.trace, "MAX_TRACE_UNPACKED", 2**20)
    bomb = tmp_path / "bomb.npz"
    with zipfile.ZipFile(bomb, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("dv1.npy", bytes(8 * 2**20))
    assert bomb.stat().st_size < 2**15
    with pytest.raises(RigError, match="unpack to 8 MB, more than the 1 MB"):
        Trace.load(bomb)


def test_bad_run_logs_are_one_clear_error(tmp_path):
    from driver.records import LOG_FORMAT, Trace

    start = json.dumps({"event": "start", "format": LOG_FORMAT, "calibration": {}})
    for name, lines in {
        "not-an-object": [start, "[1, 2, 3]", "{}"],
        "no-step": [start, json.dumps({"event": "reading", "roll": 0, "dv1": 1, "dv2": 0, "phi": 0}), "{}"],
    }.items():
        path = tmp_path / f"{name}.jsonl"
        path.write_text("\n".join(lines) + "\n")
        with pytest.raises(RigError) as info:
            Trace.load(path)
        text = str(info.value)
        assert str(path) in text and ("line 2" in text or "event 2" in text), text


def test_the_emulators_arguments_and_a_busy_port(capsys):
    for argv, words in (
        (["emulate", TREFOIL, "--tcp", "65535"], "from 1 to 65534"),
        (["emulate", TREFOIL, "--start", "nan"], "'nan' is not a finite number"),
    ):
        with pytest.raises(SystemExit):
            main(argv)
        assert words in capsys.readouterr().err
    # a start in the kidney's waist, where the jaw laid at its middle touches the part elsewhere: once a
    # calibration "not monotone ... recalibrate with more averaging"
    kidney = str(Path(TREFOIL).with_name("kidney.csv"))
    assert main(["emulate", kidney, "--start", "60"]) == 2
    assert "would touch the part elsewhere" in capsys.readouterr().err
    first = emulator()
    arm, _ = first.serve_tcp(0)
    port = int(arm.rsplit(":", 1)[1])
    try:
        with pytest.raises(RigError, match=f"cannot serve the arm on 127.0.0.1:{port}: .*in use"):
            emulator().serve_tcp(port)
    finally:
        first.close()


def test_unhelpful_open_errors_are_said_plainly():
    with pytest.raises(RigError, match="a socket URL is socket://HOST:PORT, PORT a number"):
        SerialRig("socket://h:notaport", "socket://h:1", timeout=0.2)
    with pytest.raises(RigError, match="no such device"):
        SerialRig("/dev/rolltouch-no-such-port", "/dev/rolltouch-no-such-port", timeout=0.2)


def test_swapped_devices_are_named():
    emu = emulator()
    arm, daq = emu.serve_tcp(0)
    try:
        with pytest.raises(RigError, match="swapped; swap --arm and --daq"):
            SerialRig(daq, arm, timeout=0.5)
    finally:
        emu.close()


def test_a_wild_voltage_is_printed_short():
    """A DAQ that answers 1e308 V: the error is one short line, not a 300-digit number."""
    emu = emulator()
    arm, daq = emu.serve_tcp(0)
    emu._sample = lambda n: (1e308, 0.0)
    try:
        with SerialRig(arm, daq, timeout=0.5) as rig, pytest.raises(RigError) as info:
            rig.read(8)
        assert "1e+308 V" in str(info.value) and len(str(info.value)) < 200
    finally:
        emu.close()


def test_an_os_error_that_is_not_ours_is_one_line(monkeypatch, capsys):
    """RigError is an OSError; any other (a full disk, a permission) must not slip past as a traceback."""
    import driver.cli.offline

    def refuse(args):
        raise PermissionError(13, "Permission denied", "/data/out.png")

    monkeypatch.setattr(driver.cli.offline, "localize_command", refuse)
    rc = main(["localize", TREFOIL, "--length", "25", "--turn", "31.78"])
    err = capsys.readouterr().err
    assert rc == 2 and err.strip() == "rolltouch: error: /data/out.png: Permission denied"


def test_a_second_ctrl_c_does_not_cut_the_safe_stop_short():
    """Ctrl-C during the safe stop is held off until it is done: the stop and the back-off both run,
    and what is said afterwards is what happened."""
    emu = emulator()
    arm, daq = emu.serve_tcp(0)
    try:
        rig = SerialRig(arm, daq, timeout=0.5)
        rig.move(*emu.rig.pose())
        stop = rig.stop

        def impatient():
            os.kill(os.getpid(), signal.SIGINT)  # the user presses Ctrl-C again, mid-stop
            time.sleep(0.05)
            stop()

        rig.stop = impatient
        outcome = rig.safe_stop()  # no KeyboardInterrupt escapes
        rig.close()
    finally:
        emu.close()
    assert outcome == "the arm was stopped; the jaw was backed off 5 mm"


def test_a_device_that_stops_answering_mid_roll_is_not_a_bridge(tmp_path):
    """The soak run found it: a READ that failed its three tries mid-roll was reported as the roll
    having "bridged a concave stretch". It is the DAQ that did not answer, and it says so."""
    from driver.rig import TransportError

    emu = emulator()
    handle, count = emu.handle, {"daq": 0}

    def deaf_after_a_while(device, line):
        if device == "daq":
            count["daq"] += 1
            if count["daq"] > 200:  # mid-roll: the calibration and the first steps are done
                return []
        return handle(device, line)

    emu.handle = deaf_after_a_while
    arm, daq = emu.serve_tcp(0)
    try:
        with SerialRig(arm, daq, timeout=0.2) as rig, pytest.raises(TransportError) as info:
            run_from_here(rig, PART, ROLLS)
    finally:
        emu.close()
    assert "daq did not answer READ" in str(info.value) and "bridged" not in str(info.value)
