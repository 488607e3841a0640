"""rolltouch show: how a reactive rolling's belief narrowed, replayed from its trace."""

import shutil
from pathlib import Path

import numpy as np
import pytest

from driver.cli import main
from driver.records import CALLS, LOG_COLUMNS, read_archive, replay_beliefs, replay_log
from localizer import ContactFilter, load_part

PARTS = Path(__file__).resolve().parents[2] / "parts"


@pytest.fixture(scope="module")
def reactive_trace(tmp_path_factory):
    out = tmp_path_factory.mktemp("show") / "r.npz"
    args = ["simulate", str(PARTS / "trefoil.json"), "--start", "120", "--reactive", "--noise", "paper", "--seed", "3"]
    assert main([*args, "--engine", "kinematic", "--out", str(out)]) == 0
    return out


def test_the_history_is_the_replayed_belief_at_every_check(reactive_trace):
    part = load_part(PARTS / "trefoil.json")
    _, columns = read_archive(reactive_trace, LOG_COLUMNS)
    readings = read_archive(reactive_trace, ("arcs", "turns", "true_arcs"))[1]
    truth = readings["true_arcs"]
    history = replay_beliefs(ContactFilter(part), columns, readings)
    final = replay_log(ContactFilter(part), columns)
    checks = int(np.count_nonzero(columns["call"] == CALLS.index("belief")))
    assert history.rotation.size == history.stated.size == history.mass.shape[0] == checks > 10
    assert history.final.mass == pytest.approx(final.mass) and history.final.map_arc == pytest.approx(final.map_arc)
    assert history.stated[-1] == pytest.approx(final.mass)
    assert np.allclose(history.mass.sum(axis=1), 1.0)
    assert np.all(np.diff(history.rotation) >= 0) and history.rotation[-1] > 0
    # each check's most probable contact lies where the histogram holds mass, and the truth is the trace's
    bins = np.clip(np.searchsorted(history.edges, history.map_arc) - 1, 0, history.mass.shape[1] - 1)
    near = np.maximum.reduce(
        [history.mass[np.arange(checks), np.clip(bins + d, 0, history.mass.shape[1] - 1)] for d in (-1, 0, 1)]
    )
    assert np.all(near > 0)
    assert history.true_arc[-1] == pytest.approx(truth[-1])
    assert set(history.true_arc[np.isfinite(history.true_arc)]) <= set(truth)


def test_show_draws_the_picture(reactive_trace, tmp_path, capsys):
    out = tmp_path / "b.png"
    assert main(["show", str(reactive_trace), "--part", str(PARTS / "trefoil.json"), "--out", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "checks over" in capsys.readouterr().out


def test_what_show_cannot_draw_is_refused_by_name(reactive_trace, tmp_path, capsys):
    out = str(tmp_path / "b.png")
    assert main(["show", str(reactive_trace), "--part", str(PARTS / "cam.json"), "--out", out]) == 2
    assert "cam" in capsys.readouterr().err  # made on the trefoil
    other = tmp_path / "x.npz"
    np.savez(other, metadata=np.array('{"format": "something-else/1"}'))
    assert main(["show", str(other), "--part", str(PARTS / "trefoil.json"), "--out", out]) == 2
    assert "not a rolltouch trace of this kind (something-else/1)" in capsys.readouterr().err
    assert (
        main(["show", str(reactive_trace), "--part", str(PARTS / "trefoil.json"), "--out", out, "--jaw", "wheel:5"])
        == 2
    )
    assert "of the straight:100 finger, not of --jaw wheel:5" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["show", str(reactive_trace), "--part", str(PARTS / "trefoil.json"), "--out", str(tmp_path / "b.jpg")])
    assert "must end in .png" in capsys.readouterr().err


def test_the_animation_has_a_frame_a_reading_up_to_its_bound(reactive_trace, tmp_path, capsys, monkeypatch):
    """The bound lowered to 24 frames (the film draws ~0.2 s a frame; the rolling has hundreds of readings,
    so the bound is what decides), and the bound's own sampling at its real value below."""
    from PIL import Image

    from driver.records import belief_film

    bound = 24
    monkeypatch.setattr(belief_film, "MAX_FRAMES", bound)
    out = tmp_path / "b.gif"
    assert (
        main(["show", str(reactive_trace), "--part", str(PARTS / "trefoil.json"), "--out", str(out), "--fps", "5"]) == 0
    )
    _, columns = read_archive(reactive_trace, LOG_COLUMNS)
    readings = int(np.count_nonzero(np.isin(columns["call"], [CALLS.index("update"), CALLS.index("regrasp")])))
    assert readings > bound
    with Image.open(out) as gif:
        assert gif.n_frames == bound
        assert gif.info["duration"] == 200  # ms a frame at 5 frames per second
    assert f"{bound} frames" in capsys.readouterr().out


@pytest.mark.parametrize("readings", [1, 20, 160, 161, 997])
def test_a_film_draws_every_reading_up_to_its_bound_and_the_last_always(readings):
    from driver.records.belief_film import MAX_FRAMES, _frames

    drawn = _frames(readings)
    assert drawn.size == min(readings, MAX_FRAMES)
    assert drawn[0] == 0 and drawn[-1] == readings - 1 and np.all(np.diff(drawn) > 0)
    if readings > MAX_FRAMES:
        gaps = np.diff(drawn)
        assert gaps.max() - gaps.min() <= 1  # evenly spread


def test_an_animation_that_cannot_be_written_is_refused_by_name(reactive_trace, tmp_path, capsys):
    args = ["show", str(reactive_trace), "--part", str(PARTS / "trefoil.json")]
    with pytest.raises(SystemExit):
        main([*args, "--out", str(tmp_path / "b.gif"), "--fps", "0"])
    assert "--fps 0 must be from 1 to 60" in capsys.readouterr().err
    if shutil.which("ffmpeg") is None:
        assert main([*args, "--out", str(tmp_path / "b.mp4")]) == 2
        assert "needs ffmpeg" in capsys.readouterr().err


def test_a_wheel_rolling_is_shown_and_animated(tmp_path, capsys, monkeypatch):
    from PIL import Image

    from driver.records import WheelTrace, belief_film, replay_wheel_beliefs
    from localizer import WheelFilter

    trace_file = tmp_path / "w.npz"
    args = ["simulate", str(PARTS / "kidney.csv"), "--jaw", "wheel:5", "--start", "66", "--reactive", "--seed", "2"]
    # a short rolling (15°, about 75 readings)
    assert main([*args, "--noise", "paper", "--max-rotation", "15", "--out", str(trace_file)]) in (0, 2)
    part = load_part(PARTS / "kidney.csv")
    trace = WheelTrace.load(trace_file)
    history = replay_wheel_beliefs(WheelFilter(part, trace.wheel), trace.columns)
    final = trace.relocalize(part)  # what 'locate' says: the same readings, asked once
    assert history.final.mass == pytest.approx(final.mass) and history.final.map_arc == pytest.approx(final.map_arc)
    assert history.readings.shape[0] == trace.columns["length"].size
    assert history.true_arc[-1] == pytest.approx(trace.columns["true_arc"][-1])
    monkeypatch.setattr(belief_film, "MAX_FRAMES", 20)  # the wheel drawn on 20 frames, not 75 (~0.15 s each)
    for name in ("w.png", "w.gif"):
        out = tmp_path / name
        assert main(["show", str(trace_file), "--part", str(PARTS / "kidney.csv"), "--out", str(out)]) == 0
    with Image.open(tmp_path / "w.gif") as gif:
        assert gif.n_frames == min(trace.columns["length"].size, 20) == 20


def test_fixed_rolls_are_shown_as_the_reactive_filter_takes_them(tmp_path):
    from driver.records import Trace, sequence_calls

    trace_file = tmp_path / "f.npz"
    args = ["simulate", str(PARTS / "trefoil.json"), "--start", "120", "--roll", "20", "--roll", "15"]
    assert main([*args, "--noise", "paper", "--engine", "kinematic", "--out", str(trace_file)]) == 0
    part = load_part(PARTS / "trefoil.json")
    seq = Trace.load(trace_file).step_sequence()
    assert seq["z"].size == seq["truth"].size == round(35 / 0.2) + 1
    # the filter fed the readings by hand: the history's last belief is its belief
    flt = ContactFilter(part)
    flt.touch(float(seq["jaw"][0]))
    for j in range(1, seq["z"].size):
        flt.update(float(seq["z"][j]), float(seq["turn"][j]), float(seq["jaw"][j]))
    readings = {"arcs": seq["z"], "turns": seq["turn"], "true_arcs": seq["truth"]}
    history = replay_beliefs(ContactFilter(part), sequence_calls(seq), readings)
    assert history.rotation.size == 35  # a check every fifth reading
    assert history.final.map_arc == pytest.approx(flt.belief().map_arc, abs=0.05)
    assert history.true_arc[-1] == pytest.approx(seq["truth"][-1])
    out = tmp_path / "f.png"
    assert main(["show", str(trace_file), "--part", str(PARTS / "trefoil.json"), "--out", str(out)]) == 0


@pytest.mark.parametrize("arc", [10.0, 66.0, 150.0])
def test_the_finger_is_drawn_touching_the_part_where_the_contact_is(arc):
    from driver.records import finger_outline

    part = load_part(PARTS / "kidney.csv")
    p = part.point_at_arc(arc)
    angle = float(part.tangent_angle_at_arc(arc))
    e = np.array([np.cos(angle), np.sin(angle)])
    a, b = finger_outline(
        part, arc, -12.0
    )  # the straight jaw: 100 mm along the tangent, the contact 12 mm before its middle
    assert np.linalg.norm(b - a) == pytest.approx(100.0)
    assert (b - a)[0] * e[1] - (b - a)[1] * e[0] == pytest.approx(0.0, abs=1e-9)  # along the tangent
    assert np.dot(p - 0.5 * (a + b), e) == pytest.approx(-12.0)
    assert (p - a)[0] * e[1] - (p - a)[1] * e[0] == pytest.approx(0.0, abs=1e-9)  # through the contact
    disc = finger_outline(part, arc, float("nan"), wheel_radius=5.0)
    hub = disc[:-1].mean(axis=0)  # the outline closes on its first point
    assert np.allclose(np.linalg.norm(disc - hub, axis=1), 5.0, atol=0.05)
    assert np.linalg.norm(p - hub) == pytest.approx(5.0, abs=0.05)
    # outside: no point of the part is nearer the hub than the disc's radius
    ring = part.point_at_arc(np.linspace(0.0, part.perimeter, 2000, endpoint=False))
    assert np.min(np.linalg.norm(ring - hub, axis=1)) > 5.0 - 0.05
