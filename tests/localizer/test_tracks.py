"""The rolling tables (ModeTracks) across shallow concavities, against a convex hull of a dense sample."""

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from localizer import BRIDGE_EXCESS, ModeTracks, part_from_points


def hull_bridges(part, n=40_000):
    """Every stretch the convex hull of a dense sample skips: (a, b, chord angle, excess), mm and rad.

    A straight jaw longer than the chord rolls over the hull there: the reference for where the
    contact jumps, independent of the tables' bitangent search."""
    s = np.linspace(0.0, part.perimeter, n, endpoint=False)
    pts = np.asarray(part.point_at_arc(s))
    v = np.sort(ConvexHull(pts).vertices)
    gaps = np.diff(np.r_[v, v[0] + n])
    out = []
    for i in np.flatnonzero(gaps > 3):
        ia, ib = v[i], (v[i] + gaps[i]) % n
        d = pts[ib] - pts[ia]
        arc = gaps[i] * part.perimeter / n
        out.append((s[ia], s[ia] + arc, float(np.arctan2(d[1], d[0])), arc - float(np.hypot(*d))))
    return out


@pytest.mark.parametrize("push", [0.3, 1.0])
def test_the_jaw_is_carried_across_shallow_dips_and_stopped_by_deeper_ones(push):
    # a circle of radius 60 mm through 48 points, two pushed in: the spline dips between them, by
    # microns (overshoot beside the deeper push) or by more; the hull says which the jaw bridges
    a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    r = np.full(48, 60.0)
    r[10] -= push
    r[30] -= 2.0
    part = part_from_points(np.c_[r * np.cos(a), r * np.sin(a)])
    tracks = ModeTracks(part, 0.02)
    ref = hull_bridges(part)
    # nothing near the threshold, so the test does not hang on the hull's sampling
    assert not any(0.5 * BRIDGE_EXCESS < e < 2 * BRIDGE_EXCESS for *_, e in ref)
    shallow = [x for x in ref if x[3] <= BRIDGE_EXCESS]
    assert len(shallow) >= 2 and len(ref) > len(shallow)
    assert tracks.bridges == len(shallow)
    theta = np.unwrap(np.asarray(tracks.theta))
    for sa, sb, phi, excess in ref:
        start = int(tracks.node_at(sa - 2.0))
        assert tracks.convex[start]
        # the turn from the start that brings the jaw to the chord's angle, either side of it
        to_chord = (phi - theta[start] + np.pi) % (2 * np.pi) - np.pi
        before, ok_before = tracks.advance(np.array([start]), to_chord - 1e-5)
        after, ok_after = tracks.advance(np.array([start]), to_chord + 1e-5)
        assert ok_before[0] and sa - 0.1 < before[0] % part.perimeter <= sa + 0.02
        if excess <= BRIDGE_EXCESS:
            assert ok_after[0] and sb - 0.02 <= after[0] % part.perimeter < sb + 0.1
            inside = np.flatnonzero((tracks.sigma > sa + 0.05) & (tracks.sigma < sb - 0.05))
            assert inside.size and not tracks.convex[inside].any()  # no rolling starts within a bridge
        else:
            # a deeper concavity ends the stretch (the rig reports the jump as a bridge): the contact
            # is never carried across it
            assert not ok_after[0] or after[0] % part.perimeter < 0.5 * (sa + sb)


def test_a_roll_on_a_convex_part_lands_where_the_tangent_has_turned_by_it():
    """Every start of a convex cam turned by up to a lap either way: the landing is where the grid's own
    tangent angle (unwrapped over three laps) reaches the start's plus the turn, interpolated linearly
    between grid points, as numpy's interp finds it on the whole table (the reference for the step's
    search, which starts from each start's own entry)."""
    a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    cam = part_from_points(np.c_[40 * np.cos(a) + 3 * np.cos(2 * a), 30 * np.sin(a)], name="cam")
    tracks = ModeTracks(cam, 0.2)
    assert tracks.convex.all()
    n, p = tracks.sigma.size, cam.perimeter
    theta = np.unwrap(tracks.theta)
    arcs = np.concatenate([tracks.sigma - p, tracks.sigma, tracks.sigma + p])
    angles = np.concatenate([theta - 2 * np.pi, theta, theta + 2 * np.pi])
    rng = np.random.default_rng(4)
    idx = rng.integers(0, n, 5000)
    for turn in (rng.uniform(-2 * np.pi, 2 * np.pi, idx.size), 1e-3, -0.4):
        arc, node, ok = tracks.step(idx, turn)
        want = np.interp(theta[idx] + turn, angles, arcs)
        assert ok.all() and np.abs(arc - want).max() < 1e-9
        assert np.array_equal(node, tracks.node_at(arc))


@pytest.mark.parametrize("shape", ["cam", "kidney"])
def test_a_search_started_from_the_last_landings_finds_the_same_landings(shape):
    """Rolled by a growing turn with the landings kept as the next search's start, and by random turns
    from wherever the last search ended: every landing, node and verdict is the one found from each
    start's own entry (on a part with concave stretches and faces too)."""
    a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    r = 35 + (8 * np.cos(2 * a) if shape == "kidney" else 3 * np.cos(3 * a))
    part = part_from_points(np.c_[r * np.cos(a), 0.8 * r * np.sin(a)], name=shape)
    tracks = ModeTracks(part, 0.2)
    idx = np.flatnonzero(tracks.convex)
    hints = tracks.landing_hints()
    rng = np.random.default_rng(7)
    turns = np.r_[np.cumsum(np.full(120, 0.01)), rng.uniform(-np.pi, np.pi, 30)]
    for turn in turns:
        for margin in (0.0, 0.02):
            want = tracks.step(idx, float(turn), turn_margin=margin)
            got = tracks.step(idx, float(turn), turn_margin=margin, hint=hints)
            for g, w in zip(got, want):
                assert np.array_equal(g, w, equal_nan=g.dtype.kind == "f")
