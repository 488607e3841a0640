"""The pipeline on the simulated rig: calibration, rolling fidelity (paper §III-C), localization."""

import math
from pathlib import Path

import numpy as np
import pytest

from driver.jaw import (
    Calibration,
    Hand,
    calibrate,
    delta_voltages,
    establish_contact,
    localize_by_rolling,
    press,
    roll,
)
from driver.rig import Rig, RigError
from localizer import load_part
from sim2d import NoiseModel, SimRig

PARTS = Path(__file__).resolve().parents[2] / "parts"


def part_named(name):
    return load_part(PARTS / name)


def calibration_for(part, noise="none", seed=0):
    """Calibrate on the most curved point the whole jaw reaches (a well-defined contact)."""
    rig = SimRig(part, noise=noise, seed=seed)
    return calibrate(rig, rig.calibration_pose())


@pytest.fixture(scope="module")
def cam():
    return part_named("cam.json")


@pytest.fixture(scope="module")
def cam_cal(cam):
    return calibration_for(cam)


def test_simrig_satisfies_rig(cam):
    assert isinstance(SimRig(cam), Rig)


@pytest.mark.parametrize("noise, rms_limit, max_limit", [("none", 0.02, 0.05), ("paper", 0.4, 0.8)])
def test_calibration_recovers_contact_location(cam, noise, rms_limit, max_limit):
    cal = calibration_for(cam, noise)
    rig = SimRig(cam, noise=noise, seed=5)
    errs = []
    for d in np.linspace(-45, 45, 13):
        hand, base, _ = establish_contact(rig, rig.approach_pose(120.0, jaw_position=d, standoff=1.0))
        dv1, dv2 = delta_voltages(rig, base, 32)
        errs.append(cal.position(dv2 / dv1) - rig.truth()["jaw_position"])
    errs = np.array(errs)
    assert np.sqrt(np.mean(errs**2)) < rms_limit and np.abs(errs).max() < max_limit


def roll_errors(part, cal, step_deg, starts, noise="none", offset=None):
    out = []
    for start in starts:
        rig = SimRig(part, noise=noise, seed=2)
        hand, base, _ = establish_contact(rig, rig.approach_pose(start, jaw_position=-40, standoff=1.0))
        a0 = rig.truth()["contact_arc"]
        r = roll(rig, hand, base, cal, math.radians(40), step=math.radians(step_deg), offset=offset)
        true_len = (rig.truth()["contact_arc"] - a0) % part.perimeter
        true_turn = float(part.tangent_angle_at_arc(a0 + true_len) - part.tangent_angle_at_arc(a0))
        out.append((r.length - true_len, r.turn - true_turn, r))
    return out


def test_the_pymunk_world_rolls_as_the_kinematic_one(cam):
    """A 40° roll, noise-free, in the pymunk world and the kinematic one from the same start: the same L
    within 0.5 µm and the same turn. The pymunk world settles until the jaw is still (not a fixed count),
    its solver correcting overlap within steps: 0.02-0.06 µm apart; before, 1.7-2.2 µm."""
    positions = tuple(float(d) for d in range(-50, 51, 10))
    cal = Calibration(positions, tuple(-d / (32 * 25.0) for d in positions))  # the wrist's exact ratio line
    for start in (15.0, 150.0):
        got = []
        for engine in ("kinematic", "pymunk"):
            rig = SimRig(cam, noise="none", engine=engine)
            hand, base, _ = establish_contact(rig, rig.approach_pose(start, jaw_position=-40.0, standoff=1.0))
            got.append(roll(rig, hand, base, cal, math.radians(40.0), step=math.radians(0.2)))
        assert got[1].length == pytest.approx(got[0].length, abs=0.5e-3)
        assert got[1].turn == got[0].turn


def test_contact_travel_error_shrinks_linearly_with_the_step(cam, cam_cal):
    """Paper §III-C: |A'B'| = s + O(s²) per step, so over a roll the paper's estimate is off by O(θ);
    our second-order inversion is off by O(θ²)."""
    starts = [20.0, 160.0]
    paper, ours = {}, {}
    for deg in (0.8, 0.4, 0.2):
        res = roll_errors(cam, cam_cal, deg, starts)
        paper[deg] = np.mean([abs(err - r.length + r.jaw_travel + r.offset * abs(r.turn)) for err, _, r in res])
        ours[deg] = np.mean([abs(err) for err, _, _ in res])
    for big, small in ((0.8, 0.4), (0.4, 0.2)):
        assert paper[big] / paper[small] == pytest.approx(2.0, abs=0.25)
        assert ours[big] / ours[small] == pytest.approx(4.0, abs=1.0)
    assert paper[0.2] < 0.05 and ours[0.2] < 0.001


def test_turn_matches_to_the_encoder_quantization(cam, cam_cal):
    step = math.radians(0.03)
    for noise in ("none", NoiseModel(encoder_step=step)):
        for _, dturn, _ in roll_errors(cam, cam_cal, 0.2, [60.0], noise=noise):
            assert abs(dturn) <= (step if noise != "none" else 1e-12)


def test_tool_axis_offset_correction(cam, cam_cal):
    """Without the edge-offset term, L is short by the wrist's give times the turn."""
    ((with_err, _, r),) = roll_errors(cam, cam_cal, 0.2, [90.0])
    ((without_err, _, _),) = roll_errors(cam, cam_cal, 0.2, [90.0], offset=0.0)
    assert r.offset == pytest.approx(1.0, rel=0.02)  # 1 N at 1 N/mm
    assert without_err == pytest.approx(with_err - r.offset * abs(r.turn), abs=0.01)
    assert abs(with_err) < 0.05


def localize_from(part, cal, start, noise="none", seed=3, rolls=(30.0, 25.0)):
    rig = SimRig(part, noise=noise, seed=seed)
    run = localize_by_rolling(
        rig,
        part,
        [math.radians(a) for a in rolls],
        calibration=cal,
        approach_pose=rig.approach_pose(start, jaw_position=-40, standoff=1.0),
    )
    truth = rig.truth()["contact_arc"]
    return run, truth, abs(float(part.arc_offset(run.estimate_arc, truth)))


@pytest.mark.parametrize("start", [10.0, 95.0, 180.0])
def test_two_noise_free_rolls_localize_within_0p3_mm(cam, cam_cal, start):
    run, truth, err = localize_from(cam, cam_cal, start)
    assert err < 0.3
    assert run.samples and all("contact_arc" in s for s in run.samples)


def test_non_convex_part_convex_stretch_localizes():
    part = part_named("trefoil.json")
    cal = calibration_for(part)
    run, truth, err = localize_from(part, cal, 120.0, rolls=(20.0, 15.0))
    assert err < 0.3


def test_rolls_that_bridge_a_concavity_are_refused():
    part = part_named("trefoil.json")
    cal = calibration_for(part)
    t = np.linspace(0, part.n_knots, 9000, endpoint=False)
    concave = float(part.arc_at_param(t[np.argmin(part.curvature(t))]))
    with pytest.raises(RigError, match="bridged a concave stretch"):
        localize_from(part, cal, concave - 15.0, rolls=(40.0,))


def test_symmetric_part_reports_ambiguity():
    part = part_named("ellipse.json")
    cal = calibration_for(part)
    run, truth, err = localize_from(part, cal, 30.0)
    top = run.localization.candidates[:2]
    assert run.localization.ambiguous
    assert min(abs(float(part.arc_offset(c.end_arc, truth))) for c in top) < 0.3


def test_press_without_contact_raises(cam):
    rig = SimRig(cam)
    hand = Hand(rig, rig.approach_pose(50.0, standoff=30.0))
    with pytest.raises(RigError, match="no contact after pressing 15.0 mm"):
        press(rig, hand, (0.0, 0.0))


def test_calibration_checks_and_file_roundtrip(tmp_path, cam_cal):
    with pytest.raises(RigError, match="not monotone"):
        Calibration((-50, -25, 0, 25, 50), (0.06, 0.03, 0.04, -0.03, -0.06))
    with pytest.raises(RigError, match="at least|>= 4"):
        Calibration((0.0, 1.0), (0.0, 1.0))
    with pytest.raises(RigError, match="outside the calibrated range"):
        cam_cal.position(0.5)
    f = tmp_path / "cal.json"
    cam_cal.save(f)
    assert Calibration.load(f) == cam_cal
    f.write_text("{")
    with pytest.raises(RigError, match="calibration file"):
        Calibration.load(f)
    for other in ("[1, 2, 3]", '"positions"', "42", "null"):
        f.write_text(other)  # JSON, but not a calibration's object: one clear line, not an AttributeError
        with pytest.raises(RigError, match="not a calibration's object"):
            Calibration.load(f)


def test_rolls_must_turn_one_way(cam, cam_cal):
    rig = SimRig(cam)
    with pytest.raises(RigError, match="must all turn the same way"):
        localize_by_rolling(rig, cam, [0.2, -0.2], calibration=cam_cal, approach_pose=rig.approach_pose(10.0))


def test_a_simulated_rig_has_every_optional_capability():
    from driver.rig import Clocked, ForceServo, GroundTruth, SampleLog

    sim = SimRig(load_part(PARTS / "cam.json"), noise="none", seed=0)
    assert all(isinstance(sim, p) for p in (Rig, ForceServo, Clocked, GroundTruth, SampleLog))


def test_fixed_rolls_on_a_drawing_cross_its_faces_and_refuse_its_notch():
    # the bracket: a 10 mm fillet at 203.1 mm turns onto a 30 mm face at 270°, which ends at a
    # convex corner; the top edge is two collinear faces at 180° with a 20 mm notch between them
    from localizer import load_outline

    bracket = load_outline(Path(__file__).resolve().parents[2] / "parts" / "bracket.dxf")
    cal = calibration_for(bracket)
    rig = SimRig(bracket, noise="none", seed=3)
    # from the fillet, the second roll tips the jaw over the face and pivots on the corner
    run = localize_by_rolling(
        rig,
        bracket,
        [math.radians(20.0), math.radians(60.0)],
        calibration=cal,
        approach_pose=rig.approach_pose(210.0, jaw_position=-40.0, standoff=1.0),
        sd_length=0.05,  # noise-free readings: the 8 mm fillets' rolls differ by 0.7 mm
    )
    truth = run.rolls[-1].truth[-1].contact_arc
    assert run.rolls[1].largest_jump > 25.0  # the face was crossed in one step
    # the rest of the fillet, the face, then the corner (no arc)
    rest = 10.0 * (1.5 * math.pi - (math.pi + (210.0 - 203.13274) / 10.0 + math.radians(20.0)))
    assert run.estimates[1][0] == pytest.approx(rest + 30.0, abs=0.5)
    # the most probable place is right (a roll that might end flush on that face, from a start 29° back
    # on the fillet, fits too: any L is a place on the face; the rule gives it a third)
    assert abs(float(bracket.arc_offset(run.estimate_arc, truth))) < 0.3
    # from the second fillet, tipping over the top edge jumps both faces and the notch: a bridge
    rig = SimRig(bracket, noise="none", seed=3)
    with pytest.raises(RigError, match="bridged a concave stretch"):
        localize_by_rolling(
            rig,
            bracket,
            [math.radians(60.0)],
            calibration=cal,
            approach_pose=rig.approach_pose(115.0, jaw_position=-40.0, standoff=1.0),
        )
