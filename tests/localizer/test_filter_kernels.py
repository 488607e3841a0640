"""The grid filter's compiled gather against numpy's own indexing."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from localizer.filters._filter_kernels import gather


@settings(max_examples=60, deadline=None)
@given(
    m=st.integers(1, 12),
    n=st.integers(1, 40),
    seed=st.integers(0, 2**32 - 1),
    data=st.data(),
)
def test_the_gather_is_numpys_indexing(m, n, seed, data):
    a = np.random.default_rng(seed).normal(size=(m, n))
    rows = np.array(data.draw(st.lists(st.integers(0, m - 1), max_size=m)), dtype=np.int64)
    cols = np.array(data.draw(st.lists(st.integers(0, n - 1), max_size=n)), dtype=np.int64)
    out = gather(a, rows, cols)
    assert out.shape == (rows.size, cols.size)
    assert np.array_equal(out, a[np.ix_(rows, cols)])
