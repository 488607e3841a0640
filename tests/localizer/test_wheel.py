"""The wheel finger's reach (issue 17), against closed forms and a brute-force reading of its definition."""

import math

import numpy as np
import pytest

from localizer import (
    CircularArc,
    QueryError,
    StraightJaw,
    WheelJaw,
    WheelReach,
    outline_from_pieces,
    parse_jaw,
    part_from_points,
)


def peanut(lobe=30.0, half_distance=25.0, waist=10.0):
    """Two convex lobes of radius ``lobe`` joined by concave arcs of radius ``waist`` tangent to both."""
    d, big, small = half_distance, lobe, waist
    y0 = math.sqrt((big + small) ** 2 - d**2)  # the concave arcs' centres (0, ±y0)
    a = math.atan2(y0, -d)  # from B = (d, 0) towards the upper concave centre
    b = math.atan2(-y0, d)  # from the upper concave centre towards B
    pieces = [
        CircularArc((d, 0.0), big, -a, 2 * a),  # right lobe, counter-clockwise through angle 0
        CircularArc((0.0, y0), small, b, -(2 * b + math.pi)),  # upper waist, clockwise (concave)
        CircularArc((-d, 0.0), big, math.pi - a, 2 * a),  # left lobe
        CircularArc((0.0, -y0), small, a, math.pi - 2 * a),  # lower waist, clockwise (concave)
    ]
    return outline_from_pieces(pieces), y0


def test_a_wheel_reaches_a_concave_arc_when_it_fits_and_not_when_it_does_not():
    part, y0 = peanut()
    waist = [i for i, p in enumerate(part.pieces) if p.radius == 10.0]
    assert len(waist) == 2
    for radius, fits in ((8.0, True), (12.0, False)):
        reach = WheelReach(part, WheelJaw(radius))
        for i in waist:
            # the waist's interior, 1 mm from its tangent joins
            arcs = np.linspace(part.starts[i] + 1.0, part.starts[i + 1] - 1.0, 200)
            assert reach.touchable(arcs).all() == fits and reach.touchable(arcs).any() == fits
            if fits:
                assert reach.clear(arcs).all()
                # inside the waist's circle, r short of it: 10 − r from its centre
                centre = np.array(part.pieces[i].center)
                assert np.allclose(np.hypot(*(reach.axle_at(arcs) - centre).T), 10.0 - radius, atol=1e-9)
        # the lobes are reached by both, the axle r outside them
        lobe = np.linspace(part.starts[0] + 5.0, part.starts[1] - 5.0, 100)
        assert reach.clear(lobe).all()
        assert np.allclose(np.hypot(*(reach.axle_at(lobe) - (25.0, 0.0)).T), 30.0 + radius, atol=1e-9)


def test_reach_agrees_with_the_definition_on_a_star():
    # deep lobes narrower and wider than the wheels: each grid point against its own dense sample
    a = np.linspace(0, 2 * np.pi, 70, endpoint=False)
    r = 60 * (1 + 0.35 * np.cos(5 * a) + 0.08 * np.sin(11 * a))
    star = part_from_points(np.c_[r * np.cos(a), r * np.sin(a)], name="star")
    s = np.arange(0.0, star.perimeter, 0.01)
    dense = np.asarray(star.point_at_arc(s))
    rng = np.random.default_rng(5)
    for radius in (3.0, 10.0):
        reach = WheelReach(star, WheelJaw(radius))
        assert 0.2 < reach.fraction < 1.0  # the test must see both
        assert not (reach.sure & ~reach.reached).any()
        checked = 0
        for i in rng.choice(reach.sigma.size, 300, replace=False):
            gap = np.hypot(*(dense - reach.axle[i]).T).min() - radius
            if abs(gap + reach.clearance) < 0.02:
                continue  # on the threshold: the sample's spacing decides
            assert reach.reached[i] == (gap > -reach.clearance), (radius, reach.sigma[i], gap)
            checked += 1
        assert checked > 250


def test_fingers_are_named_by_spec_strings():
    assert parse_jaw("wheel:5") == WheelJaw(5.0) and parse_jaw("straight:100") == StraightJaw(100.0)
    for finger in (WheelJaw(2.5), StraightJaw(80.0)):
        assert parse_jaw(str(finger)) == finger
    bad_specs = (("wheel:-1", "-1"), ("wheel:abc", "abc"), ("claw:3", "claw"), ("wheel", "wheel"), ("wheel:nan", "nan"))
    for bad, says in bad_specs:
        with pytest.raises(QueryError, match=says) as err:
            parse_jaw(bad)
        assert isinstance(err.value, ValueError)
