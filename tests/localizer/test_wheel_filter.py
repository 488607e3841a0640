"""The wheel's sequential filter (issue 17): its likelihood against the full Gaussian density, its belief
against the truth on noise-free rolls from concave starts, its reach and its refusals."""

import math

import numpy as np
import pytest
from scipy.stats import multivariate_normal

from localizer import OFF_SCALE, OFF_SCALE_DOUBT, QueryError, WheelFilter, WheelJaw, load_part, part_from_points
from localizer.contact._wheel_rolling import free_runs

from .test_wheel import peanut

KIDNEY = "parts/kidney.csv"


def theta(part, s):
    s = np.asarray(s, dtype=float)
    laps = np.floor(s / part.perimeter)
    return part.tangent_angle(part.param_at_arc(s - laps * part.perimeter)) + 2 * np.pi * laps


def test_the_grown_factor_gives_the_full_gaussian_density_of_the_residuals():
    part = load_part(KIDNEY)
    f = WheelFilter(part, WheelJaw(5.0), sd_length=0.0, sd_scale=0.0, thin=0.7)
    rng = np.random.default_rng(3)
    lengths = np.arange(0.5, 140.0, 0.5)  # 139 readings used: the filter's arrays doubled twice on the way
    turns = rng.normal(0.0, 0.2, lengths.size).cumsum() * 0.01
    for L, om in zip(lengths, turns):
        f.update(L, om)
    used = np.array(f.L_used)
    assert used.size > 128
    cov = f._cov(used, used)  # the documented covariance, built in one piece
    picks = (100, 3000, 7000)
    full = []
    for i in picks:
        rho = np.interp(used, lengths, turns) - (theta(part, f.grid[i] + used) - theta(part, f.grid[i]))
        full.append(multivariate_normal(np.zeros(used.size), cov).logpdf(rho))
    # log N = -½ quad - ½ log det - k/2 log 2π; compare differences between starts
    ours = -0.5 * f._quad[list(picks)] - 0.5 * f._logdet[list(picks)]
    assert np.allclose(np.diff(ours), np.diff(full), rtol=1e-6, atol=1e-6)


def test_the_readings_kept_are_bounded_and_a_reading_past_the_bound_is_refused_by_name():
    from localizer import MAX_ARRAY_BYTES

    part = load_part(KIDNEY)
    for off, numbers in ((0.0, 3), (OFF_SCALE, 6)):  # a start's numbers a reading: three, six with the scale
        g = WheelFilter(part, WheelJaw(5.0), off_scale=off)
        n, k = g.grid.size, g.max_readings
        per = 8 * numbers * n
        assert per * k + 8 * k * k <= MAX_ARRAY_BYTES < per * (k + 1) + 8 * (k + 1) ** 2
    f = WheelFilter(part, WheelJaw(5.0))
    f.max_readings = 70  # as on a part 50 times larger: past the first doubling, to the bound
    for i in range(70):
        f.update(float(i + 1), 0.0)
    assert len(f.L_used) == 70 and f._zzbuf.shape[0] == 70
    with pytest.raises(QueryError, match=r"holds 70 readings of \d+ starts .* give a larger thin, or roll less"):
        f.update(71.0, 0.0)
    f.reset()
    f.update(1.0, 0.0)  # a new start: room again


@pytest.mark.parametrize("radius", [3.0, 10.0])
def test_noise_free_rolls_from_concave_starts_end_sure_at_the_truth(radius):
    """Within 80 mm of rolling, the part's size weighed (the default: at the model's size alone 60 mm does, the
    last 15 mm being what a part that may be 1% off its size asks more of the kidney's near-circular arcs)."""
    part = load_part(KIDNEY)
    sigma = np.linspace(0, part.perimeter, 600, endpoint=False)
    starts = sigma[part.curvature_at_arc(sigma) < 0][::8]
    assert starts.size >= 5
    for s in starts:
        f = WheelFilter(part, WheelJaw(radius))
        for L in np.arange(0.25, 80.0, 0.25):
            f.update(L, float(theta(part, s + L) - theta(part, s)))
            b = f.belief() if f.steps % 4 == 0 else None
            if b is not None and b.mass >= 0.95:
                break
        assert b is not None and b.mass >= 0.95
        assert abs(float(part.arc_offset(b.map_arc, s + L))) < 0.05


def test_a_start_whose_roll_runs_over_what_the_wheel_cannot_touch_is_unlikely_not_ruled_out():
    outline, _ = peanut()  # waists of 10 mm: a 12 mm wheel cannot touch them
    dense = np.asarray(outline.point_at_arc(np.linspace(0, outline.perimeter, 400, endpoint=False)))
    part = part_from_points(dense, name="peanut")
    f = WheelFilter(part, WheelJaw(12.0))
    assert 0 < f.prior.mean() < 1
    blocked = np.flatnonzero(f.prior > 0)
    for L in np.arange(1.0, 31.0, 1.0):
        f.update(L, 0.0)
    clear = f._u_max() >= 0  # clear at the model's size
    assert not clear[blocked].all() and clear[blocked].any()
    assert np.all(f._penalty[~clear & (f.prior > 0)] <= math.log(1e-3) + 1e-9)  # CONTRADICTION at a reading used
    assert np.all(f._penalty[clear] == 0)


def test_off_its_size_a_roll_read_past_a_place_it_cannot_pass_bounds_the_scale():
    """A part 2% large reads 2% more arc than its model rolls: a wheel rolled up to the peanut's waist on it
    reads past the waist. A start whose free run is 30 mm is clear at the model's size after 29.9 mm read and
    not after 30.2; off its size the roll is clear for u up to (30 + 2h)/read − 1, and the model's size's
    contradictions there are counted for it only beyond."""
    outline, _ = peanut()
    dense = np.asarray(outline.point_at_arc(np.linspace(0, outline.perimeter, 400, endpoint=False)))
    part = part_from_points(dense, name="peanut")
    f = WheelFilter(part, WheelJaw(12.0), off_scale=OFF_SCALE)
    j = int(np.argmin(np.where(f._ahead > 0, np.abs(f._ahead - 30.0), np.inf)))
    run = float(f._ahead[j])
    for read, clear in ((29.9, True), (30.2, False)):
        f.span = (0.0, read * run / 30.0)
        assert (f._u_max()[j] >= 0) == clear
    f.span = (-5.0, 30.6 * run / 30.0)
    assert math.isclose(f._u_max()[j], (run + 2 * f.h) / f.span[1] - 1.0, rel_tol=1e-12)
    f.reset()
    for L in [*np.arange(1.0, run - 0.5, 1.0), run + 0.6]:  # the last read 0.6 mm past the free run, used
        f.update(float(L), 0.0)
    assert f._penalty[j] < 0 and f._penalty_run[j] == f._penalty[j]


@pytest.mark.parametrize(("zg", "gg"), [(0.0, 0.0), (150.0, 4e4), (-300.0, 1e5)])
@pytest.mark.parametrize("u_max", [-0.03, -0.01, 0.0, 0.02, math.inf])
def test_the_scale_weighed_out_with_a_bound_from_the_free_run_agrees_with_sampling_its_prior(zg, gg, u_max):
    """weigh_scale against brute force: u drawn from its prior N(0, σ²), each draw's factor on the likelihood
    exp(zg·u − gg·u²/2) times 1 if the roll is clear (u ≤ u_max) else the model's size's contradictions
    (e^P). The log of its mean over the draws, less P, is the evidence off the model's size against at it."""
    from localizer import PART_SCALE_SD
    from localizer.filters._wheel_scale import weigh_scale

    rng = np.random.default_rng(5)
    u = rng.normal(0.0, PART_SCALE_SD, 2_000_000)
    penalty = math.log(1e-3) * 2
    factor = np.exp(zg * u - 0.5 * gg * u**2) * np.where(u <= u_max, 1.0, math.exp(penalty))
    expected = math.log(float(factor.mean())) - penalty
    mean, sd, evidence = weigh_scale(
        np.array([zg]), np.array([gg]), PART_SCALE_SD, np.array([u_max]), np.array([penalty])
    )
    assert evidence[0] == pytest.approx(expected, abs=0.01)
    tilted = np.exp(zg * u - 0.5 * gg * u**2)
    assert mean[0] == pytest.approx(float(np.sum(tilted * u) / tilted.sum()), abs=2e-4)


def test_free_runs_count_the_arc_to_the_next_untouchable_point_both_ways():
    touch = np.array([True, True, False, True, True, True, False, True])
    ahead, behind = free_runs(touch, 0.5)
    assert ahead.tolist() == [0.5, 0.0, -1.0, 1.0, 0.5, 0.0, -1.0, 1.0]
    assert behind.tolist() == [0.5, 1.0, -1.0, 0.0, 0.5, 1.0, -1.0, 0.0]
    assert np.isinf(free_runs(np.ones(5, bool), 1.0)[0]).all()


def test_a_jump_makes_the_starts_that_could_have_rolled_on_unlikely():
    outline, _ = peanut()
    part = part_from_points(np.asarray(outline.point_at_arc(np.linspace(0, outline.perimeter, 400, endpoint=False))))
    f = WheelFilter(part, WheelJaw(12.0))
    f.jumped(+1)
    here = np.rint(f.grid / f.h).astype(int) % f.grid.size
    rolls_on = f._ahead[here] > 1.0
    assert np.all(f._penalty[rolls_on] == pytest.approx(math.log(0.05)))
    assert np.all(f._penalty[~rolls_on] == 0)
    with pytest.raises(QueryError, match="direction"):
        f.jumped(0)


def test_bad_settings_and_what_is_not_a_part_are_refused():
    part = load_part(KIDNEY)
    with pytest.raises(QueryError, match="spacing"):
        WheelFilter(part, WheelJaw(5.0), spacing=0.0)
    with pytest.raises(QueryError, match="sd_turn"):
        WheelFilter(part, WheelJaw(5.0), sd_turn=0.0)
    with pytest.raises(QueryError, match="noise_scales"):
        WheelFilter(part, WheelJaw(5.0), noise_scales=(0.5,))
    with pytest.raises(QueryError, match="a Part or an Outline, not str"):
        WheelFilter("parts/kidney.csv", WheelJaw(5.0))  # type: ignore[arg-type]
    f = WheelFilter(part, WheelJaw(5.0))
    with pytest.raises(QueryError, match="finite"):
        f.update(math.nan, 0.0)


def test_readings_that_fit_nowhere_state_nothing():
    """A wheel jammed between two walls reads as rolling on a concave arc of its own radius: on the
    kidney, whose concave radius is 65 mm at the least, no start fits that, and the belief says so."""
    part = load_part(KIDNEY)
    f = WheelFilter(part, WheelJaw(5.0))
    for L in np.arange(0.25, 12.01, 0.25):
        f.update(L, -L / 5.0)
    b = f.belief()
    assert not b.consistent and b.mass == 0.0
    g = WheelFilter(part, WheelJaw(5.0))  # the same length of true rolling fits
    for L in np.arange(0.25, 12.01, 0.25):
        g.update(L, float(theta(part, 60.0 + L) - theta(part, 60.0)))
    assert g.belief().consistent


# a convex pentagon of five different sides and angles: no symmetry, four corners a 5 mm wheel pivots on
PENTAGON = [(0.0, 0.0), (70.0, 0.0), (85.0, 25.0), (40.0, 45.0), (0.0, 30.0)]


def pivoting_readings(vertices, start, length, direction, step=0.25, pivot_step=0.05, arrive=0.6):
    """(L, Ω) of a wheel rolling ``length`` mm from arc ``start`` on the polygon, the way ``direction``
    (±1), from the vertices alone: Ω steps at each corner while L stands still, ``pivot_step`` rad a
    reading, the reading that arrives at the corner already ``arrive`` rad into its jump."""
    v = np.asarray(vertices, dtype=float)
    edges = np.roll(v, -1, axis=0) - v
    sides = np.hypot(edges[:, 0], edges[:, 1])
    heading = np.unwrap(np.arctan2(edges[:, 1], edges[:, 0]))
    corners = np.cumsum(sides)  # arc of the corner at the end of each side
    P = corners[-1]

    def theta(s):  # unwrapped heading at unrolled arc s, just after any corner there
        lap, r = divmod(s, P)
        return heading[np.searchsorted(corners, r, side="right") % v.shape[0]] + 2 * np.pi * (lap + (r >= corners[-1]))

    out = [(0.0, 0.0)]
    rolled, th0 = 0.0, theta(start)
    while rolled < length:
        nxt = rolled + step
        # a corner passed in this step: roll to it, then pivot through its jump
        here = start + direction * rolled
        cs = [c + k * P for k in (-2, -1, 0, 1) for c in corners]
        cs = [c for c in cs if 0 < direction * (c - here) <= step]
        if cs:
            c = min(cs, key=lambda c: abs(c - here))
            Lc = abs(c - start)
            before = theta(c - direction * 1e-9) - th0
            after = theta(c + direction * 1e-9) - th0
            turns = np.arange(before + direction * arrive, after, direction * pivot_step)
            out += [(direction * Lc, float(t)) for t in turns]
            out.append((direction * Lc, after))
            rolled = Lc  # the step that reached the corner ended on it, part way round
            continue
        out.append((direction * nxt, float(theta(start + direction * nxt) - th0)))
        rolled = nxt
    return out


@pytest.mark.parametrize("off_scale", [0.0, OFF_SCALE])
@pytest.mark.parametrize(("corner", "direction", "corners"), [(1, 1, 2), (2, 1, 1), (1, -1, 1), (0, -1, 2)])
def test_a_wheel_pivoting_on_a_drawings_convex_corners_is_found_from_the_vertices_alone(
    corner, direction, corners, off_scale
):
    """Rolls of 45.22 mm over one or two corners each way, one through the seam (corner 0 rolling clockwise);
    the truth off the filter's grid. Every reading 0.2 mm from the last is used, so that the one that arrives
    at a corner, part way through its pivot, is: without the corner rule it is 0.6 rad off at the truth.
    The readings are the geometry's own, so the belief lies where they put it, within the corner window. At
    the model's size it is sure; with the part's scale carried (the default) only where a second corner told
    the size: after one, the face's 30 mm since it could be 1% longer or shorter (0.3 mm, the success radius)."""
    from localizer import Line, outline_from_pieces

    pieces = [Line(PENTAGON[i], PENTAGON[(i + 1) % 5]) for i in range(5)]
    outline = outline_from_pieces(pieces, name="pentagon")
    c = outline.corners[corner].arc
    start = float(outline.wrap_arc(c - direction * 15.22))  # the corner 0.22 mm past a reading at 15 mm
    f = WheelFilter(outline, WheelJaw(5.0), thin=0.2, off_scale=off_scale)
    readings = pivoting_readings(PENTAGON, start, 45.0, direction)
    for L, om in readings:
        f.update(L, om)
    at_corner = {round(L, 9) for i, (L, _) in enumerate(readings[1:], 1) if np.isclose(L, readings[i - 1][0])}
    assert at_corner & {round(L, 9) for L in f.L_used}
    b = f.belief()
    truth = float(outline.wrap_arc(start + readings[-1][0]))
    # on a face only the corner places the contact: within the window a reading may be pivoting in
    assert abs(float(outline.arc_offset(b.map_arc, truth))) < f.corner_window(45.0)
    assert b.consistent and b.mismatch is None
    assert (b.mass >= 0.95) == (off_scale == 0.0 or corners == 2)


def test_a_jump_next_to_a_shallow_concave_corner_does_not_count_against_the_start_it_came_from():
    """A rectangle whose bottom bends in by 5° at its middle: the reach's clearance (0.1 mm) lets a 5 mm
    disc touch all of it, but the disc meets both faces 5·tan(2.5°) = 0.22 mm before the corner and cannot
    roll on (the rolling takes the 5° drop for a jump). A jump there is no evidence against the starts
    right before the corner; it still is against those 10 mm before it."""
    from localizer import Line, outline_from_pieces

    v = [(0.0, 0.0), (40.0, 1.75), (80.0, 0.0), (80.0, 50.0), (0.0, 50.0)]
    outline = outline_from_pieces([Line(v[i], v[(i + 1) % 5]) for i in range(5)], name="bent")
    (corner,) = [c for c in outline.corners if c.angle < 0]
    assert math.isclose(math.degrees(corner.angle), -5.0, abs_tol=0.02)
    f = WheelFilter(outline, WheelJaw(5.0))
    i_near = int(np.argmin(np.abs(f.grid - (corner.arc - 0.22 - 0.5))))
    i_far = int(np.argmin(np.abs(f.grid - (corner.arc - 10.0))))
    assert f.prior[i_near] > 0 and f._ahead[i_near] > 10.0  # the reach says it could roll on
    f.jumped(+1, margin=1.25)
    assert f._penalty[i_near] == 0.0 and f._penalty[i_far] < 0.0
    f.reset()
    j_near = int(np.argmin(np.abs(f.grid - (corner.arc + 0.22 + 0.5))))
    f.jumped(-1, margin=1.25)  # rolling clockwise towards it from the other face
    assert f._penalty[j_near] == 0.0


def _shifts(part, table):
    rng = np.random.default_rng(11)
    return np.r_[rng.uniform(-1.5, 1.5, 4) * part.perimeter, 0.0, table.h * 3, -0.013]


@pytest.mark.parametrize(
    "path, tol", [(KIDNEY, 1e-7), ("parts/trefoil.json", 1e-7), ("bench/parts/heldout-a/glyph-14.json", 5e-5)]
)
def test_the_shifted_grid_gives_the_parts_own_angle_and_curvature_at_any_shift(path, tol):
    """The wheel filter's interpolated Θ and κ at every start plus L against the part's own evaluation, L
    either way and past a lap: within 1e-7 rad on smooth shipped parts and 5e-5 rad on a held-out glyph
    whose curvature reaches 5.8 mm⁻¹ (a reading's angle error is 4.4e-4 rad); κ, linear between nodes and
    weighing only a reading's variance, within 1% of its largest value."""
    from localizer.contact import ShiftedGrid

    part = load_part(path)
    table = ShiftedGrid(part, int(math.ceil(part.perimeter / 0.02)))
    for L in _shifts(part, table):
        got_theta, got_kappa = table.at(float(L))
        x = table.grid + L
        assert np.abs(got_theta - theta(part, x)).max() <= tol
        kappa = part.curvature_at_arc(part.wrap_arc(x))
        assert np.abs(got_kappa - kappa).max() <= 0.01 * np.abs(kappa).max()


def test_the_shifted_grid_of_a_drawing_is_the_drawings_own_evaluation():
    from localizer.contact import ShiftedGrid

    part = load_part("parts/bracket.dxf")
    table = ShiftedGrid(part, int(math.ceil(part.perimeter / 0.02)))
    for L in _shifts(part, table):
        got_theta, got_kappa = table.at(float(L))
        x = table.grid + L
        assert np.array_equal(got_theta, part.tangent_angle_at_arc(x))
        assert np.array_equal(got_kappa, part.curvature_at_arc(part.wrap_arc(x)))


def scaled_readings(part, start: float, scale: float, lengths):
    """(L, Ω) of a noise-free roll from model arc ``start`` on the part made ``scale`` times its model's size:
    the real arc L is ``scale`` times the model's."""
    return [(float(L), float(theta(part, start + L / scale) - theta(part, start))) for L in lengths]


def test_a_part_two_percent_large_is_never_sure_and_wrong_with_its_scale():
    """Rolls of 40 mm on the kidney made 2% larger than its model, from six starts. With the scale's prior (off
    its model's size with probability OFF_SCALE, then by N(0, 1%²)) no belief is sure and wrong, four or more
    are within the success radius, and where one is, the scale's posterior given its start says the part is
    off its size and larger (u = 1/1.02 − 1 = −0.0196, shrunk towards 0 by the prior). On the kidney's
    near-circular stretches a start and a scale explain the readings alike: the belief is then not sure.
    The same rolls on the part at its model's size: the belief within 0.01 mm of the truth, the part
    taken to be off its size with probability under 0.05."""
    part = load_part(KIDNEY)
    lengths = np.arange(0.5, 40.01, 0.5)
    right = wrong_and_sure = 0
    for s in np.linspace(0.0, part.perimeter, 6, endpoint=False) + 7.0:
        for scale in (1.02, 1.0):
            f = WheelFilter(part, WheelJaw(5.0), off_scale=OFF_SCALE)
            for L, om in scaled_readings(part, s, scale, lengths):
                f.update(L, om)
            b = f.belief()
            off = abs(float(part.arc_offset(b.map_arc, s + lengths[-1] / scale)))
            mean, p_off = f._scale_posterior(temper=1.0)
            i = int(np.argmax(f.posterior()))
            if scale == 1.0:
                assert off < 0.01 and p_off[i] < 0.05
                continue
            right += off < 0.3
            wrong_and_sure += b.mass >= 0.95 and off >= 0.3
            if off < 0.3:
                assert p_off[i] > 0.9 and -0.0196 - 0.002 < mean[i] < -0.012
    assert wrong_and_sure == 0 and right >= 4


@pytest.mark.parametrize("scale", [1.0, 1.02, 0.98])
def test_on_a_drawing_two_percent_off_its_size_the_wheel_is_never_sure_and_wrong_with_its_scale(scale):
    """On the pentagon (straight faces: only its corners tell the scale) made ``scale`` times its model's size,
    noise-free rolls over one corner (40 mm: 25 mm of the face after it) and over two (50 mm), with the scale
    carried. Over one corner the size is not told: never sure there (2% off, the contact is 0.48 mm from where
    the model's size puts it, which without the scale is stated at 1.0), right at the model's size. Over two
    corners the pivots' places, 29.2 mm of the model apart, tell it: sure and right whatever the size (at the
    model's size the part taken to be off it with probability under 0.01), and without the scale carried,
    off its size nothing fits (the second pivot is 0.6 mm from where the first puts it)."""
    model = _pentagon()
    start = float(model.wrap_arc(model.corners[1].arc - 15.22))
    real = [(x * scale, y * scale) for x, y in PENTAGON]
    for length in (40.0, 50.0):  # the second corner is 29.2 mm past the first
        readings = pivoting_readings(real, start * scale, length, 1)
        truth = float(model.wrap_arc(start + readings[-1][0] / scale))
        f, told = (WheelFilter(model, WheelJaw(5.0), thin=0.2, off_scale=off) for off in (OFF_SCALE, 0.0))
        for L, om in readings:
            f.update(L, om)
            told.update(L, om)
        b, i = f.belief(), int(np.argmax(f.posterior()))
        off = abs(float(model.arc_offset(b.map_arc, truth)))
        said = f.part_scale()
        if length == 40.0:
            assert b.mass < 0.95 and (off < 0.05 or scale != 1.0)
            # nothing told of the size: the prior's (off it with probability OFF_SCALE, then 1 ± 1%)
            assert said.probability == pytest.approx(OFF_SCALE, abs=1e-3) and said.sd == pytest.approx(0.01, rel=0.01)
            continue
        assert off < 0.05 and b.mass >= 0.95
        if scale == 1.0:
            assert f.present_spread().p_off[i] < 0.01 and said.probability < 0.01
        else:
            assert not told.belief().consistent
            # told by the two pivots: within two of its standard deviations (about 0.16%) of the part's size
            assert said.probability > 0.99 and abs(said.scale - scale) < 2 * said.sd < 0.004
    assert WheelFilter(model, WheelJaw(5.0), off_scale=0.0).part_scale() == (0.0, 1.0, 0.0)


def test_a_pivot_within_thin_of_the_last_reading_used_is_read_with_the_scale_carried():
    """Readings used are spaced ``thin`` (1 mm) in arc; a pivot stands at one arc, 0.6 mm past the last reading
    used on the pentagon here. With the scale carried its first reading whose turn is beyond a reading's error is
    used all the same, so that its place counts for the starts at the corner and its turn for the rest: the
    estimate within 0.01 mm (with the pivot left out, the starts 0.6 mm about the truth fit alike)."""
    model = _pentagon()
    start = float(model.wrap_arc(model.corners[1].arc - 15.6))
    readings = pivoting_readings(PENTAGON, start, 20.0, 1)
    f = WheelFilter(model, WheelJaw(5.0), off_scale=OFF_SCALE)
    for L, om in readings:
        f.update(L, om)
    assert [round(L, 6) for L in f.L_used[14:17]] == [15.0, 15.6, 16.6]
    truth = float(model.wrap_arc(start + readings[-1][0]))
    assert abs(float(model.arc_offset(f.belief().map_arc, truth))) < 0.01


def _pentagon():
    from localizer import Line, outline_from_pieces

    return outline_from_pieces([Line(PENTAGON[i], PENTAGON[(i + 1) % 5]) for i in range(5)], name="pentagon")


@pytest.mark.parametrize("length", [25.0, 40.0])
def test_the_stated_probability_is_the_least_under_either_prior_odds_of_the_part_being_off_its_size(length):
    """The stated mass with the scale carried is the least of the masses stated by a filter that takes the part to
    be off its size with probability OFF_SCALE and by one that takes OFF_SCALE_DOUBT (each alone), where their
    estimates agree (to 0.001 mm: the present contact's mean moves by the posterior odds; the masses then to
    1e-5); the belief itself (its
    estimate, the posterior over starts) is OFF_SCALE's. On the pentagon
    at its model's size, past its only corner read, a face says nothing of the size: 25 mm on, both are sure; 40
    mm on, the contact is 0.4 mm (1σ of the 1% prior) from where the model's size puts it if the part is off its
    size, and with the doubt's odds the belief is not sure, with OFF_SCALE's alone it is."""
    model = _pentagon()
    start = float(model.wrap_arc(model.corners[1].arc - 15.22))
    readings = pivoting_readings(PENTAGON, start, length, 1)
    f = WheelFilter(model, WheelJaw(5.0), thin=0.2, off_scale=OFF_SCALE)
    odds = (OFF_SCALE, OFF_SCALE_DOUBT)
    alone = [WheelFilter(model, WheelJaw(5.0), thin=0.2, off_scale=off, off_scale_doubt=off) for off in odds]
    for L, om in readings:
        for g in (f, *alone):
            g.update(L, om)
    b, each = f.belief(), [g.belief() for g in alone]
    assert all(abs(float(model.arc_offset(e.map_arc, b.map_arc))) < 1e-3 for e in each)
    assert b.map_arc == each[0].map_arc and np.array_equal(f.posterior(), alone[0].posterior())
    assert b.mass == pytest.approx(min(e.mass for e in each), abs=1e-5)
    if length == 25.0:
        assert b.mass >= 0.95
    else:
        assert each[0].mass >= 0.95 > b.mass


def test_without_the_scale_the_doubt_changes_nothing():
    """The doubt's odds weigh a part off its size: with the scale not carried (off_scale 0) the belief is the
    same whatever they are."""
    model = _pentagon()
    start = float(model.wrap_arc(model.corners[1].arc - 15.22))
    fs = [
        WheelFilter(model, WheelJaw(5.0), thin=0.2, off_scale=0.0, off_scale_doubt=d)
        for d in (0.0, OFF_SCALE_DOUBT, 0.9)
    ]
    for L, om in pivoting_readings(PENTAGON, start, 40.0, 1):
        for g in fs:
            g.update(L, om)
    masses = {g.belief().mass for g in fs}
    assert len(masses) == 1 and masses.pop() >= 0.95


@pytest.mark.parametrize("off", [0.0, OFF_SCALE, 0.5, 0.99])
def test_a_reading_that_fits_is_consistent_whatever_the_prior_odds_of_the_part_being_off_its_size(off):
    """The fit test's deviance with the scale counts the prior's odds against a part off its size only where
    they are against it: at 0.99 (the part all but surely off its size) a bonus would make it negative, which
    the χ² test reads as no fit at all."""
    part = load_part(KIDNEY)
    f = WheelFilter(part, WheelJaw(5.0), off_scale=off)
    f.update(1.0, float(theta(part, 31.0) - theta(part, 30.0)))
    assert f.consistent() and f.consistent(1.0)


@pytest.mark.parametrize("odds", [OFF_SCALE, OFF_SCALE_DOUBT])
@pytest.mark.parametrize("factor", [1.0, 2.0])
def test_the_posterior_weighed_over_both_sizes_at_once_is_the_odds_mixture_of_each_starts_two_likelihoods(odds, factor):
    """A belief weighs each start at its model's size and off it in one pass; against the mixture written out in
    logs (each start's log-likelihood at its size plus log[(1 − p) + p·e^evidence], normalised over the starts
    by :func:`numpy.logaddexp`), after a roll over a corner of the pentagon 2% large: the same posterior and
    probability of being off its size, where a start weighs anything (1e-300 of the best)."""
    from scipy.special import logsumexp

    model = _pentagon()
    start = float(model.wrap_arc(model.corners[1].arc - 15.22))
    f = WheelFilter(model, WheelJaw(5.0), thin=0.2)
    for L, om in pivoting_readings([(1.02 * x, 1.02 * y) for x, y in PENTAGON], start * 1.02, 40.0, 1):
        f.update(L, om)
    w, spread = f._weighed(factor, odds)
    mean, sd, evidence = f._scale_evidence(factor, None, None, 0.5)
    at_size = 0.5 * (-0.5 * f._quad / factor**2 - 0.5 * f._logdet) + f._penalty
    ll = np.where(f.prior > 0, at_size + np.logaddexp(math.log1p(-odds), math.log(odds) + evidence), -np.inf)
    expected = np.exp(ll - logsumexp(ll))
    p_off = np.exp(math.log(odds) + evidence - np.logaddexp(math.log1p(-odds), math.log(odds) + evidence))
    heavy = expected > 1e-300
    np.testing.assert_allclose(w[heavy], expected[heavy], rtol=1e-9)
    np.testing.assert_allclose(spread.p_off[heavy], p_off[heavy], rtol=1e-9, atol=1e-300)
    assert w[~heavy].sum() < 1e-290


def test_relative_weights_and_their_log_sum_agree_with_numpy_and_drop_only_what_no_sum_could_show():
    """Against numpy's exp and logaddexp on log-weights from 0 down to −1e4 and −inf: the same where a weight
    is above e^−700 of the top, exactly 0 below (numpy gives at most 1e-304 there)."""
    from localizer.filters._wheel_scale import LOG_NEGLIGIBLE, log_add_exp, relative_weights

    rng = np.random.default_rng(3)
    log_w = np.concatenate([-rng.exponential(300.0, 5000), [0.0, -699.0, -701.0, -1e4, -np.inf]])
    w = relative_weights(log_w, 0.0)
    kept = log_w > LOG_NEGLIGIBLE
    np.testing.assert_array_equal(w[kept], np.exp(log_w[kept]))
    assert np.all(w[~kept] == 0.0) and np.all(np.exp(log_w[~kept]) < 1e-304)
    other = -rng.exponential(300.0, log_w.size)
    np.testing.assert_allclose(log_add_exp(log_w, other), np.logaddexp(log_w, other), rtol=1e-15, atol=1e-12)
    np.testing.assert_allclose(log_add_exp(-0.05, log_w), np.logaddexp(-0.05, log_w), rtol=1e-15, atol=1e-15)
