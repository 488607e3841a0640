"""The kinematic wheel world and rig (issue 17) against the rolling kinematics' closed forms (docs/wheel.md)."""

import math

import numpy as np
import pytest

from localizer import WheelJaw, load_part, part_from_points
from sim2d import SimError, WheelRig
from sim2d.wheel_world import WheelWorld

KIDNEY = "parts/kidney.csv"


def circle(radius: float, n: int = 96):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return part_from_points(np.c_[radius * np.cos(a), radius * np.sin(a)], name="circle")


def seated_roll(part, radius: float, arcs, depth: float = 0.5, slip: float = 0.0):
    """Command the axle at ``depth`` into the offset of the model at each of ``arcs`` (mm); the world's
    disc angle and contacts at each."""
    world = WheelWorld(part, part, radius, slip=slip)
    psi, contact = [], []
    for s in arcs:
        p = np.asarray(part.point_at_arc(s % part.perimeter))
        th = float(part.tangent_angle_at_arc(s % part.perimeter))
        c = p + (radius - depth) * np.array([math.sin(th), -math.cos(th)])
        world.set_hand(c[0], c[1], th)
        psi.append(world.psi)
        contact.append(world.contact())
    return np.array(psi), contact


def test_a_disc_rolled_once_round_a_coin_of_its_size_turns_twice():
    part = circle(10.0)
    arcs = np.linspace(0.0, part.perimeter, 2000)
    psi, contact = seated_roll(part, 10.0, arcs)
    assert psi[-1] - psi[0] == pytest.approx(4 * math.pi, rel=2e-3)
    assert all(c.force == pytest.approx(0.5, abs=1e-3) for c in contact)


def test_the_disc_turns_by_the_tangent_turning_plus_the_arc_over_its_radius_through_concave_stretches():
    part = load_part(KIDNEY)
    sigma = np.linspace(0, part.perimeter, 4000, endpoint=False)
    concave = sigma[part.curvature_at_arc(sigma) < 0]
    runs = np.split(concave, np.flatnonzero(np.diff(concave) > 1.0) + 1)
    longest = max(runs, key=np.ptp)  # the kidney's waist, 40 mm
    arcs = np.linspace(longest[0] + 2.0, longest[-1] - 2.0, 400)
    for slip in (0.0, 0.1):
        psi, contact = seated_roll(part, 5.0, arcs, slip=slip)
        true = np.array([c.arc for c in contact])
        travelled = float(part.arc_offset(true[-1], true[0]))
        theta = part.tangent_angle(part.param_at_arc(np.array([true[0], true[-1]])))
        turn = float(theta[1] - theta[0])
        assert turn < -0.05  # the roll crosses the concave stretch: θ falls
        assert psi[-1] - psi[0] == pytest.approx(turn + (1 - slip) * travelled / 5.0, abs=2e-3)


def test_a_disc_wider_than_a_pocket_rests_on_both_walls_and_never_cuts_in():
    part = load_part("bench/parts/tuning/star-04.json")
    world = WheelWorld(part, part, 5.0)
    rng = np.random.default_rng(4)
    dense = np.asarray(part.point_at_arc(np.linspace(0, part.perimeter, 20000, endpoint=False)))
    for s in rng.uniform(0, part.perimeter, 40):
        p = np.asarray(part.point_at_arc(s))
        th = float(part.tangent_angle_at_arc(s))
        c = p + 4.0 * np.array([math.sin(th), -math.cos(th)])  # 1 mm into the disc's offset
        _, _, centre, depth = world._seat(c)
        assert depth > 0
        assert np.hypot(*(dense - centre).T).min() >= 5.0 - 2e-3


def test_the_wrist_reads_the_force_direction_relative_to_the_hand():
    part = load_part(KIDNEY)
    rig = WheelRig(part, WheelJaw(5.0), noise="none")
    s = 30.0
    x, y, phi = rig.approach_pose(s, standoff=-0.5)  # 0.5 mm pressed
    for tilt in (0.0, math.radians(5.0), math.radians(-3.0)):
        rig.move(x, y, phi + tilt)
        v1, v2 = rig.read(8)
        assert math.atan2(v2, v1) == pytest.approx(-tilt, abs=1e-4)
        assert math.hypot(v1, v2) == pytest.approx(0.5 * 0.4, rel=1e-3)
    assert rig.truth()["contact_arc"] == pytest.approx(s, abs=1e-3)


def test_the_axle_encoder_is_quantized_and_a_bad_wheel_is_refused():
    part = load_part(KIDNEY)
    rig = WheelRig(part, WheelJaw(5.0), noise="paper")
    step = rig.noise.axle_encoder_step
    assert step == pytest.approx(2 * math.pi / 4096)
    x, y, phi = rig.approach_pose(10.0, standoff=-0.5)
    rig.move(x, y, phi)
    for s in (10.5, 11.0, 12.5):
        rig.move(*rig.approach_pose(s, standoff=-0.5))
        assert rig.axle() / step == pytest.approx(round(rig.axle() / step), abs=1e-9)
    with pytest.raises(SimError, match="WheelJaw"):
        WheelRig(part, "wheel:5")  # type: ignore[arg-type]
    with pytest.raises(SimError, match="slip"):
        WheelWorld(part, part, 5.0, slip=1.5)


def test_the_pymunk_disc_rolls_as_the_kinematic_one():
    """The same commanded axle path on both worlds: contacts, force directions and the encoder agree."""
    part = load_part(KIDNEY)
    wheel = WheelJaw(5.0)
    kin = WheelRig(part, wheel, noise="none")
    dyn = WheelRig(part, wheel, noise="none", engine="pymunk")
    sigma = np.linspace(0, part.perimeter, 4000, endpoint=False)
    concave = sigma[part.curvature_at_arc(sigma) < 0]
    dyn.move(*kin.approach_pose(concave[0] - 5.0, standoff=1.0))  # the arm starts clear of the part
    turned = []
    for s in np.linspace(concave[0] - 5.0, concave[0] + 15.0, 81):  # through a concave stretch
        pose = kin.approach_pose(s, standoff=-1.0)  # 1 mm pressed
        for rig in (kin, dyn):
            rig.move(*pose)
        a, b = kin.world.contact(), dyn.world.contact()
        assert b.arc == pytest.approx(a.arc, abs=0.02)
        assert b.normal == pytest.approx(a.normal, abs=2e-3)
        assert b.force == pytest.approx(a.force, rel=0.05)
        turned.append(dyn.axle() - kin.axle())
    assert turned[-1] - turned[0] == pytest.approx(0.0, abs=2e-3)  # rad, after a 20 mm roll of 4 rad
    with pytest.raises(SimError, match="slip is the kinematic"):
        WheelRig(part, wheel, engine="pymunk", slip=0.1)


def test_a_disc_turns_by_the_real_parts_arc_where_the_part_is_larger_than_its_model():
    """Round a coin of radius 10.2 mm whose model is 10 mm, a 10 mm disc turns by 2π + 2π·10.2/10 (the arc it
    rolled on the real coin over its radius), its contacts still reported in the model's arc positions. Counted
    in the model's arc it would turn by 4π: a part 2% large would read as the rim slipping 2%."""
    real, model = circle(10.2), circle(10.0)
    world = WheelWorld(real, model, 10.0)
    arcs = np.linspace(0.0, real.perimeter, 2000)
    psi, reported = [], []
    for s in arcs:
        p = np.asarray(real.point_at_arc(s % real.perimeter))
        th = float(real.tangent_angle_at_arc(s % real.perimeter))
        c = p + 9.5 * np.array([math.sin(th), -math.cos(th)])
        world.set_hand(c[0], c[1], th)
        psi.append(world.psi)
        reported.append(world.contact().arc)
    assert psi[-1] - psi[0] == pytest.approx(2 * math.pi * (1 + 10.2 / 10.0), rel=2e-3)
    assert max(reported) < model.perimeter and reported[len(arcs) // 2] == pytest.approx(model.perimeter / 2, abs=0.1)


@pytest.mark.parametrize("scale", [1.0, 1.02])
def test_on_a_drawing_the_disc_rolls_the_real_faces_arc_and_pivots_on_its_corners(scale):
    """The bracket drawing (scaled ``scale`` about its centroid, not machined), a 3 mm disc rolled from 4 mm
    before a convex corner, round it, to 4 mm after: the disc turns by the hand's turn plus the real faces' arc
    over its radius, the model's arc between the first and last contacts times ``scale``, and pivots on the
    corner. (Machined, a corner moved inwards loses 2·d·tan(jump/2) of the faces' arc to its neighbours, a
    corner moved outwards gains a round of radius d that is pivoted over, d a few µm.)"""
    from localizer import load_outline
    from sim2d import PRESETS, WorldChange, world_part

    model = load_outline("parts/bracket.dxf")
    real = world_part(model, WorldChange(scale=scale), PRESETS["none"], np.random.default_rng(3))
    corner = next(c for c in model.corners if c.angle > 0.3)
    world = WheelWorld(real, model, 3.0)
    centroid = np.mean(np.asarray(model.point_at_arc(np.linspace(0, model.perimeter, 4000, endpoint=False))), axis=0)

    def press(s: float, th: float) -> None:
        p = centroid + scale * (np.asarray(model.point_at_arc(model.wrap_arc(s))) - centroid)
        c = p + 2.8 * np.array([math.sin(th), -math.cos(th)])
        world.set_hand(c[0], c[1], th)

    before = float(model.tangent_angle_at_arc(model.wrap_arc(corner.arc - 1.0)))
    psi0, normal0, arc0 = None, math.nan, math.nan
    for s in np.linspace(corner.arc - 4.0, corner.arc - 1e-6, 400):
        press(s, float(model.tangent_angle_at_arc(model.wrap_arc(s))))
        if psi0 is None:
            psi0, normal0, arc0 = world.psi, world.contact().normal, world.contact().arc
    for th in np.linspace(before, before + corner.angle, 200):  # the pivot: the axle circles the corner
        press(corner.arc, th)
    for s in np.linspace(corner.arc + 1e-6, corner.arc + 4.0, 400):
        press(s, float(model.tangent_angle_at_arc(model.wrap_arc(s))))
    assert psi0 is not None
    turn = (world.contact().normal - normal0 - corner.angle + math.pi) % (2 * math.pi) - math.pi + corner.angle
    assert abs(turn - corner.angle) < 0.01
    travelled = float(model.arc_offset(world.contact().arc, arc0))  # the model's arc, where the contacts were
    assert travelled == pytest.approx(8.0, abs=0.05)
    assert world.psi - psi0 == pytest.approx(turn + scale * travelled / 3.0, abs=3e-4)  # rad: 1 µm of arc
