import numpy as np
import pytest

from localizer import QueryError, localize, part_from_points
from tests.localizer.test_part import ellipse_points, trefoil


def chain(part, s0, lengths, sign=1.0):
    pos = s0 + sign * np.cumsum([0.0] + list(lengths))
    turns = np.diff(part.tangent_angle_at_arc(pos))
    return list(zip(lengths, turns)), part.wrap_arc(pos)


def arc_err(a, b, P):
    return abs((a - b + P / 2) % P - P / 2)


@pytest.mark.parametrize("rule", ["paper", "likelihood"])
@pytest.mark.parametrize("s0", [12.0, 120.0, 250.0])
def test_noise_free_chain_is_localized(rule, s0):
    part = trefoil()
    rolls, pos = chain(part, s0, [25.0, 20.0])
    res = localize(part, rolls, rule=rule)
    assert len(res.segments) > 1  # the first roll alone is ambiguous
    assert arc_err(res.best.end_arc, pos[-1], part.perimeter) < 1e-6
    assert arc_err(res.best.start_arc, s0, part.perimeter) < 1e-6
    assert not res.ambiguous


def test_paper_rule_keeps_ties_within_tolerance():
    part = trefoil()
    rolls, _ = chain(part, 120.0, [25.0, 20.0])
    strict = localize(part, rolls, rule="paper", turn_tol=1e-9)
    loose = localize(part, rolls, rule="paper", turn_tol=10.0)
    assert sum(c.probability > 0 for c in strict.candidates) == 1
    kept = [c for c in loose.candidates if c.probability > 0]
    assert len(kept) == len(loose.segments)
    assert sum(c.probability for c in kept) == pytest.approx(1.0)


def test_likelihood_with_noise_finds_the_truth_and_sums_to_one():
    part = trefoil()
    rng = np.random.default_rng(7)
    hits = 0
    for _ in range(6):
        s0 = rng.uniform(0, part.perimeter)
        rolls, pos = chain(part, s0, [25.0, 20.0])
        noisy = [(L + rng.normal(0, 0.1), w + rng.normal(0, 2e-4)) for L, w in rolls]
        res = localize(part, noisy, sd_length=0.1, sd_turn=2e-4)
        assert sum(c.probability for c in res.candidates) == pytest.approx(1.0)
        hits += arc_err(res.best.end_arc, pos[-1], part.perimeter) < 1.0
    assert hits >= 5


def test_symmetric_part_is_ambiguous_with_symmetric_candidates():
    part = part_from_points(ellipse_points(48, 40.0, 25.0))
    P = part.perimeter
    rolls, pos = chain(part, 20.0, [20.0, 15.0])
    res = localize(part, rolls)
    assert res.ambiguous
    top = res.candidates[:2]
    assert top[0].probability == pytest.approx(0.5, abs=0.02)
    assert top[1].probability == pytest.approx(0.5, abs=0.02)
    assert arc_err(top[0].end_arc, top[1].end_arc, P) == pytest.approx(P / 2, abs=1e-6)
    assert min(arc_err(c.end_arc, pos[-1], P) for c in top) < 1e-6


def test_clockwise_chain():
    part = trefoil()
    rolls, pos = chain(part, 200.0, [25.0, 20.0], sign=-1.0)
    res = localize(part, rolls, rule="paper", direction="cw")
    assert arc_err(res.best.end_arc, pos[-1], part.perimeter) < 1e-6


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(rolls=[]), "rolls is empty"),
        (dict(rolls=[(10.0,)]), "sequence of"),
        (dict(rolls=[(10.0, 0.1), (-2.0, 0.1)]), r"roll 2: length=-2.0 mm"),
        (dict(rolls=[(10.0, float("nan"))]), "roll 1: .* must be finite"),
        (dict(rolls=[(10.0, 0.1)], rule="best"), r"unknown rule 'best'; use one of \['likelihood', 'paper'\]"),
        (dict(rolls=[(10.0, 0.1)], sd_length=0.0), "sd_length=0.0 is below 0.0001"),
        (dict(rolls=[(10.0, 0.1)], confidence=2.0), "confidence=2.0"),
        (dict(rolls=[(10.0, 0.1)], direction="left"), "unknown direction 'left'"),
    ],
)
def test_bad_arguments(kwargs, match):
    with pytest.raises(QueryError, match=match):
        localize(trefoil(), **kwargs)
