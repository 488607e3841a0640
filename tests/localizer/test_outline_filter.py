"""The sequential filter on outlines with faces and corners (issue 16), against an independent reference:
where the contact is after a turn, from the chord directions of a dense polyline through the outline
(not the filter's tables nor the outline's own θ)."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

import localizer.filters._contact_marginal as contact_marginal_module
from localizer import ContactFilter, load_outline
from localizer.filters._contact_settings import FACE_SLOPES

PARTS = Path(__file__).resolve().parents[2] / "parts"
H = 0.002  # mm between the reference's points
STEP = math.radians(0.2)


class Rolling:
    """Where a straight jaw rolled counter-clockwise puts the contact: the first point at or after the
    start whose tangent (chord direction, unwrapped) reaches the start's angle plus the turn. A
    corner is a jump of the chords' direction, so the contact waits there while the jaw pivots."""

    def __init__(self, outline):
        self.P = outline.perimeter
        s = np.arange(0.0, 2 * self.P, H)
        xy = outline.point_at_arc(s)
        d = np.diff(np.vstack([xy, xy[:1]]), axis=0)[:-1]
        raw = np.arctan2(d[:, 1], d[:, 0])
        self.theta = raw[0] + np.concatenate([[0.0], np.cumsum((np.diff(raw) + np.pi) % (2 * np.pi) - np.pi)])
        self.s = s[:-1]

    def contact(self, start, theta0, turn):
        """Arc (mm, unwrapped) of the contact after ``turn`` (rad) from ``start`` laid at angle ``theta0``;
        None where the roll would leave the convex stretch (the chords' direction falls on the way)."""
        i0 = int(np.searchsorted(self.s, start))
        ahead = self.theta[i0:]
        j = int(np.argmax(ahead >= theta0 + turn - 1e-9))
        if ahead[j] < theta0 + turn - 1e-9 or np.any(np.diff(ahead[: j + 1]) < -1e-6):
            return None
        return float(self.s[i0 + j])


@pytest.fixture(scope="module")
def bracket():
    return load_outline(PARTS / "bracket.dxf")


@pytest.fixture(scope="module")
def rolling(bracket):
    return Rolling(bracket)


def roll_and_check(outline, rolling, start, theta0, sd=0.0, seed=0, max_steps=600):
    """Feed the filter a counter-clockwise roll; returns (mass, error mm, degrees rolled) at its first
    belief at 95% (or the end)."""
    flt = ContactFilter(outline, sd_position=max(sd, 0.01))
    rng = np.random.default_rng(seed)
    e0 = sd * rng.standard_normal()
    for k in range(1, max_steps + 1):
        c = rolling.contact(start, theta0, k * STEP)
        assert c is not None, "the test's roll must stay on a convex stretch"
        flt.update(c - start + sd * rng.standard_normal() - e0, k * STEP)
        if k % 5 == 0:
            b = flt.belief()
            if b.mass >= 0.95:
                break
    return b.mass, abs(float(outline.arc_offset(b.map_arc, c))), math.degrees(k * STEP)


@pytest.mark.parametrize(
    "start, where",
    [(75.0, "fillet"), (210.0, "fillet"), (100.0, "face"), (60.0, "face"), (230.0, "face")],
)
def test_noise_free_localization_from_fillets_and_faces(bracket, rolling, start, where):
    theta0 = float(bracket.tangent_angle_at_arc(start))
    mass, error, rolled = roll_and_check(bracket, rolling, start, theta0)
    assert mass >= 0.95 and error < 0.05, (where, mass, error, rolled)


@pytest.mark.parametrize("corner_index, fraction", [(0, 0.3), (0, 0.8), (4, 0.5)])
def test_noise_free_localization_from_a_corner_at_any_angle_within_its_jump(bracket, rolling, corner_index, fraction):
    # the jaw laid on a convex corner at an angle within the jump: it pivots there, then rolls on
    corner = bracket.corners[corner_index]
    assert corner.angle > 0
    theta0 = float(bracket.tangent_angle_at_arc(corner.arc, side="before")) + fraction * corner.angle
    mass, error, rolled = roll_and_check(bracket, rolling, corner.arc, theta0)
    assert mass >= 0.95 and error < 0.05, (corner, mass, error, rolled)


def test_with_reading_noise_the_stated_belief_holds_on_the_bracket(bracket, rolling):
    # 0.03 mm per reading: wherever it stops sure, it is right
    sure = 0
    for seed, start in enumerate((75.0, 100.0, 210.0, 230.0)):
        theta0 = float(bracket.tangent_angle_at_arc(start))
        mass, error, _ = roll_and_check(bracket, rolling, start, theta0, sd=0.03, seed=seed)
        if mass >= 0.95:
            sure += 1
            assert error < 0.3, (start, mass, error)
    assert sure >= 2


def test_a_corner_is_a_pivot_in_the_filters_tables(bracket, rolling):
    # the tables move a start at a convex corner nowhere until the jaw has turned through the jump,
    # and the reference agrees on random starts and turns along convex stretches
    flt = ContactFilter(bracket)
    t = flt.tracks
    corner = bracket.corners[0]
    at_corner = np.flatnonzero(np.abs(bracket.arc_offset(t.sigma, corner.arc)) < 1e-9)
    assert at_corner.size >= int(corner.angle / math.radians(0.2)) - 1  # one start per 0.2° of jaw angle
    rng = np.random.default_rng(5)
    checked = 0
    for _ in range(400):
        i = int(rng.choice(np.flatnonzero(t.convex)))
        turn = float(rng.uniform(0.0, math.radians(60)))
        ref = rolling.contact(float(t.sigma[i]), float(t.theta[i]), turn)
        if ref is None:
            continue
        arc, ok = t.advance(np.array([i]), turn)
        assert ok[0]
        assert abs(float(bracket.arc_offset(arc[0], ref))) < 0.03, (t.sigma[i], turn, arc[0], ref)
        checked += 1
    assert checked > 150


DATA = Path(__file__).resolve().parent / "data"


def replay_checks(name, **settings):
    """A recorded reactive rolling on a held-out drawing (bench.replay, cad-heldout.toml, `paper` noise)
    fed to a filter: at every fifth reading, (stated mass, error of its most probable contact against
    the true start's present contact on the model, mm, whether that contact sits on a pivot, the readings
    of each stretch quarantined so far)."""
    rec = json.loads((DATA / name).read_text())
    part = load_outline(DATA / rec["part"])
    flt = ContactFilter(part, **{**rec["settings"], **settings})
    true = int(np.argmin(np.abs(part.arc_offset(flt.grid, rec["start_arc"]))))
    out = []
    for call, args, kwargs in rec["calls"]:
        getattr(flt, call)(*args, **kwargs)
        if call == "update" and flt.steps % 5 == 0:
            b = flt.belief()
            truth = float(part.wrap_arc(flt.current[true]))
            pivot = bool(flt.tracks.pivot[flt.node[true]])
            taken = tuple(m.rows for m in flt.misfits)
            out.append((b.mass, abs(float(part.arc_offset(b.map_arc, truth))), pivot, taken))
    return out


def test_pivoting_on_a_corner_the_contact_is_the_corner():
    # dee-06, trial 36: the jaw pivots on the corner where the ellipse meets a face for 23°; the slope
    # term's offset at the last reading put the contact 0.36 mm beyond the corner, on the face, at a
    # stated 0.96. On a pivot the real contact is the corner: machining moves it along the normal only
    checks = replay_checks("cad-heldout-dee06-t36.json")
    on_pivot = [c for c in checks if c[2]]
    assert len(on_pivot) > 20
    assert max(c[1] for c in on_pivot) < 0.05
    assert not [c for c in checks if c[0] >= 0.95 and c[1] > 0.3]


def test_pruning_does_not_raise_the_stated_probability():
    # dee-10, trial 62: hypotheses 40 nats below the best under the slope prior carry the mass away
    # from the leader under the envelope's other priors; pruned under the first alone, they were gone
    # when the others were asked, and the filter said 0.986 at 0.56 mm off (0.011 without pruning)
    # (under the envelope's priors; the look-alike check, asked only where the belief would be sure, weighs
    # the starts they keep)
    pruned = replay_checks("cad-heldout-dee10-t62.json", lookalike_slope=0.0)
    full = replay_checks("cad-heldout-dee10-t62.json", prune=math.inf, lookalike_slope=0.0)
    assert len(pruned) == len(full) > 100
    # the same as long as both took the same stretches out (which stretch to take out is chosen among the
    # starts still live: the pruned filter may choose another, issue 29)
    same = [(a, b) for a, b in zip(pruned, full) if a[3] == b[3]]
    assert len(same) > 100
    assert max(abs(a[0] - b[0]) for a, b in same) < 1e-3
    assert not [c for c in full if c[0] >= 0.95 and c[1] > 0.3]
    assert not [c for c in pruned if c[0] >= 0.95 and c[1] > 0.3]
    checked = replay_checks("cad-heldout-dee10-t62.json")  # with the look-alike check: never sure and wrong
    assert len(checked) > 100 and not [c for c in checked if c[0] >= 0.95 and c[1] > 0.3]


def test_a_pure_pivot_does_not_choose_between_corners_that_both_allow_it():
    # plate-04 of cad-heldout-b, trial 62, its 321 calls recorded when it was sure and wrong (commit
    # afd8350, `python -m bench.replay bench/studies/cad-heldout-b.toml --level 0 --trial 62`): the jaw,
    # laid on the face just before a 64.3° corner, pivoted 60° on it with no contact travel. The plate's
    # 81.7° corner allows that pivot from more of its angles: under the uniform prior over a corner's
    # angles it leads (then 60:1 and sure, 94 mm off). Under the prior that lays the jaw at a corner's
    # ends the two corners are alike: the stated mass stays near a half while the pivot says nothing more
    uniform = replay_checks("cad-heldout-b-plate04-t62.json", corner_ends=False)
    ends = replay_checks("cad-heldout-b-plate04-t62.json")
    assert len(ends) == len(uniform) > 50
    far = [i for i, c in enumerate(uniform) if c[1] > 50.0]  # the look-alike corner leads
    assert len(far) > 40
    assert max(uniform[i][0] for i in far) > 0.7
    assert max(ends[i][0] for i in far) < 0.6
    assert not [c for c in ends if c[0] >= 0.95 and c[1] > 0.3]


@pytest.mark.parametrize("slopes", [FACE_SLOPES, 0.0])
def test_a_contact_just_past_a_machined_face_is_not_stated_sure_on_the_next_piece(monkeypatch, slopes):
    # plate-04 of cad-heldout-d, world-cad-d-clean trial 87 (96 recorded calls): the jaw tipped over a 46 mm
    # face and turned 0.18° past its angle. The model puts the contact 0.01 mm into the next fillet (r 8 mm);
    # the simulated rig's machined face, tilted more than that, still held the jaw 0.35 mm before the face's
    # end, and the filter said 1.00 there. Within a few machined slopes of the face's angle the contact
    # counts as anywhere on the face's end: not sure (with FACE_SLOPES 0, as before: sure and 0.36 mm off)
    monkeypatch.setattr(contact_marginal_module, "FACE_SLOPES", slopes)
    rec = json.loads((DATA / "cad-heldout-d-plate04-t87.json").read_text())
    part = load_outline(DATA / rec["part"])
    flt = ContactFilter(part, **rec["settings"])
    for call, args, kwargs in rec["calls"]:
        getattr(flt, call)(*args, **kwargs)
    b = flt.belief()
    off = abs(float(part.arc_offset(b.map_arc, rec["rig_truth_arc"])))
    assert off > 0.3  # the model's place is off the rig's: only the stated mass can be honest
    if slopes:
        assert b.mass < 0.5
    else:
        assert b.mass >= 0.95
