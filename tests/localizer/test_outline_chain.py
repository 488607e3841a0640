"""Disambiguation over chains of rolls on outlines with corners: against a brute-force reference
(every start every 0.05 mm, the turns from a dense polyline's chords), on corners (pivots) and on
continua (faces the rolls cannot tell apart)."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from localizer import Line, elliptical_arc, load_outline, localize, outline_from_pieces

from .reference import ChordAngle

PARTS = Path(__file__).resolve().parents[2] / "parts"


def half_ellipse():
    arcs = elliptical_arc((0.0, 0.0), (40.0, 0.0), (0.0, 15.0), -0.5 * math.pi, math.pi)
    return outline_from_pieces([*arcs, Line((-40.0, 0.0), (0.0, 0.0)), Line((0.0, 0.0), (0.0, -15.0))])


def off(outline, a, b):
    P = outline.perimeter
    return abs((a - b + P / 2) % P - P / 2)


def near_piece_ends(outline, sigma, margin):
    return min(off(outline, float(s), float(e)) for s in np.atleast_1d(sigma) for e in outline.starts[:-1]) < margin


@pytest.mark.parametrize(("name", "identifiable"), [("profile.svg", 0), ("half-ellipse", 3)])
def test_noise_free_chains_against_brute_force(name, identifiable):
    """Complete (the truth among the candidates) and sound (every probable candidate fits the
    reference) on random chains; where the reference leaves one place only, sure of it. On the
    profile every chain drawn here has a look-alike at a corner (a partial pivot), so none is
    identifiable; on the half-ellipse at least three of ten are (counted from the reference)."""
    outline = half_ellipse() if name == "half-ellipse" else load_outline(PARTS / name)
    ref = ChordAngle(outline)
    P = outline.perimeter
    grid = np.arange(0.0, P, 0.05)
    rng = np.random.default_rng(2005)
    unique = tried = 0
    while tried < 10:
        s0, lengths = rng.uniform(0, P), rng.uniform(8.0, 25.0, size=2)
        pos = s0 + np.concatenate([[0.0], np.cumsum(lengths)])
        if near_piece_ends(outline, pos, 0.5):
            continue
        tried += 1
        turns = np.diff(ref(pos))
        # the reference: every start on the grid whose two rolls can turn as measured, each end
        # anywhere within half a grid step (so a corner there may be at any angle of its jump)
        g = grid[:, None] + np.concatenate([[0.0], np.cumsum(lengths)])[None, :]
        win = ref(g[..., None] + np.linspace(-0.025, 0.025, 11))
        lo, hi = win.min(axis=-1), win.max(axis=-1)
        fits = np.all((turns > lo[:, 1:] - hi[:, :-1] - 3e-3) & (turns < hi[:, 1:] - lo[:, :-1] + 3e-3), axis=1)
        ends = np.mod(g[fits, -1], P)
        assert ends.size, "the truth itself must fit the reference"
        alone = all(off(outline, e, pos[-1]) < 0.5 for e in ends)
        chain = list(zip(lengths, turns))
        lik = localize(outline, chain, sd_length=0.02)
        paper = localize(outline, chain, rule="paper")
        for result in (lik, paper):
            # complete: the truth is among the candidates (within min_separation, one per 0.5 mm of a
            # stretch the rolls leave unresolved)
            assert min(off(outline, c.end_arc, pos[-1]) for c in result.candidates) < 0.5
            # sound: every candidate the rule keeps ends where the reference fits
            for c in result.candidates:
                if c.probability > 0.01:
                    assert min(off(outline, c.end_arc, e) for e in ends) < 0.5
        if alone:
            unique += 1
            assert off(outline, lik.best.end_arc, pos[-1]) < 0.05 and not lik.ambiguous
            assert off(outline, paper.best.end_arc, pos[-1]) < 0.05
        else:
            assert lik.ambiguous or off(outline, lik.best.end_arc, pos[-1]) < 0.05
    assert unique >= identifiable


def rectangle(w=60.0, h=40.0):
    pts = [(0, 0), (w, 0), (w, h), (0, h)]
    return outline_from_pieces([Line(pts[i], pts[(i + 1) % 4]) for i in range(4)])


@pytest.mark.parametrize("rule", ["likelihood", "paper"])
def test_a_pivot_on_a_corner_is_an_interval_of_turn(rule):
    """Roll 10 mm to a corner turning 0.5 rad of its quarter turn, then the rest of it and 45 mm
    along the next face: only the two corners followed by a 60 mm face fit, each at its corner."""
    box = rectangle()
    chain = [(10.0, 0.5), (45.0, math.pi / 2 - 0.5)]
    result = localize(box, chain, rule=rule, sd_length=0.02)
    corners_before_long_face = [c.arc for c in box.corners if math.isclose(c.arc % 100.0, 0.0, abs_tol=1e-9)]
    want = sorted((c + 45.0) % box.perimeter for c in corners_before_long_face)
    kept = sorted(c.end_arc for c in result.candidates if c.probability > 0.01)
    assert len(kept) == 2
    assert kept == pytest.approx(want, abs=0.05)
    assert result.ambiguous  # the rectangle's half-turn symmetry


@pytest.mark.parametrize("rule", ["likelihood", "paper"])
def test_rolls_along_one_face_are_not_sure(rule):
    """Two rolls that stay on a 60 mm face fit every start along it: never a confident answer."""
    box = rectangle()
    result = localize(box, [(5.0, 0.0), (5.0, 0.0)], rule=rule, sd_length=0.02)
    assert result.ambiguous
    assert result.best.probability < 0.5


def test_noisy_chains_keep_the_truth_and_are_sure_only_when_right():
    """Readings with the noise the rule is told (0.05 mm on each length, the encoder's 0.03° on each
    turn): the truth keeps some probability, and a confident answer is right."""
    outline = half_ellipse()
    P = outline.perimeter
    rng = np.random.default_rng(11)
    sd_length, sd_turn = 0.05, math.radians(0.03)
    sure = 0
    for _ in range(8):
        s0, lengths = rng.uniform(0, P), rng.uniform(8.0, 25.0, size=2)
        pos = s0 + np.concatenate([[0.0], np.cumsum(lengths)])
        turns = np.diff(outline.tangent_angle_at_arc(pos))
        chain = list(zip(lengths + rng.normal(0, sd_length, 2), turns + rng.normal(0, sd_turn, 2)))
        result = localize(outline, chain, sd_length=sd_length, sd_turn=sd_turn)
        near = [c for c in result.candidates if off(outline, c.end_arc, pos[-1]) < 0.5]
        assert near and max(c.probability for c in near) > 1e-3
        if not result.ambiguous:
            sure += 1
            assert off(outline, result.best.end_arc, pos[-1]) < 0.5
    assert sure >= 1


CHAINS = json.loads((Path(__file__).parent / "data" / "outline-chains-8b9ee9b.json").read_text())


def _chain_case(case):
    outline = load_outline(PARTS.parent / case["part"])
    sign = 1.0 if case["direction"] == "ccw" else -1.0
    return outline, tuple((float(L), float(w)) for L, w in case["rolls"]), sign


@pytest.mark.parametrize("k", range(0, len(CHAINS), 3))
def test_the_sums_relative_to_the_largest_source_are_the_sums_in_logarithms(k):
    """The likelihood rule's fast sums (relative to each roll's largest source, far-off turns not weighed)
    against every way weighed in logarithms: the same posterior within 1e-12 on recorded chains, noise-free
    and noisy, either direction, sd_length 0.5 and 0.05 mm, on the shipped drawings."""
    from localizer.chain import chain_forward

    case = CHAINS[k]
    outline, chain, sign = _chain_case(case)
    posterior = []
    for exact in (False, True):
        f = chain_forward(outline, chain, sign, case["sd_length"], math.radians(0.03), exact=exact)
        w = np.exp(f.log_alpha - f.log_alpha.max())
        posterior.append(w / w.sum())
    assert np.abs(posterior[0] - posterior[1]).max() <= 1e-12


def test_a_chain_that_fits_almost_nowhere_is_summed_in_logarithms():
    """A first roll turning 2 rad in 20 mm, which no stretch of the bracket does, pivots included: the fast
    sums lose every state, and the rule sums the chain again in logarithms, giving what every way weighed
    gives (a posterior, however poor the fit, for the fit test to refuse)."""
    from localizer.chain import chain_forward

    outline = load_outline(PARTS / "bracket.dxf")
    chain = ((20.0, 2.0), (15.0, 0.0))
    fast = chain_forward(outline, chain, 1.0, 0.5, math.radians(0.03))
    slow = chain_forward(outline, chain, 1.0, 0.5, math.radians(0.03), exact=True)
    assert fast is not None and slow is not None
    assert np.isfinite(fast.log_alpha).any()
    assert np.array_equal(fast.log_alpha, slow.log_alpha)


def test_the_likelihood_rule_on_drawings_gives_what_it_gave_before_it_was_compiled():
    """Recorded results of the likelihood rule (numpy, commit 8b9ee9b: 16 chains on each shipped drawing).
    The fit test's p-value within 1e-9; where one candidate held ≥ 0.2 alone, the same place and
    probability; elsewhere (continua along faces, split into candidates by ties) the probability within
    every 5 mm of the boundary within 0.03."""
    for case in CHAINS:
        outline, chain, sign = _chain_case(case)
        got = localize(outline, chain, direction=case["direction"], sd_length=case["sd_length"])
        assert got.fit_pvalue == pytest.approx(case["fit_pvalue"], rel=1e-9, abs=1e-12)
        old = case["candidates"]
        probs = sorted((c["probability"] for c in old), reverse=True)
        if probs[0] >= 0.2 and (len(probs) == 1 or probs[1] < probs[0] - 1e-6):
            assert got.best.probability == pytest.approx(probs[0], abs=1e-9)
            assert off(outline, got.best.end_arc, old[0]["end_arc"]) < 1e-6
        bins = int(math.ceil(outline.perimeter / 5.0))

        def mass(ends, p, bins=bins):
            return np.bincount((np.asarray(ends) // 5.0).astype(int) % bins, weights=p, minlength=bins)

        before = mass([c["end_arc"] for c in old], [c["probability"] for c in old])
        after = mass([c.end_arc for c in got.candidates], [c.probability for c in got.candidates])
        assert np.abs(before - after).max() <= 0.03
