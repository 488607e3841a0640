import math
from pathlib import Path

import numpy as np
import pytest

from localizer import load_part
from sim2d import SimError
from sim2d.quasistatic import QuasiStaticWorld
from sim2d.rig import SimRig

PARTS = str(Path(__file__).resolve().parents[2] / "parts") + "/"


def tangent_pose(part, arc, jaw_position, press):
    t = part.param_at_arc(arc)
    c, phi = part.point(t), float(part.tangent_angle(t))
    e, m = np.array([math.cos(phi), math.sin(phi)]), np.array([-math.sin(phi), math.cos(phi)])
    d = c - jaw_position * e + press * m
    return float(d[0]), float(d[1]), phi


def test_contact_force_location_and_truth():
    part = load_part(PARTS + "cam.json")
    world = QuasiStaticWorld(part, stiffness=2.0)
    world.set_hand(*tangent_pose(part, 40.0, -20.0, 0.3))
    c = world.contact()
    assert c.force == pytest.approx(0.6, rel=1e-6)
    assert c.jaw_position == pytest.approx(-20.0, abs=0.02)
    assert part.arc_at_param(c.param) == pytest.approx(40.0, abs=0.02)
    world.set_hand(*tangent_pose(part, 40.0, -20.0, -0.5))
    assert world.contact().force == 0.0


def test_straight_jaw_bridges_a_concavity():
    """On a concave stretch the deepest point jumps across: the jaw touches the convex hull."""
    part = load_part(PARTS + "trefoil.json")
    t = np.linspace(0, part.n_knots, 9000, endpoint=False)
    k = part.curvature(t)
    concave = float(part.arc_at_param(t[np.argmin(k)]))
    world = QuasiStaticWorld(part)
    # a jaw pressed at the deepest concave point touches elsewhere, on the hull
    world.set_hand(*tangent_pose(part, concave, 0.0, 0.2))
    c = world.contact()
    arc = float(part.arc_at_param(c.param))
    assert abs(part.arc_offset(arc, concave)) > 3.0
    assert part.curvature(c.param) > 0


def test_simrig_is_deterministic_and_logs_truth():
    part = load_part(PARTS + "cam.json")
    runs = []
    for _ in range(2):
        rig = SimRig(part, noise="paper", seed=7)
        rig.move(*rig.approach_pose(50.0, standoff=-0.4))
        runs.append((rig.read(16), rig.pose(), rig.samples[-1]["contact_arc"]))
    assert runs[0] == runs[1]
    assert runs[0][2] == pytest.approx(50.0, abs=0.5)


def test_simrig_rejects_bad_input():
    part = load_part(PARTS + "cam.json")
    with pytest.raises(SimError, match="unknown engine 'box2d'"):
        SimRig(part, engine="box2d")
    rig = SimRig(part)
    with pytest.raises(SimError, match="must be finite"):
        rig.move(0.0, float("nan"), 0.0)
