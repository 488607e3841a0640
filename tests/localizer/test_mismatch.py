"""A part that is not its model (issue 29): the grid filter's quarantine, fit test and stretch envelope."""

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.special import logsumexp, softmax

from localizer import NOISE_FIT_LIMIT, ContactFilter, QueryError, load_part, part_from_points
from localizer.filters._filter_kernels import weigh_scales

PARTS = Path(__file__).resolve().parents[2] / "parts"
STEP = math.radians(0.2)


@pytest.fixture(scope="module")
def cam():
    return load_part(PARTS / "cam.json")


@pytest.fixture(scope="module")
def kidney():
    return load_part(PARTS / "kidney.csv")


def exact(flt, start_arc, turns):
    """The cumulative arc a true start would give, from the filter's own tracks."""
    i = int(round(start_arc / flt.tracks.h)) % flt.grid.size
    arcs, ok = flt.tracks.advance(np.full(len(turns), i), np.asarray(turns))
    assert ok.all()
    return arcs - flt.grid[i], arcs


def noisy(z, rng, sd):
    e = sd * rng.standard_normal(len(z) + 1)
    return z + e[1:] - e[0]


def test_a_quarantined_reading_is_as_if_never_taken(cam):
    # without the terms whose weights depend on the order of the readings (drift, the rotation reading's
    # error) a filter given all readings and then told to distrust some holds exactly the likelihood of
    # one that never saw them
    plain = {"sd_turn": 0.0, "sd_drift": 0.0, "sd_slope": 0.0, "prune": math.inf, "defect_window": 0.0}
    rng = np.random.default_rng(1)
    turns = STEP * np.arange(1, 121)
    a = ContactFilter(cam, **plain)
    z, _ = exact(a, 80.0, turns)
    z = noisy(z, rng, 0.035)
    for k in range(turns.size):
        a.update(float(z[k]), float(turns[k]))
    before = a.log_likelihood()
    out = set(range(40, 61))
    a.set_quarantine(out)
    b = ContactFilter(cam, **plain)
    for k in range(turns.size):
        if k + 1 not in out:  # reading 0 is the start; update k is reading k + 1
            b.update(float(z[k]), float(turns[k]))
    la, lb = a.log_likelihood(), b.log_likelihood()
    live = np.isfinite(lb)
    np.testing.assert_allclose(la[live] - la[live].max(), lb[live] - lb[live].max(), atol=1e-7)
    a.set_quarantine(set())  # and trusted again: back to the first
    np.testing.assert_allclose(a.log_likelihood()[live], before[live], atol=1e-7)


def test_clean_readings_fit(kidney):
    # 20 noisy rolls of 60° over the kidney's convex lobe at the noise the filter was told, and at
    # twice it not told: the fit test finds nothing
    turns = -STEP * np.arange(1, 301)
    for seed in range(20):
        for sd in (0.035, 0.07):
            flt = ContactFilter(kidney, spacing=0.05)
            z, _ = exact(flt, 29.3, turns)
            z = noisy(z, np.random.default_rng(seed), sd)
            for k in range(turns.size):
                flt.update(float(z[k]), float(turns[k]))
            truth = int(round(29.3 / flt.tracks.h))
            assert flt.fit_test([truth]) is None, (seed, sd)


def test_a_stretch_off_the_model_is_found_where_it_is(kidney):
    # a burr's readings: over 3 mm of the roll the contact lags the model's by up to 0.8 mm and comes
    # back (the jaw pivots on the crest, then jumps on): the fit test names that stretch, and the
    # belief quarantines it and says where, never sure
    turns = -STEP * np.arange(1, 301)
    flt = ContactFilter(kidney, spacing=0.05)
    z, arcs = exact(flt, 29.3, turns)
    z = noisy(z, np.random.default_rng(7), 0.035)
    travel = np.abs(z)
    lag = np.where((travel > 12.0) & (travel < 15.0), 0.8 * np.sin(np.pi * (travel - 12.0) / 3.0), 0.0)
    z = z + lag  # rolling clockwise: z falls, a lag raises it
    for k in range(turns.size):
        flt.update(float(z[k]), float(turns[k]))
    truth = int(round(29.3 / flt.tracks.h))
    found = flt.fit_test([truth])
    assert found is not None and found.p_value < 1e-6 and found.rms_mm > 0.1
    on_burr = arcs[lag != 0]
    lo, hi = found.arcs
    assert lo - 2.0 <= float(np.mean(on_burr)) <= hi + 2.0
    b = flt.belief()
    assert b.mismatch is not None and flt.misfits and not b.sure(0.95)


def test_no_belief_rests_on_one_short_stretch(cam):
    # 30 readings over one millimetre of the cam: sure by the readings alone, but a burr's crest would read
    # the same anywhere, so without that stretch nothing is known
    turns = STEP * np.arange(1, 31)
    flt = ContactFilter(cam, sd_position=0.005, sd_scale=0.0, sd_slope=0.0)
    z, _ = exact(flt, 57.3, turns)
    for k in range(turns.size):
        flt.update(float(z[k]), float(turns[k]))
    ungarded = ContactFilter(cam, sd_position=0.005, sd_scale=0.0, sd_slope=0.0, defect_window=0.0)
    for k in range(turns.size):
        ungarded.update(float(z[k]), float(turns[k]))
    assert ungarded.belief().mass > 0.95
    mass, (lo, hi) = flt.stretch_mass(ungarded.belief().map_arc)
    assert mass < 0.5 and lo <= z[0] + 1e-9 and hi >= z[-1] - 1e-9
    assert flt.belief().mass < 0.95


def test_the_stretch_check_is_weighed_with_the_model(cam):
    # the same readings as above: the stated mass is the mixture (1 - q)·m + q·min(m, s) of the model's
    # mass and the least without any one stretch, asked because the model alone is sure; weight 1 is the least
    turns = STEP * np.arange(1, 31)
    weighed = {q: ContactFilter(cam, sd_position=0.005, sd_scale=0.0, sd_slope=0.0, stretch_weight=q) for q in (0.3, 1)}
    ungarded = ContactFilter(cam, sd_position=0.005, sd_scale=0.0, sd_slope=0.0, defect_window=0.0)
    z, _ = exact(ungarded, 57.3, turns)
    for k in range(turns.size):
        ungarded.update(float(z[k]), float(turns[k]))
        for flt in weighed.values():
            flt.update(float(z[k]), float(turns[k]))
    model = ungarded.belief().mass
    stretch, _ = weighed[1].stretch_mass(ungarded.belief().map_arc)
    assert model > 0.95 and stretch < 0.5
    for q, flt in weighed.items():
        assert flt.belief().mass == pytest.approx((1 - q) * model + q * stretch, abs=1e-9)
    # a weight above 1 - confidence on a stretch check that leaves little keeps the belief from being sure
    assert not weighed[0.3].belief().sure(0.95)


@pytest.mark.parametrize("bad", [1.5, -0.1, math.nan, True, "x"])
def test_a_stretch_weight_that_is_not_a_probability_is_refused(cam, bad):
    with pytest.raises(QueryError, match="stretch_weight"):
        ContactFilter(cam, stretch_weight=bad)


def test_when_nothing_fits_the_belief_says_so(cam):
    flt = ContactFilter(cam)
    flt.update(0.1, STEP)
    flt.feasible[:] = False
    flt._live[:] = False  # every start ruled out (a turn no convex stretch takes)
    flt._live_idx = np.flatnonzero(flt._live)
    b = flt.belief()
    assert flt.ruled_out and not b.consistent and b.mass == 0.0 and not b.sure(0.5)


def test_a_bridge_no_place_predicts_is_unexplained(kidney):
    # rolling clockwise from the convex lobe: a bridge after 10° is predicted by no start the readings
    # leave (the lobe goes on), and the true start does not explain it
    turns = -STEP * np.arange(1, 51)
    flt = ContactFilter(kidney, spacing=0.05)
    z, _ = exact(flt, 29.3, turns)
    for k in range(turns.size):
        flt.update(float(z[k]), float(turns[k]), jaw=-40.0 - float(z[k]))
    predicted = flt.bridged(float(turns[-1] - STEP))
    truth = int(round(29.3 / flt.tracks.h))
    assert predicted < 0.01 and len(flt.unexplained_bridges(truth)) == 1


def test_a_burr_rolled_over_twice_costs_its_readings_once(kidney):
    # the lag of the test above, 1 mm, 13-16 mm into the roll, with a belief every 5 readings as the rolling
    # asks and the settings taken at their word: the burr's readings prune the true start before the fit
    # test finds them; quarantined, the filter is rebuilt without them from the start, and the true start
    # is back. Rolling back over the burr, its readings fall in the quarantined zones and are taken out as
    # they come: no further quarantine on the way back, and the truth is the most probable place
    out = -STEP * np.arange(1, 301)
    back = out[-1] + STEP * np.arange(1, 201)
    turns = np.concatenate([out, back])
    flt = ContactFilter(kidney, spacing=0.05, noise_scales=(1.0,))
    z, arcs = exact(flt, 29.3, turns)
    z = noisy(z, np.random.default_rng(7), 0.035)
    travel = np.abs(z)
    z = z + np.where((travel > 13.0) & (travel < 16.0), 1.0 * np.sin(np.pi * (travel - 13.0) / 3.0), 0.0)
    truth = int(round(29.3 / flt.tracks.h))
    pruned_before = None
    for k in range(turns.size):
        if k == 50:  # a call refused on the way is not made again when the filter is rebuilt
            with pytest.raises(QueryError):
                flt.update(10.0 * kidney.perimeter, float(turns[k]))
        flt.update(float(z[k]), float(turns[k]))
        if k % 5 == 4:
            alive = bool(np.isfinite(flt.log_likelihood()[truth]))
            flt.belief()
            if flt.misfits and pruned_before is None:
                pruned_before = not alive
        if k + 1 == out.size:
            found_out = len(flt.misfits)
    b = flt.belief()
    assert pruned_before and np.isfinite(flt.log_likelihood()[truth])
    assert 1 <= found_out == len(flt.misfits) and b.mismatch is not None and not b.sure(0.95)
    assert abs(float(kidney.arc_offset(b.map_arc, arcs[-1]))) < 0.3


def test_each_stretch_left_out_is_a_filter_that_never_saw_it(cam):
    # the stretch envelope and the fit test leave stretches out of the sums, several in one batched solve;
    # a filter that never got a stretch's readings is the independent reference (settings without
    # order-dependent terms, so that the two hold the same likelihood): the same log-likelihood over the
    # starts, and, where the stretch is not the last (else the reference's contact is not the present
    # one), the same probability near the contact
    plain = {"sd_turn": 0.0, "sd_drift": 0.0, "sd_slope": 0.0, "prune": math.inf}
    turns = STEP * np.arange(1, 151)
    flt = ContactFilter(cam, **plain)
    z, _ = exact(flt, 80.0, turns)
    z = noisy(z, np.random.default_rng(3), 0.035)
    for k in range(turns.size):
        flt.update(float(z[k]), float(turns[k]))
    arc = flt.belief().map_arc
    rows = flt._trusted()
    windows = [inside for _, inside in flt._windows(rows)]
    solves = list(flt._without_each(flt._stack(rows), windows))
    assert len(windows) >= 8 and len(solves) < len(windows)  # batched
    compared = 0
    for first, s in solves:
        mean, sd = flt._shift_of(s)
        for n, inside in enumerate(windows[first : first + s["ll"].shape[0]]):
            out = {rows[i] for i in inside}
            ref = ContactFilter(cam, defect_window=0.0, **plain)
            for k in range(turns.size):
                if k + 1 not in out:  # reading 0 is the start; update k is reading k + 1
                    ref.update(float(z[k]), float(turns[k]))
            ll, ll_ref = s["ll"][n], ref.log_likelihood()
            live = np.isfinite(ll_ref)
            np.testing.assert_allclose(ll[live] - ll[live].max(), ll_ref[live] - ll_ref[live].max(), atol=1e-7)
            if max(out) == len(rows):
                continue
            w = np.exp(ll - ll.max())
            mass = flt._mass_near(w / w.sum(), cam.wrap_arc(flt.current + mean[n]), sd[n], arc, flt.radius)
            m_ref, s_ref = ref.shift()
            ref_mass = ref._mass_near(ref.posterior(), cam.wrap_arc(ref.current + m_ref), s_ref, arc, ref.radius)
            assert mass == pytest.approx(ref_mass, abs=1e-9)
            compared += 1
    assert compared >= 4


@settings(max_examples=60, deadline=None)
@given(
    quad=st.lists(st.floats(0.0, 1e5), min_size=1, max_size=6),
    k=st.integers(0, 400),
    lam=st.lists(st.floats(0.05, 20.0), min_size=1, max_size=30),
)
def test_the_noise_scale_is_weighed_out_as_a_log_mean_of_exponentials(quad, k, lam):
    q, scales = np.array([quad]), np.array(sorted(lam))
    terms = -0.5 * q[0][None, :] / scales[:, None] ** 2 - k * np.log(scales)[:, None]
    expected = logsumexp(terms, axis=0) - math.log(scales.size)
    post = softmax(terms, axis=0)
    log_mean, lam2 = weigh_scales(q, np.array([float(k)]), scales)
    np.testing.assert_allclose(log_mean[0], expected, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(lam2[0], (post * scales[:, None] ** 2).sum(axis=0), rtol=1e-12)


def test_a_stretch_off_a_large_radius_is_judged_too():
    # on a 400 mm radius the contact moves 1.4 mm every 0.2°: a jump is a step beyond what the radius
    # makes of the turn, not any step over a millimetre (which would leave every reading here unjudged)
    a = np.linspace(0, 2 * np.pi, 120, endpoint=False)
    r = 400.0 + 6.0 * np.cos(3 * a)
    big = part_from_points(np.c_[r * np.cos(a), r * np.sin(a)], name="big")
    turns = STEP * np.arange(1, 121)
    flt = ContactFilter(big, spacing=0.2)
    z, _ = exact(flt, 300.0, turns)
    assert np.median(np.abs(np.diff(z))) > 1.0
    z = noisy(z, np.random.default_rng(5), 0.035)
    # a burr's crest: the jaw pivots on it for 6 mm of the model's rolling, the contact held, then goes on
    hold = np.flatnonzero((np.abs(z) > 60.0) & (np.abs(z) < 66.0))
    z[hold] = z[hold[0]]
    for k in range(turns.size):
        flt.update(float(z[k]), float(turns[k]))
    truth = int(round(300.0 / flt.tracks.h))
    found = flt.fit_test([truth])
    assert found is not None and found.rms_mm > 0.1


def test_readings_that_fit_only_as_noise_many_times_the_rigs_state_no_probability(kidney):
    # the fit test judges a stretch against the rest, so readings that misfit a start all along pass it: a
    # wrong start may then explain them as noise many times the rig's (a corner's pivot, after a burr under the
    # start ruled the true one out). Beyond NOISE_FIT_LIMIT times the noise it was told the belief states no
    # probability; within it (noise four times what it was told, the filter's own remit) it does
    turns = -STEP * np.arange(1, 301)
    stated = {}
    for factor in (4.0, 12.0):
        flt = ContactFilter(kidney, spacing=0.05)
        z, _ = exact(flt, 29.3, turns)
        z = noisy(z, np.random.default_rng(3), factor * flt.sd_position)
        for k in range(turns.size):
            flt.update(float(z[k]), float(turns[k]))
        stated[factor] = (flt.noise_scale(), flt.belief().mass)
    assert stated[4.0][0] < NOISE_FIT_LIMIT < stated[12.0][0], stated
    assert stated[4.0][1] > 0.0 and stated[12.0][1] == 0.0, stated
