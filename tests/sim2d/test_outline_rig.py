"""The kinematic world and the reactive rolling on an outline from CAD (issue 16): pivots on convex
corners, flush contact on faces, and localization from starts on fillets, faces and corners."""

import math
from pathlib import Path

import numpy as np
import pytest

from driver.jaw import calibrate_simulated, localize_reactively
from localizer import load_outline
from sim2d import SimRig

PARTS = Path(__file__).resolve().parents[2] / "parts"


@pytest.fixture(scope="module")
def bracket():
    return load_outline(PARTS / "bracket.dxf")


@pytest.fixture(scope="module")
def calibration(bracket):
    return calibrate_simulated(bracket, noise="none", seed=99)


def contact_after(rig, pose):
    rig.world.set_hand(*pose)
    return rig.world.contact()


def test_a_convex_corner_is_a_pivot(bracket):
    # the jaw pressed on a corner at angles within its jump: the contact stays at the corner
    rig = SimRig(bracket, noise="none")
    corner = bracket.corners[0]
    arcs = []
    for fraction in (0.1, 0.3, 0.5, 0.7, 0.9):
        x, y, phi = rig.approach_pose(corner.arc, jaw_position=-10.0, standoff=-0.5, tilt=-fraction * corner.angle)
        c = contact_after(rig, (x, y, phi))
        assert c.force > 0
        arcs.append(float(bracket.arc_offset(c.param, corner.arc)))
        assert abs(c.jaw_position + 10.0) < 0.01
    assert np.max(np.abs(arcs)) < 0.01


def test_flush_on_a_face_the_wrist_reads_the_middle_of_the_face_under_the_jaw(bracket):
    # the first face runs from arc 0 to 72 mm; laid flush with arc 40 at jaw position -40, the jaw
    # covers arcs 30 to 130 of its line, so the face from 30 to 72 bears: centre of pressure at 51
    rig = SimRig(bracket, noise="none")
    c = contact_after(rig, rig.approach_pose(40.0, jaw_position=-40.0, standoff=-0.2))
    assert c.force > 0 and not c.at_edge
    assert c.param == pytest.approx(51.0, abs=0.01)
    assert c.jaw_position == pytest.approx(-29.0, abs=0.01)
    # turned a little either way, it rests on one end of that stretch
    x, y, phi = rig.approach_pose(40.0, jaw_position=-40.0, standoff=-0.2)
    for turn, end in ((1e-3, 72.0), (-1e-3, 30.0)):
        c = contact_after(rig, (x, y, phi + turn))
        assert abs(float(bracket.arc_offset(c.param, end))) < 0.5, (turn, c.param)


@pytest.mark.parametrize(
    "arc, jaw, tilt",
    [(40.0, -40.0, 0.0), (40.0, 0.0, 0.0), (75.0, 10.0, 0.0), (0.0, -10.0, 0.5), (183.13274122871834, -40.0, 0.5)],
)
def test_the_pymunk_world_agrees_with_the_kinematic_one_on_faces_fillets_and_corners(bracket, arc, jaw, tilt):
    # laid flush on the first face (arcs 0 to 72), on a fillet, pivoting on convex corners: the
    # dynamic jaw settles where the static one is, and reads the same place (flush: the middle)
    corner = [c for c in bracket.corners if abs(c.arc - arc) < 1e-9]
    turn = -tilt * corner[0].angle if corner else 0.0
    kinematic, dynamic = SimRig(bracket, noise="none"), SimRig(bracket, noise="none", engine="pymunk")
    dynamic.world.set_hand(*kinematic.approach_pose(arc, jaw_position=jaw, standoff=2.0, tilt=turn))
    for press in (0.2, 0.5):
        pose = kinematic.approach_pose(arc, jaw_position=jaw, standoff=-press, tilt=turn)
        a, b = contact_after(dynamic, pose), contact_after(kinematic, pose)
        # N, at 1 N/mm: the solver lets a corner sink into the jaw by about 0.01 mm more than a face
        assert a.force == pytest.approx(b.force, abs=0.02)
        assert a.jaw_position == pytest.approx(b.jaw_position, abs=0.01)  # mm
        assert abs(float(bracket.arc_offset(a.param, b.param))) < 0.01  # mm
        assert not a.at_edge and not b.at_edge


# (start arc mm, tilt as a fraction of the corner's jump, jaw position mm): fillets, faces, and
# convex corners at angles where the jaw, laid there, touches the corner (localizer.Reach)
STARTS = [
    (75.0, 0.0, -40.0),
    (210.0, 0.0, -40.0),
    (100.0, 0.0, -40.0),
    (230.0, 0.0, -40.0),
    (40.0, 0.0, -40.0),
    (0.0, 0.5, -40.0),
    (0.0, 0.2, -40.0),
    (183.13274122871834, 0.5, -40.0),
]


def roll_from(bracket, calibration, start, engine="kinematic"):
    """Noise-free reactive rolling from a STARTS entry: (the run, its error against the truth, mm)."""
    arc, fraction, jaw = start
    corner = [c for c in bracket.corners if abs(c.arc - arc) < 1e-9]
    tilt = -fraction * corner[0].angle if corner else 0.0
    rig = SimRig(bracket, noise="none", seed=1, engine=engine)
    res = localize_reactively(
        rig,
        bracket,
        calibration=calibration,
        approach_pose=rig.approach_pose(arc, jaw_position=jaw, standoff=1.0, tilt=tilt),
    )
    return res, abs(float(bracket.arc_offset(res.estimate_arc, rig.truth()["contact_arc"])))


def test_noise_free_reactive_localization_from_fillets_faces_and_corners(bracket, calibration):
    sure = 0
    for arc, fraction, jaw in STARTS:
        res, error = roll_from(bracket, calibration, (arc, fraction, jaw))
        if res.stopped == "confident":
            sure += 1
            assert error < 0.3, (arc, fraction, res.belief.mass, error)
        else:  # not sure: then it must not state that it is
            assert res.belief.mass < 0.95, (arc, fraction, res.stopped, res.belief.mass)
    # the three starts on convex corners pivot there until the jaw jumps both ways: readings of one spot,
    # which a burr's crest would give as well, are not enough to be sure (issue 29)
    assert sure >= 5, sure


@pytest.mark.parametrize("arc", [73.0, 78.0, 82.0])
def test_from_a_fillet_the_jaw_rolls_to_what_tells_it_from_its_twin(bracket, calibration, arc):
    # the bracket's lower right fillet and its mirror twin, the upper right one, read alike all along; what tells
    # them apart lies past either end: the face rolling on counter-clockwise crosses in one step, 24 mm against
    # the twin's 22. Seeking information the jaw rolls on to it, sure and right without turning round; the
    # spread rule of the two leading modes turned round over the fillet 14 to 69 times, and from 78 mm spent
    # its 240 degrees there
    res, error = roll_from(bracket, calibration, (arc, 0.0, -40.0))
    assert res.stopped == "confident" and error < 0.3, (res.stopped, res.belief.mass, error)
    assert res.reversals == 0 and res.rotation < math.radians(90.0), (res.reversals, math.degrees(res.rotation))


def test_noise_free_reactive_localization_in_the_pymunk_world(bracket, calibration):
    # two fillets and a face: the dynamic jaw's readings localize as the static one's do
    for start in (STARTS[2], STARTS[4], STARTS[1]):
        res, error = roll_from(bracket, calibration, start, engine="pymunk")
        assert res.stopped == "confident" and error < 0.3, (start, res.stopped, res.belief.mass, error)


def test_calibration_on_a_drawing_is_not_where_the_jaw_lies_flush_on_a_face():
    """On a drawing every point of a fillet is "most curved", and the first of them is where the fillet
    meets a face: a jaw laid along the tangent there lies flush on that face, and tapped with the
    contact near its end it touches the face as well (the calibration came out non-monotone in 6 of 7
    trials on a generated plate). Checked from the geometry: laid at the calibration point, the jaw
    clears the outline by at least 0.5 mm from 5 to 15 mm along it on both sides; and calibrating
    there works at every seed tried."""
    import math

    from driver.jaw import calibrate_simulated
    from localizer import CircularArc, Line, calibration_arc, outline_from_pieces
    from sim2d import load_noise

    def rounded(vertices, radii):
        n = len(vertices)
        pieces, ends = [], []
        for i in range(n):
            p, q, r = (np.asarray(vertices[j % n], float) for j in (i - 1, i, i + 1))
            a, b = (q - p) / np.linalg.norm(q - p), (r - q) / np.linalg.norm(r - q)
            turn = math.atan2(a[0] * b[1] - a[1] * b[0], a @ b)
            back = radii[i] * math.tan(turn / 2)
            t0, t1 = q - a * back, q + b * back
            centre = t0 + np.array([-a[1], a[0]]) * radii[i]
            start = math.atan2(*(t0 - centre)[::-1])
            ends.append((tuple(t0), tuple(t1)))
            pieces.append(CircularArc(tuple(centre), radii[i], start, turn))
        out = []
        for i in range(n):
            out.append(pieces[i])
            out.append(Line(ends[i][1], ends[(i + 1) % n][0]))
        return outline_from_pieces(out)

    # a 20° turn at (60, 0) between two long faces, then three big rounded corners
    plate = rounded([(0, 0), (60, 0), (120, 21.8), (120, 90), (0, 90)], [12, 3, 12, 12, 12])
    arc = calibration_arc(plate)
    c, phi = plate.point_at_arc(arc), float(plate.tangent_angle_at_arc(arc))
    along = np.array([math.cos(phi), math.sin(phi)])
    inward = np.array([-math.sin(phi), math.cos(phi)])
    pts = plate.sample(0.05)[:-1] - c
    u, v = pts @ along, pts @ inward
    for side in (1, -1):
        near = (side * u >= 5.0) & (side * u <= 15.0)
        assert near.any() and v[near].min() >= 0.5, (side, v[near].min())
    for seed in range(4):
        calibrate_simulated(plate, load_noise("paper"), seed=seed, engine="kinematic")


def _every_point_touch(outline, origin, phi, half_span):
    """outline_touch's rule over every point of the sample (the reference its run-by-run search must equal)."""
    from sim2d.quasistatic import EDGE, FLUSH

    e, m = np.array([np.cos(phi), np.sin(phi)]), np.array([-np.sin(phi), np.cos(phi)])
    rel = outline.xy - origin
    u, depth = rel @ e, -(rel @ m)
    inside = np.abs(u) <= half_span
    if not inside.any():
        return False, 0.0, float("nan"), 0.0, False
    k = int(np.argmax(np.where(inside, depth, -np.inf)))
    flush = inside & (depth >= depth[k] - FLUSH)
    P = outline.perimeter
    arc = float((outline.arcs[k] + ((outline.arcs[flush] - outline.arcs[k] + P / 2) % P - P / 2).mean()) % P)
    at_edge = not float(np.ptp(u[flush])) > EDGE and abs(float(u[k])) >= half_span - EDGE
    return True, float(u[flush].mean()), arc, float(depth[k]), at_edge


@pytest.mark.parametrize("name", ["bracket.dxf", "profile.svg"])
def test_the_touch_sought_run_by_run_is_the_touch_over_every_point(name):
    """On the machined sample of each shipped drawing, jaws laid at random places, along the tangent and
    tilted, pressed in and held clear, flush on faces and off the ends: the same contact, to the bit."""
    from sim2d.quasistatic import outline_touch

    rig = SimRig(load_outline(PARTS / name), noise="paper", seed=1)
    rng = np.random.default_rng(7)
    for _ in range(300):
        x, y, phi = rig.approach_pose(
            rng.uniform(0, rig.part.perimeter),
            jaw_position=rng.uniform(-60, 60),
            standoff=rng.uniform(-1.0, 0.5),
            tilt=float(rng.choice([0.0, rng.normal(0, 0.05)])),
        )
        got = outline_touch(rig.part, (x, y), phi, 50.0)
        want = _every_point_touch(rig.part, (x, y), phi, 50.0)
        assert got == want or (not got[0] and not want[0])
    assert outline_touch(rig.part, (1e4, 1e4), 0.0, 50.0)[0] is False  # nothing under a jaw far away
