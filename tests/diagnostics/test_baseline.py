"""A unit's own baseline (prsm_health.diagnostics.baseline): robust statistics against their
known values, exact JSON round trips. Pure numpy, no model. Its evidence and change statistic:
tests/monitoring/test_evidence.py."""

import json
import math

import numpy as np
import pytest

from prsm_health.core.errors import ParameterError
from prsm_health.diagnostics.baseline import (
    CENTRE_FLOOR,
    MAD_TO_SIGMA,
    Baseline,
    mad_factor,
    shrunk_scale,
)

# ----------------------------------------------------------------------------- Baseline


def test_fit_recovers_the_centre_and_scale_of_normal_indicators():
    rng = np.random.default_rng(7)
    n = 400
    truth = {"a": (2.0, 0.5), "b": (-30.0, 4.0), "c": (1e-5, 2e-7)}
    rows = [{k: rng.normal(mu, sd) for k, (mu, sd) in truth.items()} for _ in range(n)]
    b = Baseline.fit(rows)
    assert b.names == ("a", "b", "c") and b.count == n
    for name, centre, scale in zip(b.names, b.center, b.scale):
        mu, sd = truth[name]
        # standard errors of the median (1.2533 σ/√n) and of 1.4826·MAD (1.1664 σ/√n) of
        # normal samples; 4 of them: a miss by chance has probability < 1e-4
        assert abs(centre - mu) < 4 * 1.2533 * sd / math.sqrt(n)
        assert abs(scale - sd) < 4 * 1.1664 * sd / math.sqrt(n)


def test_mad_small_sample_factors_make_the_scale_unbiased():
    # Croux & Rousseeuw's b_n, checked by simulation: the mean of b_n·1.4826·MAD over many
    # normal samples of n is σ = 1 (20 000 samples: standard error < 0.005; tolerance 0.02)
    rng = np.random.default_rng(3)
    for n in (2, 3, 5, 12):
        x = rng.standard_normal((20_000, n))
        mad = np.median(np.abs(x - np.median(x, axis=1, keepdims=True)), axis=1)
        assert np.mean(mad_factor(n) * mad) == pytest.approx(1.0, abs=0.02)
    assert mad_factor(50) == pytest.approx(MAD_TO_SIGMA * 50 / 49.2)


def test_two_recordings_shrink_toward_the_prior():
    rows = [{"a": 0.0}, {"a": 2.0}]
    own = mad_factor(2) * 1.0  # median 1, both deviations 1
    b = Baseline.fit(rows, prior_scale={"a": 0.5}, prior_weight=3.0)
    # scaled inverse-χ² posterior: (ν0 σ0² + (n − 1) s²)/(ν0 + n − 1), n − 1 = 1
    assert b.center == (1.0,)
    assert b.scale[0] == pytest.approx(math.sqrt((3 * 0.25 + own**2) / 4), rel=1e-12)
    assert 0.5 < b.scale[0] < own
    # more recordings, less prior: 3 pseudo-recordings against 19 degrees of freedom
    assert shrunk_scale(2.0, 20, 0.5, 3.0) == pytest.approx(math.sqrt((0.75 + 19 * 4) / 22))
    # no prior: the unit's own spread; prior weight 0: the same
    assert Baseline.fit(rows).scale[0] == pytest.approx(own)
    assert Baseline.fit(rows, prior_scale={"a": 0.5}, prior_weight=0.0).scale[0] == (
        pytest.approx(own)
    )
    # one recording: the prior alone
    assert Baseline.fit([{"a": 3.0}], prior_scale={"a": 0.5}).scale == (0.5,)


def test_scale_is_never_zero():
    same = [{"a": 4.0, "z": 0.0}] * 3
    b = Baseline.fit(same)
    assert b.scale[0] == pytest.approx(CENTRE_FLOOR * 4.0)
    assert 0 < b.scale[1] < 1e-12  # identically 0, no prior: the smallest finite scale
    assert math.isfinite(b.change({"a": 4.0, "z": 1.0})["z"])
    # a prior of 0 or NaN carries no scale: the unit's own (then the floor)
    assert Baseline.fit(same, prior_scale={"a": 0.0, "z": math.nan}).scale == b.scale


def test_missing_values_are_ignored_per_indicator():
    rows = [{"a": 1.0, "b": None}, {"a": 2.0, "b": 5.0}, {"a": math.nan, "b": 7.0}]
    # default: the indicators finite in every row — none here (a is NaN once, b None once)
    with pytest.raises(ParameterError, match="names"):
        Baseline.fit(rows)
    b = Baseline.fit(rows, names=["a", "b", "c"])
    assert b.names == ("a", "b")  # c has no value at all
    assert b.center == (1.5, 6.0)


def test_change_and_distance_by_hand():
    b = Baseline(("a", "b", "c"), (1.0, 2.0, 0.0), (0.5, 2.0, 1.0), 3)
    z = b.change({"a": 2.0, "b": -2.0, "c": None, "other": 9.0})
    assert z["a"] == 2.0 and z["b"] == -2.0 and math.isnan(z["c"])
    assert list(z) == ["a", "b", "c"]
    assert b.distance({"a": 2.0, "b": -2.0}) == 2.0  # RMS of (2, −2)
    assert b.distance({"a": 1.0, "b": 2.0, "c": 3.0}) == pytest.approx(math.sqrt(3.0))
    assert b.distance({"a": 1.0, "b": 2.0, "c": 0.0}) == 0.0
    assert math.isnan(b.distance({"x": 1.0}))


def test_baseline_json_round_trip_is_exact():
    rng = np.random.default_rng(1)
    rows = [{"a": rng.normal(), "b": rng.normal(1e-6, 1e-7)} for _ in range(5)]
    b = Baseline.fit(rows, prior_scale={"a": 0.3}, recordings=list("vwxyz"))
    again = Baseline.from_json(json.loads(json.dumps(b.to_json())))
    assert again == b and again.recordings == tuple("vwxyz")


@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(rows=[]), "rows"),
        (dict(rows=[{"a": 1.0}], recordings=["x", "y"]), "recordings"),
        (dict(rows=[{"a": 1.0}], prior_weight=-1.0), "prior_weight"),
    ],
)
def test_fit_refuses_bad_input_naming_the_field(kwargs, field):
    rows = kwargs.pop("rows")
    with pytest.raises(ParameterError, match=field):
        Baseline.fit(rows, **kwargs)
