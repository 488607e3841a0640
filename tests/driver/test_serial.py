"""The serial rig against the emulator over real I/O: equality with SimRig, faults, fuzzing."""

import contextlib
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import serial
from hypothesis import given, settings
from hypothesis import strategies as st

from driver.jaw import run_from_here
from driver.link import (
    ARM_COMMANDS,
    MAX_LINE,
    Emulator,
    Faults,
    LineReader,
    SerialRig,
    Workspace,
    encode_reply,
    encode_request,
    parse_reply,
    parse_request,
)
from driver.records import RunLog, Trace
from driver.rig import ProtocolError, RigError
from localizer import load_part
from sim2d import SimRig

ROOT = Path(__file__).resolve().parents[2]
PART = load_part(ROOT / "parts" / "trefoil.json")
ROLLS = [math.radians(20), math.radians(15)]
START = 120.0


def sim(seed=3, noise="paper"):
    rig = SimRig(PART, noise=noise, seed=seed)
    rig.move(*rig.approach_pose(START, jaw_position=0.0, standoff=1.0))
    return rig


def emulator(faults=Faults(), seed=3, noise="paper"):
    rig = SimRig(PART, noise=noise, seed=seed)
    return Emulator(rig, start_pose=rig.approach_pose(START, jaw_position=0.0, standoff=1.0), faults=faults)


@pytest.fixture(scope="module")
def direct():
    run, cal = run_from_here(sim(), PART, ROLLS)
    return run


@pytest.mark.parametrize("transport", ["tcp", "pty"])
def test_same_seed_same_localization_over_real_io(direct, transport):
    emu = emulator()
    arm, daq = emu.serve_tcp(0) if transport == "tcp" else emu.serve_pty()
    try:
        with SerialRig(arm, daq) as rig:
            run, _ = run_from_here(rig, PART, ROLLS)
    finally:
        emu.close()
    assert np.allclose(run.estimates, direct.estimates, rtol=0, atol=1e-9)
    assert run.estimate_arc == pytest.approx(direct.estimate_arc, abs=1e-9)


def run_with_log(tmp_path, faults, timeout=0.5, retries=2, **kw):
    emu = emulator(faults)
    arm, daq = emu.serve_tcp(0)
    log = RunLog(tmp_path / "run.jsonl", {"part": {"name": PART.name}})
    t0 = time.monotonic()
    try:
        with SerialRig(arm, daq, timeout=timeout, retries=retries, log=log) as rig:
            run_from_here(rig, PART, ROLLS, observer=log, **kw)
        outcome = None
    except RigError as exc:
        outcome = exc
    finally:
        log.close()
        elapsed = time.monotonic() - t0
    hand = emu.rig.world.hand
    force = emu.rig.world.contact().force
    emu.close()
    events = [json.loads(line) for line in (tmp_path / "run.jsonl").read_text().splitlines()]
    return outcome, events, elapsed, hand, force


def test_garbled_lines_are_retried(tmp_path):
    outcome, events, _, _, _ = run_with_log(tmp_path, Faults(garble=0.02), retries=3)
    assert outcome is None
    assert any(e["event"] == "retry" and "garbled" in e["problem"] for e in events)


def test_always_garbled_stops_with_a_clear_error(tmp_path):
    outcome, events, elapsed, _, _ = run_with_log(tmp_path, Faults(garble=1.0))
    assert isinstance(outcome, RigError)
    assert "did not answer STATUS after 3 tries" in str(outcome) and "garbled" in str(outcome)
    assert elapsed < 30  # stopped, not hung: a few timeouts of 0.2-0.5 s, room for a loaded machine


def test_dropped_replies_time_out_and_stop(tmp_path):
    outcome, events, elapsed, _, _ = run_with_log(tmp_path, Faults(drop=1.0), timeout=0.2)
    assert isinstance(outcome, RigError) and "no reply within 0.2 s" in str(outcome)
    assert elapsed < 30  # stopped, not hung: a few timeouts of 0.2-0.5 s, room for a loaded machine


def test_slow_device(tmp_path):
    outcome, _, elapsed, _, _ = run_with_log(tmp_path, Faults(delay=0.5), timeout=0.2, retries=1)
    assert isinstance(outcome, RigError) and "no reply" in str(outcome)
    assert elapsed < 30  # stopped, not hung


def test_disconnect_mid_roll_leaves_a_readable_log(tmp_path):
    outcome, events, elapsed, _, _ = run_with_log(tmp_path, Faults(disconnect_after=200))
    assert isinstance(outcome, RigError)
    assert "connection failed" in str(outcome) or "no reply" in str(outcome)
    readings = [e for e in events if e["event"] == "reading"]
    samples = [e for e in events if e["event"] == "sample"]
    assert readings and samples  # everything read before the fault is there
    trace = Trace.from_log(tmp_path / "run.jsonl")
    assert len(trace.columns["dv1"]) <= len(readings)
    assert elapsed < 30  # stopped, not hung


def test_saturated_sensor_stops_and_backs_off(tmp_path):
    outcome, events, _, hand, force = run_with_log(tmp_path, Faults(saturate=0.3))
    assert isinstance(outcome, RigError) and "saturated" in str(outcome)
    assert force == 0.0  # the jaw is off the part
    assert any(e["event"] == "safe_stop" for e in events)


def test_ctrl_c_backs_off_the_jaw(tmp_path):
    emu = emulator()
    arm, daq = emu.serve_tcp(0)

    def interrupt(event):
        if event.get("event") == "reading" and event["step"] == 10:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt), SerialRig(arm, daq) as rig:
        run_from_here(rig, PART, ROLLS, observer=interrupt)
    assert emu.rig.world.contact().force == 0.0
    emu.close()


def test_workspace_and_unreachable_device():
    emu = emulator()
    arm, daq = emu.serve_tcp(0)
    with (
        SerialRig(arm, daq, workspace=Workspace(x=(-10.0, 10.0))) as rig,
        pytest.raises(RigError, match=r"x=50.0 is outside the workspace \[-10.0, 10.0\]"),
    ):
        rig.move(50.0, 0.0, 0.0)
    emu.close()
    with pytest.raises(RigError, match="cannot open the arm"):
        SerialRig("socket://127.0.0.1:1", "socket://127.0.0.1:1", timeout=0.2)


def test_device_errors_are_reported():
    emu = emulator()
    reply = emu.handle("arm", b"7 FLY 1 2 3")
    assert parse_reply(reply[0]).status == "ERR" and "unknown command 'FLY'" in parse_reply(reply[0]).error
    reply = emu.handle("daq", b"8 READ 0")
    assert "BADARG" in parse_reply(reply[0]).error
    emu.close()


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=300))
def test_reply_parser_only_raises_rig_error(data):
    with contextlib.suppress(RigError):
        parse_reply(data)


def looped(data=b""):
    """A pyserial ``loop://`` port holding ``data``: what is written to it is read back."""
    port = serial.serial_for_url("loop://", timeout=0)
    port.write(data)
    return port


def test_lines_that_came_together_are_read_one_at_a_time():
    lines = LineReader(looped(b"1 OK 0.5 0.25\n2 DATA 7\n3 OK"))
    soon = time.monotonic() + 5.0  # each of these is in the port already: none waits
    assert lines.readline(soon) == b"1 OK 0.5 0.25\n"
    assert lines.readline(soon) == b"2 DATA 7\n"
    lines.port.write(b" 1\n")  # the rest of the third line comes later
    assert lines.readline(soon) == b"3 OK 1\n"


def test_a_line_cut_by_its_deadline_is_returned_as_it_came_and_not_kept():
    lines = LineReader(looped(b"4 OK 0."))
    past = time.monotonic() - 1.0  # what the port holds is read even so; nothing is waited for
    assert lines.readline(past) == b"4 OK 0."  # no newline: the reply timed out
    lines.port.write(b"5 OK\n")
    assert lines.readline(past) == b"5 OK\n"  # the cut line's bytes are gone
    assert lines.readline(past) == b""


@settings(max_examples=40, deadline=None)
@given(st.lists(st.sampled_from([b"\n", b"7 OK 1.5", b"x" * (MAX_LINE - 3), b"y" * (MAX_LINE + 40), b"z"]), max_size=8))
def test_lines_as_pyserials_read_until_gives_them(parts):
    # pyserial's own reader of a line of at most MAX_LINE + 1 bytes is the reference, on the same bytes: the
    # lines, and too-long lines cut at MAX_LINE + 1 and the rest read on (all in the port: none waits)
    data = b"".join(parts) + b"\n"
    ref, mine = looped(data), LineReader(looped(data))
    ref.timeout = 60.0
    want, got = [], []
    while sum(map(len, want)) < len(data) and (not want or want[-1]):
        want.append(ref.read_until(b"\n", MAX_LINE + 1))
    while sum(map(len, got)) < len(data) and (not got or got[-1]):
        got.append(mine.readline(time.monotonic() + 60.0))
    assert got == want


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 65535), st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64), max_size=4))
def test_replies_round_trip(seq, values):
    r = parse_reply(encode_reply(seq, "OK", *values))
    assert r.seq == seq and r.numbers(len(values)) == tuple(values)


@pytest.mark.parametrize(
    "line, code, seq",
    [
        (b"7 FLY 1 2 3", "BADCMD", 7),
        (b"9 MOVE 1 2", "BADARG", 9),
        (b"4 MOVE 1 x 3", "BADARG", 4),
        (b"4 MOVE 1 nan 3", "BADARG", 4),
        (b"MOVE 1 2 3", "BADCMD", 0),
        (b"\xff\xfe", "BADCMD", 0),
    ],
)
def test_bad_requests_carry_their_code_and_sequence(line, code, seq):
    with pytest.raises(ProtocolError) as info:
        parse_request(line, ARM_COMMANDS)
    assert (info.value.code, info.value.seq) == (code, seq)
    reply = parse_reply(emulator().handle("arm", line)[0])
    assert (reply.status, reply.seq, reply.fields[0]) == ("ERR", seq, code)


def test_the_serial_rig_is_a_rig_without_the_simulators_extras():
    from driver.rig import Clocked, GroundTruth, Pose, Rig, SampleLog

    emu = emulator()
    arm, daq = emu.serve_tcp(0)
    try:
        with SerialRig(arm, daq) as rig:
            assert isinstance(rig, Rig)
            assert not any(isinstance(rig, p) for p in (Clocked, GroundTruth, SampleLog))
            assert isinstance(rig.pose(), Pose)
    finally:
        emu.close()


def test_a_closed_rig_does_not_wait_out_pyserials_grace_but_a_rig_reopening_its_port_does(monkeypatch):
    """pyserial sleeps 0.3 s after closing a socket:// port, room for the server to take the next
    connection (here the sleep lasts until the test ends it): the rig's close returns once its ports are
    shut; a rig opening the same URL waits for the grace to end."""
    import threading
    from types import SimpleNamespace

    import serial.urlhandler.protocol_socket as protocol_socket

    grace = threading.Event()
    asleep = threading.Semaphore(0)

    def sleep(seconds):
        asleep.release()
        grace.wait()

    monkeypatch.setattr(protocol_socket, "time", SimpleNamespace(sleep=sleep))
    emu = emulator()
    arm, daq = emu.serve_tcp(0)
    try:
        rig = SerialRig(arm, daq)
        ports = list(rig.ports.values())
        closing = threading.Thread(target=rig.close, daemon=True)
        closing.start()
        closing.join(30)
        assert not closing.is_alive()  # returned while pyserial sleeps
        assert not any(port.is_open for port in ports) and not grace.is_set()
        reopened = []
        opener = threading.Thread(target=lambda: reopened.append(SerialRig(arm, daq)), daemon=True)
        opener.start()
        opener.join(0.5)
        assert opener.is_alive() and not reopened  # waiting for the grace, however long it takes
        assert asleep.acquire(timeout=30) and asleep.acquire(timeout=30)  # both ports in it
        grace.set()
        opener.join(30)
        assert reopened and reopened[0].pose() is not None
        reopened[0].close()
    finally:
        grace.set()
        emu.close()


def test_requests_round_trip():
    seq, cmd, args = parse_request(encode_request(12, "MOVE", 1.5, -2.25, 30.0), ARM_COMMANDS)
    assert (seq, cmd, args) == (12, "MOVE", [1.5, -2.25, 30.0])


def test_cli_emulate_and_run(tmp_path):
    port = 47000 + os.getpid() % 1000
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    exe = [sys.executable, "-m", "driver.cli"]
    emu = subprocess.Popen(
        exe + ["emulate", str(ROOT / "parts" / "trefoil.json"), "--tcp", str(port), "--start", "120", "--seed", "3"],
        stdout=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        assert emu.stdout.readline().startswith("arm socket://127.0.0.1:")
        emu.stdout.readline()
        out = subprocess.run(
            exe
            + [
                "run",
                str(ROOT / "parts" / "trefoil.json"),
                "--arm",
                f"socket://127.0.0.1:{port}",
                "--daq",
                f"socket://127.0.0.1:{port + 1}",
                "--json",
                "--log",
                str(tmp_path / "r.jsonl"),
            ],
            capture_output=True,
            text=True,
            timeout=120,
            env=env,
        )
    finally:
        emu.terminate()
        emu.wait(10)
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    assert "estimate_arc" in doc and "candidates" in doc
    loc = subprocess.run(
        exe + ["locate", str(tmp_path / "r.jsonl"), "--part", str(ROOT / "parts" / "trefoil.json"), "--json"],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
    )
    assert loc.returncode == 0 and json.loads(loc.stdout)["estimate_arc"] == pytest.approx(doc["estimate_arc"])


def test_cli_emulate_run_reactively_and_locate_its_log(tmp_path, capsys):
    # the log of 'run --reactive' holds the filter's calls: locate has the run's belief again from it.
    # What is checked is the log, not the processes: the emulator 'emulate PART --tcp PORT --start 120
    # --seed 3' serves is served here, and both commands run in this process (test_cli_emulate_and_run runs
    # each as a command line of its own)
    from driver.cli import main

    trefoil = str(ROOT / "parts" / "trefoil.json")
    rig = SimRig(PART, noise="paper", seed=3)
    emu = Emulator(rig, start_pose=rig.approach_pose(START, jaw_position=0.0, standoff=1.0), seed=3)
    arm, daq = emu.serve_tcp(0)
    try:
        capsys.readouterr()
        args = ["run", trefoil, "--arm", arm, "--daq", daq, "--reactive", "--max-rotation", "30"]
        rc = main([*args, "--json", "--log", str(tmp_path / "r.jsonl")])
        out = capsys.readouterr()
    finally:
        emu.close()
    assert rc in (0, 2), out.err
    doc = json.loads(out.out)
    loc_rc = main(["locate", str(tmp_path / "r.jsonl"), "--part", trefoil, "--json"])
    loc = capsys.readouterr()
    again = json.loads(loc.out)
    assert loc_rc == rc, loc.err
    assert again["estimate_arc"] == doc["estimate_arc"] and again["mass"] == doc["mass"]


def test_cli_run_fails_with_one_line_on_disconnect(tmp_path):
    # the command line's stderr is what is checked, so 'run' is a process of its own; the emulator is the
    # one 'emulate PART --tcp PORT --start 120 --fault disconnect-after=50' serves (seed 0), served here
    rig = SimRig(PART, noise="paper", seed=0)
    emu = Emulator(
        rig, start_pose=rig.approach_pose(START, jaw_position=0.0, standoff=1.0), faults=Faults(disconnect_after=50)
    )
    arm, daq = emu.serve_tcp(0)
    try:
        out = subprocess.run(
            [sys.executable, "-m", "driver.cli", "run", str(ROOT / "parts" / "trefoil.json")]
            + ["--arm", arm, "--daq", daq, "--timeout", "0.5"],
            capture_output=True,
            text=True,
            timeout=60,
        )
    finally:
        emu.close()
    assert out.returncode != 0
    last = [line for line in out.stderr.splitlines() if line.startswith("rolltouch:")]
    assert len(last) == 1 and "error" in last[0]


def test_overload_stops_before_the_wrist_is_overloaded(tmp_path):
    emu = emulator()
    arm, daq = emu.serve_tcp(0)
    try:
        with pytest.raises(RigError, match="above the overload limit 0.3 V"), SerialRig(arm, daq, overload=0.3) as rig:
            run_from_here(rig, PART, ROLLS)
        assert emu.rig.world.contact().force == 0.0
    finally:
        emu.close()


def test_cli_calibrate_over_the_emulator(tmp_path, capsys):
    from driver.cli import main
    from driver.jaw import Calibration

    emu = emulator(noise="none")
    arm, daq = emu.serve_tcp(0)
    try:
        assert main(["calibrate", "--arm", arm, "--daq", daq, "--out", str(tmp_path / "cal.json")]) == 0
    finally:
        emu.close()
    cal = Calibration.load(tmp_path / "cal.json")
    assert np.allclose(cal.ratios, [-d / (32 * 25.0) for d in cal.positions], atol=2e-4)
    assert "calibration written" in capsys.readouterr().out
