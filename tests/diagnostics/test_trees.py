"""Compiled boosted trees against scikit-learn's own predictions: the same numbers, or
scikit-learn predicts (never a different answer)."""

import numpy as np
import pytest
from sklearn.calibration import CalibratedClassifierCV
from sklearn.ensemble import HistGradientBoostingClassifier, HistGradientBoostingRegressor
from sklearn.model_selection import StratifiedKFold

from prsm_health.diagnostics import trees
from prsm_health.diagnostics.trees import _kernels


def _data(n=600, seed=0, classes=3):
    rng = np.random.default_rng(seed)
    X = rng.standard_normal((n, 6))
    X[rng.random((n, 6)) < 0.1] = np.nan  # missing values take each split's learnt side
    y = np.nan_to_num(X[:, 0]) + 0.5 * np.nan_to_num(X[:, 1]) ** 2 + 0.1 * rng.standard_normal(n)
    labels = np.digitize(y, np.quantile(y, np.linspace(0, 1, classes + 1)[1:-1]))
    return X, y, labels


@pytest.mark.parametrize(
    "loss",
    [{"loss": "squared_error"}, {"loss": "absolute_error"}, {"loss": "quantile", "quantile": 0.05}],
)
def test_regressor_predictions_are_scikit_learns(loss):
    X, y, _ = _data()
    model = HistGradientBoostingRegressor(max_iter=60, random_state=0, **loss).fit(X, y)
    X_new = _data(300, seed=1)[0]
    assert trees.compile_booster(model) is not None
    # the same trees summed in the same order: equal to the last bit with today's scikit-learn;
    # 1e-12 leaves room for a release that sums in another order
    np.testing.assert_allclose(
        trees.regressor_predict(model, X_new), model.predict(X_new), rtol=1e-12, atol=0
    )


@pytest.mark.parametrize("classes", [2, 4])
def test_calibrated_classifier_probabilities_are_scikit_learns(classes):
    X, _, labels = _data(classes=classes)
    model = CalibratedClassifierCV(
        HistGradientBoostingClassifier(max_iter=30, random_state=0),
        method="sigmoid",
        cv=StratifiedKFold(3, shuffle=True, random_state=0),
    ).fit(X, labels)
    X_new = _data(300, seed=2)[0]
    # raw sums are bitwise equal; the sigmoid is numpy's exp where scipy uses expit: rounding
    np.testing.assert_allclose(
        trees.calibrated_proba(model, X_new), model.predict_proba(X_new), rtol=1e-12, atol=1e-15
    )


def test_what_cannot_be_compiled_is_left_to_scikit_learn():
    X, y, labels = _data()
    X_cat = np.column_stack([np.floor(np.abs(np.nan_to_num(X[:, 0])) * 2) % 4, X[:, 1:]])
    model = HistGradientBoostingRegressor(
        max_iter=20, categorical_features=[0], random_state=0
    ).fit(X_cat, y)
    assert trees.compile_booster(model) is None  # a categorical split
    np.testing.assert_array_equal(trees.regressor_predict(model, X_cat), model.predict(X_cat))
    poisson = HistGradientBoostingRegressor(max_iter=20, loss="poisson").fit(X, np.exp(y / 4))
    np.testing.assert_array_equal(trees.regressor_predict(poisson, X), poisson.predict(X))
    isotonic = CalibratedClassifierCV(
        HistGradientBoostingClassifier(max_iter=10), method="isotonic", cv=3
    ).fit(X, labels)
    np.testing.assert_array_equal(trees.calibrated_proba(isotonic, X), isotonic.predict_proba(X))


def test_kernel_without_jit_gives_the_same_sums():
    X, y, _ = _data(200)
    booster = trees.compile_booster(HistGradientBoostingRegressor(max_iter=10).fit(X, y))
    args = (booster.roots, booster.output_of, booster.feature, booster.threshold,
            booster.missing_left, booster.left, booster.right, booster.leaf, booster.value)  # fmt: skip
    jitted, plain = np.zeros((200, 1)), np.zeros((200, 1))
    _kernels.add_tree_values(X, *args, jitted)
    _kernels.add_tree_values.py_func(X, *args, plain)
    np.testing.assert_array_equal(jitted, plain)


def test_a_compiled_model_that_disagrees_is_not_used(monkeypatch):
    # e.g. a newer scikit-learn whose node arrays mean something else: the probe rows catch it
    X, y, _ = _data()
    model = HistGradientBoostingRegressor(max_iter=20, random_state=0).fit(X, y)
    flatten = trees._flatten

    def wrong(m):
        b = flatten(m)
        return trees.CompiledBooster(**{**b.__dict__, "value": b.value * 1.001})

    monkeypatch.setattr(trees, "_flatten", wrong)
    assert trees.compile_booster(model) is None
    np.testing.assert_array_equal(trees.regressor_predict(model, X), model.predict(X))
