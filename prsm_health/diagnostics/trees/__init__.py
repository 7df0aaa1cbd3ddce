"""Compiled boosted trees: the shipped models' predictions in a few milliseconds.

scikit-learn's :class:`~sklearn.ensemble.HistGradientBoostingRegressor` /
:class:`~sklearn.ensemble.HistGradientBoostingClassifier` predict tree by tree from Python,
and every nested estimator (calibration folds, quantile models) validates its input again: for
one window the default model's ~2,000 trees cost 25–45 ms, most of it per-call overhead
(docs/performance.md). Here every tree of a fitted booster is flattened once into node arrays
and walked by one numba kernel (:mod:`._kernels`) in scikit-learn's order of summation, so the
raw predictions are the same floating-point numbers; the sigmoid calibration of
:class:`~sklearn.calibration.CalibratedClassifierCV` is applied as scikit-learn does (Platt's
``1 / (1 + exp(a·f + b))`` per class, normalised, averaged over the folds).

What cannot be compiled is left to scikit-learn (``compile_*`` returns None): categorical
splits, a fitted preprocessor, isotonic or temperature calibration, a link that is not the
identity for a regressor. Each compiled model is checked once against scikit-learn on probe
rows built from its own split thresholds (and all-NaN rows); a mismatch beyond 1e-9 also
leaves it to scikit-learn — a newer scikit-learn that changed its internals costs speed, never
correctness.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

__all__ = ["CompiledBooster", "compile_booster", "calibrated_proba", "regressor_predict"]

#: Largest relative difference to scikit-learn's prediction on the probe rows.
CHECK_TOLERANCE = 1e-9

_cache: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_UNSUPPORTED = object()


@dataclass(frozen=True)
class CompiledBooster:
    """Node arrays of every tree of one fitted HistGradientBoosting model."""

    baseline: np.ndarray  # (n_outputs,)
    roots: np.ndarray  # (n_trees,) index of each tree's root node
    output_of: np.ndarray  # (n_trees,) output column each tree adds to
    feature: np.ndarray
    threshold: np.ndarray
    missing_left: np.ndarray
    left: np.ndarray
    right: np.ndarray
    leaf: np.ndarray
    value: np.ndarray
    n_features: int

    def raw_predict(self, x: np.ndarray) -> np.ndarray:
        """Raw predictions (n_samples, n_outputs): baseline plus every tree's leaf value."""
        from ._kernels import add_tree_values

        x = np.ascontiguousarray(x, dtype=np.float64)
        raw = np.zeros((x.shape[0], len(self.baseline)))
        raw += self.baseline
        add_tree_values(x, self.roots, self.output_of, self.feature, self.threshold,
                        self.missing_left, self.left, self.right, self.leaf, self.value,
                        raw)  # fmt: skip
        return raw


def _flatten(model) -> CompiledBooster | None:
    predictors = getattr(model, "_predictors", None)
    baseline = getattr(model, "_baseline_prediction", None)
    if predictors is None or baseline is None or getattr(model, "_preprocessor", None) is not None:
        return None
    columns = {
        k: [] for k in ("feature", "threshold", "missing_left", "left", "right", "leaf", "value")
    }
    roots, output_of, offset = [], [], 0
    for iteration in predictors:
        for k, predictor in enumerate(iteration):
            nodes = predictor.nodes
            if np.any(nodes["is_categorical"]):
                return None
            roots.append(offset)
            output_of.append(k)
            columns["feature"].append(nodes["feature_idx"].astype(np.int64))
            columns["threshold"].append(nodes["num_threshold"].astype(np.float64))
            columns["missing_left"].append(nodes["missing_go_to_left"].astype(np.bool_))
            columns["left"].append(nodes["left"].astype(np.int64) + offset)
            columns["right"].append(nodes["right"].astype(np.int64) + offset)
            columns["leaf"].append(nodes["is_leaf"].astype(np.bool_))
            columns["value"].append(nodes["value"].astype(np.float64))
            offset += len(nodes)
    arrays = {k: np.concatenate(v) if v else np.zeros(0) for k, v in columns.items()}
    return CompiledBooster(
        baseline=np.asarray(baseline, np.float64).reshape(-1),
        roots=np.asarray(roots, np.int64),
        output_of=np.asarray(output_of, np.int64),
        n_features=int(model.n_features_in_),
        **arrays,
    )


def _probe_rows(booster: CompiledBooster, n: int = 32, seed: int = 0) -> np.ndarray:
    """Rows that walk many paths: each feature at one of its own split thresholds (exactly,
    just above, or NaN), plus an all-NaN row."""
    rng = np.random.default_rng(seed)
    splits = ~booster.leaf
    rows = np.full((n + 1, booster.n_features), np.nan)
    for j in range(booster.n_features):
        values = booster.threshold[splits & (booster.feature == j)]
        values = values[np.isfinite(values)]
        if len(values):
            pick = rng.choice(values, n) * (1 + rng.choice([0.0, 1e-6], n))
            rows[:n, j] = np.where(rng.random(n) < 0.1, np.nan, pick)
    return rows


def _cached(model, build):
    try:
        hit = _cache.get(model)
    except TypeError:  # not weak-referenceable: compile every call would cost more than it saves
        return None
    if hit is None:
        try:
            hit = build(model)
        except Exception:  # internals not as expected, or the kernel cannot compile here:
            hit = None  # scikit-learn predicts (slower, never different)
        _cache[model] = _UNSUPPORTED if hit is None else hit
    return None if hit is _UNSUPPORTED else hit


def _close(a, b) -> bool:
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(float(np.max(np.abs(b))) if b.size else 0.0, 1.0)
    return a.shape == b.shape and bool(np.all(np.abs(a - b) <= CHECK_TOLERANCE * scale))


def compile_booster(model) -> CompiledBooster | None:
    """The compiled form of a fitted HistGradientBoosting model (cached per model), or None
    when it cannot be compiled or its raw predictions differ from scikit-learn's."""

    def build(m):
        booster = _flatten(m)
        if booster is None:
            return None
        probe = _probe_rows(booster)
        return booster if _close(booster.raw_predict(probe), m._raw_predict(probe)) else None

    return _cached(model, build)


def regressor_predict(model, x: np.ndarray) -> np.ndarray:
    """``model.predict(x)`` of a fitted HistGradientBoostingRegressor with an identity link
    (squared, absolute, quantile losses), compiled when it can be."""
    link = type(getattr(getattr(model, "_loss", None), "link", None)).__name__
    booster = compile_booster(model) if link == "IdentityLink" else None
    if booster is None:
        return model.predict(x)
    return booster.raw_predict(x)[:, 0]


@dataclass(frozen=True)
class _CalibratedFolds:
    boosters: tuple
    a: tuple  # per fold, per calibrated output: Platt slope
    b: tuple
    n_classes: int


def _compile_calibrated(model) -> _CalibratedFolds | None:
    if getattr(model, "method", None) != "sigmoid":
        return None
    boosters, slopes, intercepts = [], [], []
    n_classes = len(model.classes_)
    for fold in model.calibrated_classifiers_:
        booster = compile_booster(fold.estimator)
        if booster is None or not np.array_equal(fold.estimator.classes_, np.arange(n_classes)):
            return None
        calibrators = fold.calibrators
        if len(calibrators) != (1 if n_classes == 2 else n_classes):
            return None
        boosters.append(booster)
        slopes.append(np.array([c.a_ for c in calibrators], float))
        intercepts.append(np.array([c.b_ for c in calibrators], float))
    folds = _CalibratedFolds(tuple(boosters), tuple(slopes), tuple(intercepts), n_classes)
    probe = _probe_rows(folds.boosters[0])
    return folds if _close(_calibrated(folds, probe), model.predict_proba(probe)) else None


def _calibrated(folds: _CalibratedFolds, x: np.ndarray) -> np.ndarray:
    mean = np.zeros((x.shape[0], folds.n_classes))
    for booster, a, b in zip(folds.boosters, folds.a, folds.b):
        raw = booster.raw_predict(x)
        # scikit-learn's _SigmoidCalibration.predict: expit(-(a·f + b)) = 1 / (1 + exp(a·f + b))
        calibrated = 1.0 / (1.0 + np.exp(a * raw + b))
        if folds.n_classes == 2:
            proba = np.column_stack([1.0 - calibrated[:, 0], calibrated[:, 0]])
        else:
            total = calibrated.sum(axis=1, keepdims=True)
            proba = np.divide(
                calibrated,
                total,
                out=np.full_like(calibrated, 1.0 / folds.n_classes),
                where=total != 0,
            )
        proba[(1.0 < proba) & (proba <= 1.0 + 1e-5)] = 1.0
        mean += proba
    return mean / len(folds.boosters)


def calibrated_proba(model, x: np.ndarray) -> np.ndarray:
    """``model.predict_proba(x)`` of a fitted sigmoid CalibratedClassifierCV over
    HistGradientBoostingClassifiers, compiled when it can be."""
    folds = _cached(model, _compile_calibrated)
    return model.predict_proba(x) if folds is None else _calibrated(folds, x)
