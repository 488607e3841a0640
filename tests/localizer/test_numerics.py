"""The shared numerics: the remainder of arc positions by the perimeter."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from localizer.geometry import mod_period

EDGES = st.sampled_from([0.0, -0.0, 1.0, -1.0, 5e-324, -5e-324, 1 - 2**-53, -(1 - 2**-53), 2 - 2**-52, 2.0, -1.5])


@given(
    st.floats(1e-6, 1e4),
    st.lists(st.one_of(st.floats(-1.0, 2.0), EDGES), min_size=1, max_size=300),
    st.one_of(st.floats(-3.0, 3.0), st.sampled_from([np.nan, np.inf, -np.inf])),
)
def test_the_remainder_is_numpys_to_the_bit(period, fractions, outlier):
    """Within a period of [0, period) and beyond it, the edges and −0 included: the same bits as np.mod."""
    x = np.asarray(fractions) * period
    for values in (x, np.tile(x, 64 // x.size + 1), np.r_[np.tile(x, 64 // x.size + 1), outlier * period]):
        with np.errstate(invalid="ignore"):  # NaN and infinities: NaN, as numpy says
            assert mod_period(values, period).tobytes() == np.mod(values, period).tobytes()
