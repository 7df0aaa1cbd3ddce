"""percentiles() is np.percentile, bitwise, from one sort."""

import numpy as np
import pytest

from prsm_health.signals.percentiles import percentiles


@pytest.mark.parametrize("n", [1, 2, 7, 101, 10_000, 20_001])
def test_percentiles_are_numpys_bitwise(n):
    rng = np.random.default_rng(n)
    q = [0, 1, 2, 5, 12.5, 33.3, 50, 95, 98, 99, 99.99, 100]
    for x in (
        rng.standard_normal(n) * 1e3,
        np.round(rng.standard_normal(n), 1),  # ties
        np.cumsum(rng.standard_normal(n)),
    ):
        found, expected = percentiles(x, q), np.percentile(x, q)
        np.testing.assert_array_equal(found.view(np.int64), expected.view(np.int64))
        assert percentiles(x, [5, 95]).tolist() == np.percentile(x, [5, 95]).tolist()
