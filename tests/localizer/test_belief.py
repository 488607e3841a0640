"""The estimate of a belief: the most probable point, or the middle of a flat top."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from localizer.filters._belief import FLAT_TOP, flat_top


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
