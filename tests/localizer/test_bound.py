"""The Cramér–Rao bound of one roll, against the spread of the exact solver's answers to noisy rolls."""

from pathlib import Path

import numpy as np
import pytest

from localizer import QueryError, feasible_segments, load_part, roll_bound

PARTS = Path(__file__).resolve().parents[2] / "parts"


@pytest.mark.parametrize("start, length", [(115.0, 12.0), (85.0, 8.0)])
def test_the_solvers_answers_to_noisy_rolls_spread_as_the_bound_says(start, length):
    # small noise: the solution of two readings in two unknowns is efficient, so its spread over
    # 600 noisy rolls is the bound (sampling error of a standard deviation ~3%; 12% allowed)
    cam = load_part(PARTS / "cam.json")
    sd_l, sd_o = 0.01, 2e-4
    raw = float(cam.tangent_angle_at_arc(start + length) - cam.tangent_angle_at_arc(start))
    turn = (raw + np.pi) % (2 * np.pi) - np.pi  # a short roll turns by less than half a turn
    rng = np.random.default_rng(7)
    starts, ends = [], []
    for _ in range(600):
        segs = feasible_segments(cam, length + rng.normal(0, sd_l), turn + rng.normal(0, sd_o))
        near = min(segs, key=lambda g: abs(cam.arc_offset(g.start_arc, start)))
        starts.append(float(cam.arc_offset(near.start_arc, start)))
        ends.append(float(cam.arc_offset(near.end_arc, start + length)))
    for got, at in ((starts, "start"), (ends, "end")):
        bound = float(roll_bound(cam, start, length, sd_length=sd_l, sd_turn=sd_o, at=at))
        assert np.isfinite(bound) and np.std(got) == pytest.approx(bound, rel=0.12), (at, np.std(got), bound)


def test_bad_queries_are_refused_by_name():
    cam = load_part(PARTS / "cam.json")
    for kwargs, says in (
        ({"length": -1.0, "sd_length": 0.1, "sd_turn": 0.1}, "length"),
        ({"length": 5.0, "sd_length": float("nan"), "sd_turn": 0.1}, "sd_length"),
        ({"length": 5.0, "sd_length": 0.1, "sd_turn": 0.1, "at": "middle"}, "middle"),
    ):
        with pytest.raises(QueryError, match=says):
            roll_bound(cam, 10.0, **kwargs)
