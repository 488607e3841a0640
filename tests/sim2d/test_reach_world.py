"""The localizer's reach against the simulated world: where the rigid jaw really touches."""

from pathlib import Path

import numpy as np
import pytest

from localizer import Reach, load_part
from sim2d import SimRig

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("name", ["parts/trefoil.json", "parts/kidney.csv", "bench/parts/tuning/star-04.json"])
def test_the_jaw_touches_where_the_sure_interval_says_and_never_outside_the_generous_one(name):
    # Lay the jaw along the model's tangent at arc s with the contact at d on it, pressed 0.01 mm in:
    # the kinematic world finds the deepest point under the jaw. Inside the sure interval that is s;
    # outside the generous one it is somewhere else.
    part = load_part(ROOT / name)
    reach = Reach(part)
    rig = SimRig(part)
    rng = np.random.default_rng(5)
    counts = {"sure": 0, "blocked": 0}
    for _ in range(250):
        s, d = rng.uniform(0, part.perimeter), rng.uniform(-48, 48)
        rig.move(*rig.approach_pose(s, jaw_position=d, standoff=-0.01))
        arc = rig.truth()["contact_arc"]
        here = np.isfinite(arc) and abs(part.arc_offset(arc, s)) < 0.5
        if reach.clear(s, d):
            assert here, (s, d, arc)
            counts["sure"] += 1
        elif not reach.touchable(s, jaw=d):
            assert not here, (s, d, arc)
            counts["blocked"] += 1
    assert counts["sure"] > 40 and (counts["blocked"] > 10 or name.endswith("kidney.csv"))
