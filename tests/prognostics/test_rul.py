"""Prognostics: RUL from a history of diagnoses (prsm_health.prognostics.rul).

The fleets are synthetic, drawn here from the exponential degradation model of Gebraeel et al.
(2005) with known parameters; the expected accuracy is derived from the noise level (a
Cramér-Rao bound), not from the code's own output.
"""

import json
import math

import numpy as np
import pandas as pd
import pytest
from scipy.special import erf

from prsm_health.core.errors import ParameterError, PRSMHealthError
from prsm_health.prognostics import (
    HISTORY_COLUMNS,
    HORIZON_FACTOR,
    HistoryError,
    Prognosis,
    RULModel,
    load_prognostics_model,
    prognose,
    read_history,
    save_prognostics_model,
    validate_history,
)
from prsm_health.prognostics.metrics import evaluate_units

Z90 = 1.6448536269514722
THRESHOLD = 30e-6
# The generating exponential model S(t) = PHI0 + exp(ln_theta + beta t) + measurement noise.
PHI0 = 8e-6
LN_THETA, SD_LN_THETA = math.log(2e-6), 0.15
BETA, SD_BETA = 2.4e-4, 0.15 * 2.4e-4  # [1/h]: lives around ln(22/2)/2.4e-4 ~ 10 000 h
SD_RANGE = (0.2e-6, 0.5e-6)  # measurement standard deviation of a diagnosis [m]


def _rows(uid, ages, estimate, sd):
    return pd.DataFrame(
        {
            "unit_id": uid,
            "age_hours": ages,
            "clearance": estimate,
            "clearance_lower": estimate - Z90 * sd,
            "clearance_upper": estimate + Z90 * sd,
        }
    )


def exponential_fleet(n_units=20, n_points=30, seed=0, first_id=0, sd_range=SD_RANGE):
    """Histories (30 diagnoses over each unit's life), failure ages and the true parameters."""
    rng = np.random.default_rng(seed)
    parts, lives, truth = [], {}, {}
    for uid in range(first_id, first_id + n_units):
        ln_theta = LN_THETA + SD_LN_THETA * rng.standard_normal()
        beta = BETA + SD_BETA * rng.standard_normal()
        life = (math.log(THRESHOLD - PHI0) - ln_theta) / beta
        ages = np.linspace(0.0, life, n_points, endpoint=False)
        sd = rng.uniform(*sd_range, n_points)
        estimate = PHI0 + np.exp(ln_theta + beta * ages) + sd * rng.standard_normal(n_points)
        parts.append(_rows(uid, ages, estimate, sd))
        lives[uid] = life
        truth[uid] = (ln_theta, beta, ages, sd)
    return pd.concat(parts, ignore_index=True), lives, truth


def linear_fleet(n_units=12, n_points=20, seed=0, sd=0.3e-6, first_id=0):
    """S(t) = c0 + slope t: failure at (THRESHOLD - c0) / slope."""
    rng = np.random.default_rng(seed)
    parts, lives, truth = [], {}, {}
    for uid in range(first_id, first_id + n_units):
        c0 = 10e-6 + 0.5e-6 * rng.standard_normal()
        slope = 2e-9 * (1 + 0.15 * rng.standard_normal())  # [m/h]
        life = (THRESHOLD - c0) / slope
        ages = np.linspace(0.0, life, n_points, endpoint=False)
        sds = np.full(n_points, sd)
        estimate = c0 + slope * ages + sds * rng.standard_normal(n_points)
        parts.append(_rows(uid, ages, estimate, sds))
        lives[uid] = life
        truth[uid] = (c0, slope)
    return pd.concat(parts, ignore_index=True), lives, truth


def history_of(histories, uid, rows=None):
    h = histories[histories["unit_id"] == uid].drop(columns="unit_id").reset_index(drop=True)
    return h if rows is None else h.iloc[:rows]


@pytest.fixture(scope="module")
def fleet_model():
    histories, lives, _ = exponential_fleet(seed=0)
    return RULModel().fit(histories, lives)


@pytest.fixture(scope="module")
def held_out(fleet_model):
    histories, lives, truth = exponential_fleet(seed=1, first_id=100)
    predictions, summary = evaluate_units(histories, lives, fleet_model)
    return histories, lives, truth, predictions, summary


def _crb_rul_sd(ln_theta, beta, ages, sd):
    """Bayesian Cramér-Rao bound of the crossing age's standard deviation [h].

    Fisher information of (ln theta, beta) from diagnoses S_j = PHI0 + exp(ln theta + beta t_j)
    + N(0, sd_j^2), plus the population prior's information; crossing
    T = (ln(THRESHOLD - PHI0) - ln theta) / beta, gradient (-1/beta, -T/beta).
    """
    g = np.exp(ln_theta + beta * ages)
    x = np.column_stack([g, ages * g]) / sd[:, None]
    info = x.T @ x + np.diag([SD_LN_THETA**-2, SD_BETA**-2])
    life = (math.log(THRESHOLD - PHI0) - ln_theta) / beta
    grad = np.array([-1.0 / beta, -life / beta])
    return math.sqrt(grad @ np.linalg.solve(info, grad))


# --------------------------------------------------------------------------------------------
# Fleet performance
# --------------------------------------------------------------------------------------------


def test_degradation_alpha_lambda_after_half_life_beats_noise_derived_bound(held_out):
    _, lives, truth, predictions, summary = held_out
    alpha = 0.2
    # Expected accuracy from the noise level: for each prediction after half of life, an
    # unbiased estimator with twice the Cramér-Rao standard deviation (room for the estimated
    # baseline phi, prior and noise model) lands inside (1 +- alpha) r* with probability
    # erf(alpha r* / (2 sqrt(2) sd_crb)).
    chances = []
    for uid, (ln_theta, beta, ages, sd) in truth.items():
        for k in range(2, len(ages) + 1):
            age = ages[k - 1]
            if age >= 0.5 * lives[uid]:
                rul_sd = _crb_rul_sd(ln_theta, beta, ages[:k], sd[:k])
                chances.append(erf(alpha * (lives[uid] - age) / (2 * math.sqrt(2) * rul_sd)))
    expected = float(np.mean(chances))
    # Predictions of one unit are correlated: take the number of units (20) as the sample size
    # and allow 3 binomial standard deviations below the expectation (~0.90 - 0.2 = ~0.7).
    bound = expected - 3 * math.sqrt(expected * (1 - expected) / len(truth))
    deg = predictions[predictions["method"] == "degradation"]
    late = deg[deg["age_hours"] >= 0.5 * (deg["age_hours"] + deg["true_rul"])]
    inside = np.abs(late["estimate"] - late["true_rul"]) <= alpha * late["true_rul"]
    assert len(late) == len(chances)
    assert inside.mean() >= bound, (inside.mean(), bound)
    assert summary["degradation"]["alpha_lambda"] == pytest.approx(inside.mean())


def test_degradation_intervals_cover_true_rul(held_out):
    _, _, _, predictions, _ = held_out
    deg = predictions[predictions["method"] == "degradation"]
    covered = (deg["lower"] <= deg["true_rul"]) & (deg["true_rul"] <= deg["upper"])
    # Nominal 0.9 over 580 predictions (20 units x 29 prefixes). Independent predictions would
    # give a binomial sd of 0.012; predictions of one unit are correlated, so take the 20
    # units as the effective sample: sd sqrt(0.9 * 0.1 / 20) = 0.067, and 0.8 is 1.5 such sd
    # below nominal while an interval without the posterior's spread (point mass) covers ~0.
    assert covered.mean() >= 0.8, covered.mean()
    assert (deg["lower"] >= 0).all() and (deg["lower"] <= deg["estimate"]).all()
    assert (deg["estimate"] <= deg["upper"]).all()


def test_similarity_baseline_beats_the_fleet_average(held_out, fleet_model):
    _, lives, _, predictions, summary = held_out
    sim = predictions[predictions["method"] == "similarity"]
    assert set(sim["model"]) == {"similarity"}
    late = sim[sim["age_hours"] >= 0.5 * (sim["age_hours"] + sim["true_rul"])]
    # The naive prognosis a user has without a model: the training fleet's mean life - age.
    naive = np.mean(fleet_model.failure_ages_) - late["age_hours"]
    naive_rmse = math.sqrt(np.mean((naive - late["true_rul"]) ** 2))
    sim_rmse = math.sqrt(np.mean((late["estimate"] - late["true_rul"]) ** 2))
    assert sim_rmse < 0.6 * naive_rmse, (sim_rmse, naive_rmse)
    naive_inside = np.mean(np.abs(naive - late["true_rul"]) <= 0.2 * late["true_rul"])
    assert summary["similarity"]["alpha_lambda"] > naive_inside
    # Its interval is the spread of the library units' remaining lives only (no model of the
    # unit's own scatter), so less than nominal; still far from a point estimate's ~0.
    assert summary["similarity"]["coverage"] >= 0.7
    # The Bayesian model, which uses the unit's own trend, is the better one after half life.
    assert summary["degradation"]["rmse_after"] < summary["similarity"]["rmse_after"]


def test_similarity_finds_the_library_unit_a_history_repeats():
    # Precise diagnoses (0.05 µm): the history of the fleet's fastest-wearing unit matches its
    # own library curve far better than any other, so the kernel weights single it out and the
    # RUL is its remaining life; the fleet's median remaining life at that age is far off.
    histories, lives, _ = exponential_fleet(n_units=12, seed=8, sd_range=(0.04e-6, 0.06e-6))
    model = RULModel(method="similarity").fit(histories, lives)
    fastest = min(lives, key=lives.get)
    history = history_of(histories, fastest, rows=20)
    age = history["age_hours"].iloc[-1]
    p = model.predict(history)
    assert p.model["nearest_unit"] == fastest
    assert p.model["effective_units"] < 6
    true = lives[fastest] - age
    assert abs(p.rul_hours["estimate"] - true) < 0.05 * true
    assert abs(np.median(list(lives.values())) - age - true) > 0.2 * true


def test_form_selection_follows_the_generating_model(fleet_model):
    assert fleet_model.form_ == "exponential"
    assert fleet_model.loo_rmse_["exponential"] < fleet_model.loo_rmse_["linear"]
    histories, lives, _ = linear_fleet(seed=3)
    linear = RULModel().fit(histories, lives)
    assert linear.form_ == "linear"
    # the profile-likelihood baseline recovers the generating one (PHI0) to a few % of the rise
    phi = fleet_model.forms_["exponential"]["phi"]
    assert abs(phi - PHI0) < 0.05 * (THRESHOLD - PHI0), phi


def test_similarity_aligns_on_the_linear_form_too():
    # a model whose chosen form is linear aligns the history on its units' straight lines
    # (regression: that branch once shadowed the curve function and raised UnboundLocalError)
    histories, lives, _ = linear_fleet(seed=3)
    model = RULModel().fit(histories, lives)
    assert model.form_ == "linear"
    unit = histories[histories["unit_id"] == 0].drop(columns="unit_id").iloc[:10]
    p = model.predict(unit, method="similarity")
    assert p.model["form"] == "linear" and p.model["nearest_unit"] == 0  # itself, in-sample
    assert 0 <= p.rul_hours["lower"] <= p.rul_hours["estimate"] <= p.rul_hours["upper"]


# --------------------------------------------------------------------------------------------
# Analytic checks
# --------------------------------------------------------------------------------------------


def test_noiseless_linear_history_gives_the_exact_crossing():
    histories, lives, _ = linear_fleet(seed=4, sd=0.0)
    model = RULModel().fit(histories, lives)
    slope, c0 = 2.3e-9, 10.5e-6
    ages = np.linspace(0.0, 3000.0, 9)
    value = c0 + slope * ages
    history = pd.DataFrame(
        {"age_hours": ages, "clearance": value, "clearance_lower": value, "clearance_upper": value}
    )
    expected = (THRESHOLD - value[-1]) / slope
    for method in ("degradation-linear", "degradation"):  # the fit picks linear on this fleet
        p = model.predict(history, method=method)
        assert p.model["name"] == "degradation-linear"
        for key in ("estimate", "lower", "upper"):
            assert p.rul_hours[key] == pytest.approx(expected, rel=1e-6)
        assert p.model["posterior_mean"] == pytest.approx([c0, slope], rel=1e-6)


def test_posterior_collapses_to_the_truth_as_the_history_grows():
    histories, lives, _ = linear_fleet(seed=5)
    model = RULModel(method="degradation-linear").fit(histories, lives)
    rng = np.random.default_rng(7)
    c0, slope, sd = 9.7e-6, 1.8e-9, 0.3e-6
    sds, errors = [], []
    for n in (10, 100, 10000):
        ages = np.linspace(0.0, 6000.0, n)
        value = c0 + slope * ages + sd * rng.standard_normal(n)
        history = _rows(0, ages, value, np.full(n, sd)).drop(columns="unit_id")
        p = model.predict(history)
        mean = np.array(p.model["posterior_mean"])
        cov = np.array(p.model["posterior_cov"])
        sds.append(np.sqrt(np.diag(cov)))
        errors.append(np.abs(mean - [c0, slope]) / np.sqrt(np.diag(cov)))
    sds = np.array(sds)
    # the standard deviations shrink like 1/sqrt(n) once the data outweigh the prior: x10 per
    # 100x data; allow a factor 2 either way
    assert np.all(sds[1] / sds[2] > 10 / 2) and np.all(sds[1] / sds[2] < 10 * 2)
    assert np.all(sds[2] < 0.02 * np.array([c0, slope]))
    assert np.all(np.array(errors) < 4.0)  # the truth stays within 4 posterior sd


def test_threshold_already_crossed_gives_zero_with_a_warning(fleet_model):
    ages = np.array([0.0, 4000.0, 8000.0, 9000.0])
    value = np.array([10e-6, 13e-6, 24e-6, 31e-6])
    history = _rows(0, ages, value, np.full(4, 0.3e-6)).drop(columns="unit_id")
    for method in ("degradation", "similarity"):
        p = fleet_model.predict(history, method=method)
        assert p.rul_hours == {"estimate": 0.0, "lower": 0.0, "upper": 0.0}
        assert any("threshold already crossed" in w for w in p.warnings)


def test_no_wear_trend_is_capped_at_the_horizon_with_warnings(fleet_model):
    ages = np.linspace(0.0, 3000.0, 12)
    value = np.linspace(10.5e-6, 9.5e-6, 12)  # decreasing, noiseless: wear rate <= 0
    history = pd.DataFrame(
        {"age_hours": ages, "clearance": value, "clearance_lower": value, "clearance_upper": value}
    )
    p = fleet_model.predict(history)
    horizon = HORIZON_FACTOR * max(fleet_model.failure_ages_)
    assert p.rul_hours["upper"] == pytest.approx(horizon)
    assert any("health indicator decreasing" in w for w in p.warnings)
    assert any("capped" in w and "horizon" in w for w in p.warnings)


def test_predictions_at_prefixes_use_only_the_rows_up_to_them(held_out, fleet_model):
    histories, *_ = held_out
    history = history_of(histories, 100)
    prefixes = fleet_model.predict_prefixes(history)
    assert len(prefixes) == len(history) - 1
    for k in (2, 11, 30):
        alone = fleet_model.predict(history.iloc[:k])
        assert prefixes[k - 2].rul_hours == alone.rul_hours
        sim = fleet_model.predict(history.iloc[:k], method="similarity")
        assert fleet_model.predict_prefixes(history, "similarity")[k - 2].rul_hours == sim.rul_hours


def test_prognosis_json_contract(fleet_model, held_out):
    histories, *_ = held_out
    history = history_of(histories, 101, rows=12)
    for method, name in (("degradation", "degradation-exponential"), ("similarity", "similarity")):
        p = prognose(history, fleet_model, method=method)
        assert isinstance(p, Prognosis)
        d = json.loads(json.dumps(p.as_dict(), allow_nan=False))
        assert set(d) == {"rul_hours", "health_indicator", "model", "warnings", "headline"}
        assert set(d["rul_hours"]) == {"estimate", "lower", "upper"}
        assert 0 <= d["rul_hours"]["lower"] <= d["rul_hours"]["estimate"] <= d["rul_hours"]["upper"]
        hi = d["health_indicator"]
        assert hi["name"] == "clearance" and hi["unit"] == "m" and hi["threshold"] == THRESHOLD
        assert hi["ages_hours"] == history["age_hours"].tolist()
        assert hi["values"] == history["clearance"].tolist()
        assert hi["lower"] == pytest.approx(history["clearance_lower"].tolist())
        assert hi["upper"] == pytest.approx(history["clearance_upper"].tolist())
        assert hi["current"] == history["clearance"].iloc[-1]
        assert d["model"]["name"] == name
        assert d["model"]["design"] == "paper01" and d["model"]["units_trained"] == 20
        assert isinstance(d["model"]["version"], str)
        assert isinstance(d["warnings"], list)


# --------------------------------------------------------------------------------------------
# Bad input
# --------------------------------------------------------------------------------------------


def _good(n=4):
    ages = np.arange(n) * 100.0
    value = 10e-6 + ages * 1e-9
    return pd.DataFrame(
        {
            "age_hours": ages,
            "clearance": value,
            "clearance_lower": value - 0.5e-6,
            "clearance_upper": value + 0.5e-6,
        }
    )


def _with(column, row, value):
    def make():
        h = _good()
        if isinstance(value, str):
            h[column] = h[column].astype(object)
        h.loc[row, column] = value
        return h

    return make


BAD_HISTORIES = {
    "one row": (lambda: _good(1), "at least 2 diagnoses over operating hours; the history has 1"),
    "no rows": (lambda: _good(0), "the history has 0"),
    "repeated hours": (_with("age_hours", 2, 100.0), "strictly increasing; row 2"),
    "decreasing hours": (_with("age_hours", 3, 50.0), "strictly increasing; row 3"),
    "negative hours": (_with("age_hours", 0, -1.0), "age_hours must be >= 0"),
    "nan clearance": (_with("clearance", 1, np.nan), "clearance must be a finite number; row 1"),
    "inf upper": (_with("clearance_upper", 2, np.inf), "clearance_upper must be a finite"),
    "text age": (_with("age_hours", 1, "soon"), "age_hours must be a finite number; row 1"),
    "lower above upper": (
        _with("clearance_lower", 2, 20e-6),
        "clearance_lower > clearance_upper in row 2",
    ),
    "missing column": (
        lambda: _good().drop(columns="clearance_upper"),
        "lacks column(s) clearance_upper",
    ),
    "mixed designs": (lambda: _good().assign(design=["paper01", "paper02"] * 2), "mixes designs"),
    "other design": (
        lambda: _good().assign(design="paper03"),
        "history is of design 'paper03', the prognostics model of 'paper01'",
    ),
    "two units": (lambda: _good().assign(unit_id=[1, 1, 2, 2]), "mixes units"),
    "not a table": (lambda: _good().to_dict(), "must be a pandas DataFrame"),
}


@pytest.mark.parametrize("case", sorted(BAD_HISTORIES))
def test_bad_histories_are_refused_in_one_line(case, fleet_model):
    make, words = BAD_HISTORIES[case]
    with pytest.raises(ParameterError) as info:
        validate_history(make(), fleet_model)
    message = str(info.value)
    assert "\n" not in message and words in message, message
    with pytest.raises(HistoryError):
        prognose(make(), fleet_model)


def test_validate_history_returns_a_clean_copy():
    h = _good().assign(design="paper01", fault_class="healthy")
    h.index = [10, 11, 12, 13]
    clean = validate_history(h)
    assert list(clean.index) == [0, 1, 2, 3]
    assert all(clean[c].dtype == np.float64 for c in HISTORY_COLUMNS)
    assert list(clean["fault_class"]) == ["healthy"] * 4
    clean.loc[0, "clearance"] = 1.0
    assert h["clearance"].iloc[0] != 1.0


def test_fit_refusals():
    histories, lives, _ = linear_fleet(n_units=3, n_points=5, seed=6)
    with pytest.raises(ParameterError, match="at least 3 training units"):
        RULModel().fit(histories[histories["unit_id"] < 2], lives)
    with pytest.raises(ParameterError, match="no failure age"):
        RULModel().fit(histories, {0: lives[0], 1: lives[1]})
    with pytest.raises(ParameterError, match="unit 1: .*strictly increasing"):
        bad = histories.copy()
        bad.loc[bad.index[bad["unit_id"] == 1][2], "age_hours"] = 0.0
        RULModel().fit(bad, lives)
    with pytest.raises(ParameterError, match="threshold"):
        RULModel(threshold=5e-6).fit(histories, lives)
    with pytest.raises(ParameterError, match="method"):
        RULModel(method="oracle").fit(histories, lives)
    with pytest.raises(ParameterError, match="n_samples"):
        RULModel(n_samples=10).fit(histories, lives)
    with pytest.raises(PRSMHealthError, match="not fitted"):
        RULModel().predict(_good())


# --------------------------------------------------------------------------------------------
# Files and persistence
# --------------------------------------------------------------------------------------------


def test_read_history_csv_and_parquet(tmp_path):
    h = _good().assign(design="paper01")
    h.to_csv(tmp_path / "h.csv", index=False)
    h.to_parquet(tmp_path / "h.parquet")
    for name in ("h.csv", "h.parquet"):
        back = read_history(tmp_path / name)
        pd.testing.assert_frame_equal(back[list(HISTORY_COLUMNS)], h[list(HISTORY_COLUMNS)])


@pytest.mark.parametrize(
    ("name", "content", "words"),
    [
        ("missing.csv", None, "no such file"),
        ("h.txt", "age_hours\n1\n", "unknown suffix"),
        ("h.parquet", "not parquet at all", "cannot read history"),
        (
            "h.csv",
            "age_hours,clearance\n1,2e-5\n",
            "lacks column(s) clearance_lower, clearance_upper",
        ),
    ],
)
def test_read_history_errors_name_the_file(tmp_path, name, content, words):
    path = tmp_path / name
    if content is not None:
        path.write_text(content)
    with pytest.raises(PRSMHealthError) as info:
        read_history(path)
    message = str(info.value)
    assert "\n" not in message and words in message and name in message, message


def test_dict_and_file_round_trips_give_identical_predictions(fleet_model, held_out, tmp_path):
    histories, *_ = held_out
    history = history_of(histories, 102, rows=15)
    d = fleet_model.to_dict()
    text = json.dumps(d, allow_nan=False)  # plain JSON
    rebuilt = RULModel.from_dict(json.loads(text))
    path = save_prognostics_model(tmp_path / "prognostics.json", fleet_model)
    loaded = load_prognostics_model(path)
    assert rebuilt.to_dict() == d and loaded.to_dict() == d
    for method in ("degradation", "similarity", "degradation-linear"):
        expected = fleet_model.predict(history, method=method)
        for other in (rebuilt, loaded):
            assert other.predict(history, method=method) == expected
    assert d["fitted"]["form"] == "exponential"
    assert set(d["fitted"]["loo_rmse"]) == {"exponential", "linear"}


@pytest.mark.parametrize(
    ("content", "words"),
    [
        (None, "no such file"),
        ('{"format": "prsm_health-prognostics", "format_ver', "invalid JSON"),
        ("[1, 2]", "not a prsm_health prognostics model"),
        ('{"format": "prsm_health-prognostics", "format_version": 1}', "malformed"),
    ],
)
def test_corrupt_model_files_are_refused_in_one_line(tmp_path, content, words):
    path = tmp_path / "model.json"
    if content is not None:
        path.write_text(content)
    with pytest.raises(PRSMHealthError) as info:
        load_prognostics_model(path)
    message = str(info.value)
    assert "\n" not in message and words in message and "model.json" in message, message


def test_truncated_fitted_state_is_refused(fleet_model, tmp_path):
    d = fleet_model.to_dict()
    del d["fitted"]["forms"]["linear"]["cov"]
    path = tmp_path / "model.json"
    path.write_text(json.dumps(d))
    with pytest.raises(PRSMHealthError, match="malformed prognostics model"):
        load_prognostics_model(path)
    with pytest.raises(ParameterError, match="fitted"):
        save_prognostics_model(tmp_path / "unfitted.json", RULModel())
