"""The estimate of a belief: the most probable point, or the middle of a flat top; its modes."""

import math
from types import SimpleNamespace

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from localizer.filters._belief import FLAT_TOP, find_modes, flat_top, most_probable


@given(st.integers(8, 400), st.integers(0, 399), st.integers(1, 60), st.integers(0, 2**32 - 1))
def test_a_flat_top_anywhere_on_the_circle_gives_its_middle(n, start, length, seed):
    """A run of equal weights (within a tenth of FLAT_TOP), through index 0 too, above a lower floor."""
    length = min(length, n - 2)
    start %= n
    rng = np.random.default_rng(seed)
    w = rng.uniform(0.0, 0.5, n)
    top = (start + np.arange(length)) % n
    w[top] = 1.0 - rng.uniform(0.0, 0.1 * FLAT_TOP, length)
    i = flat_top(w)
    # the middle, counted from the run's start round the circle (within one for an even run)
    assert abs((i - start) % n - (length - 1) / 2) <= 1.0


@given(st.lists(st.floats(0.0, 1.0), min_size=3, max_size=200))
def test_the_estimate_is_always_as_probable_as_the_most_probable_point(weights):
    w = np.asarray(weights)
    if w.max() <= 0:
        return
    assert w[flat_top(w)] >= w.max() * (1.0 - FLAT_TOP)


def test_a_single_peak_is_its_own_estimate():
    w = np.full(50, 0.01)
    w[17], w[18] = 1.0, 0.9
    assert flat_top(w) == 17


def test_weights_without_a_positive_top_give_the_argmax():
    assert flat_top(np.zeros(10)) == 0
    w = np.zeros(10)
    w[3] = np.nan
    assert flat_top(w) == 3


def modes_by_walking(perimeter, w, present, radius):
    """The modes as sets of bins: walk round the circle from each live bin, joining its live neighbours
    (mass above 1e-4 of the largest bin's)."""
    nb = max(8, int(perimeter / radius))
    b = np.minimum((present / perimeter * nb).astype(int), nb - 1)
    mass = np.zeros(nb)
    for k, wk in zip(b, w):
        mass[k] += wk
    live = {k for k in range(nb) if mass[k] > 1e-4 * mass.max()}
    groups, seen = [], set()
    for k in sorted(live):
        if k in seen:
            continue
        group, todo = set(), [k]
        while todo:
            j = todo.pop()
            if j in live and j not in group:
                group.add(j)
                todo += [(j - 1) % nb, (j + 1) % nb]
        seen |= group
        groups.append(group)
    out = []
    for group in groups:
        held = [h for h in range(len(w)) if b[h] in group]
        top = max(held, key=lambda h: (w[h], -h))  # the first of the most probable
        out.append((float(present[top]), sum(mass[k] for k in group), top))
    return sorted(out, key=lambda m: -m[1])


@given(st.integers(1, 300), st.floats(0.5, 20.0), st.integers(0, 2**32 - 1), st.floats(0.0, 0.9))
def test_the_modes_are_the_runs_of_live_bins_round_the_circle(n, radius, seed, dead):
    """Against a walk over the bins' neighbours: the same groups (one across the seam too), each with its
    mass and its most probable hypothesis."""
    perimeter = 200.0
    rng = np.random.default_rng(seed)
    present = rng.uniform(0.0, perimeter, n)
    w = rng.exponential(1.0, n) * (rng.uniform(size=n) >= dead)
    if w.sum() <= 0:
        return
    w /= w.sum()
    starts = rng.uniform(0.0, perimeter, n)
    got = find_modes(SimpleNamespace(perimeter=perimeter, name="ring"), w, present, starts, radius)
    want = modes_by_walking(perimeter, w, present, radius)
    assert len(got) == len(want)
    for mode, (arc, mass, top) in zip(got, want):
        assert mode.arc == arc and mode.start_arc == starts[top]
        assert math.isclose(mode.mass, mass, rel_tol=1e-12, abs_tol=1e-15)


@given(
    st.lists(st.sampled_from([0.0, 0.1, 0.25, 0.5, 1.0]) | st.floats(0.0, 1.0), min_size=1, max_size=200),
    st.integers(0, 12),
)
def test_the_most_probable_are_the_largest_first_equal_ones_by_index(weights, k):
    """Against a sort by (−weight, index): the same indices in the same order, ties and all."""
    w = np.asarray(weights)
    want = sorted(range(w.size), key=lambda i: (-w[i], i))[:k]
    assert most_probable(w, k).tolist() == want
