"""A prognostics model carries the design it was fitted for (name and fingerprint): it refuses
the histories of another design — by fingerprint where both have one, by name otherwise — and
reads model files from before fingerprints (a preset name stands for its fingerprint)."""

import json
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from prsm_health.actuator.design import preset
from prsm_health.actuator.design_files import design_fingerprint
from prsm_health.prognostics import (
    DEFAULT_PROGNOSTICS_MODEL,
    HistoryError,
    RULModel,
    load_prognostics_model,
    prognose,
    save_prognostics_model,
    validate_history,
)

Z90 = 1.6448536269514722
BASE = preset("paper01")
#: Design A and design B: both named "acme-ema-24", neither a preset, B with a heavier nut.
DESIGN_A = BASE.with_(name="acme-ema-24", screw_free_length=0.2)
DESIGN_B = DESIGN_A.with_(masses=replace(BASE.masses, nut_mass=0.5))
PRINT_A, PRINT_B = design_fingerprint(DESIGN_A), design_fingerprint(DESIGN_B)


def _fleet(n_units=4, n_points=6, seed=0, **columns) -> tuple[pd.DataFrame, dict]:
    """Linear wear from ~10 µm to the 30 µm threshold: histories and failure ages."""
    rng = np.random.default_rng(seed)
    parts, lives = [], {}
    for uid in range(n_units):
        c0, slope = 10e-6 + 0.5e-6 * rng.standard_normal(), 2e-9 * (1 + 0.1 * uid)
        lives[uid] = (30e-6 - c0) / slope
        ages = np.linspace(0.0, lives[uid], n_points, endpoint=False)
        value = c0 + slope * ages + 0.3e-6 * rng.standard_normal(n_points)
        parts.append(
            pd.DataFrame(
                {
                    "unit_id": uid,
                    "age_hours": ages,
                    "clearance": value,
                    "clearance_lower": value - Z90 * 0.3e-6,
                    "clearance_upper": value + Z90 * 0.3e-6,
                    **columns,
                }
            )
        )
    return pd.concat(parts, ignore_index=True), lives


@pytest.fixture(scope="module")
def model_a():
    histories, lives = _fleet(design="acme-ema-24", design_fingerprint=PRINT_A)
    model = RULModel(design="acme-ema-24", design_fingerprint=PRINT_A, n_samples=200)
    return model.fit(histories, lives)


def _one_unit(**columns) -> pd.DataFrame:
    histories, _ = _fleet(**columns)
    return histories[histories["unit_id"] == 1].drop(columns="unit_id")


def test_a_model_of_design_a_accepts_design_a_and_any_name_only_history_of_its_name(model_a):
    assert model_a.design_id == ("acme-ema-24", PRINT_A)
    for history in (
        _one_unit(design="acme-ema-24", design_fingerprint=PRINT_A),
        _one_unit(design_fingerprint=PRINT_A),
        _one_unit(design="acme-ema-24"),  # name only: compared by name
        _one_unit(),  # nothing said: accepted
    ):
        assert prognose(history, model_a).rul_hours["estimate"] >= 0


def test_a_model_of_design_a_refuses_design_b_of_the_same_name(model_a):
    history = _one_unit(design="acme-ema-24", design_fingerprint=PRINT_B)
    with pytest.raises(HistoryError) as info:
        prognose(history, model_a)
    message = str(info.value)
    assert "\n" not in message and PRINT_A in message and PRINT_B in message
    assert "another design" in message
    with pytest.raises(HistoryError, match="history is of design 'paper01'"):
        validate_history(_one_unit(design="paper01"), model_a)
    with pytest.raises(HistoryError, match="mixes designs"):
        validate_history(_one_unit().assign(design_fingerprint=[PRINT_A, PRINT_B] * 3), model_a)


def test_fitting_on_histories_of_another_design_is_refused():
    histories, lives = _fleet(design="acme-ema-24", design_fingerprint=PRINT_B)
    model = RULModel(design="acme-ema-24", design_fingerprint=PRINT_A, n_samples=200)
    with pytest.raises(HistoryError, match="unit 0: history is of design"):
        model.fit(histories, lives)


def test_the_design_round_trips_through_the_model_file(model_a, tmp_path):
    path = save_prognostics_model(tmp_path / "a.json", model_a)
    loaded = load_prognostics_model(path)
    assert loaded.design_id == ("acme-ema-24", PRINT_A)
    assert prognose(_one_unit(), loaded).model["design_fingerprint"] == PRINT_A


def test_an_old_model_file_with_only_a_preset_name_stands_for_that_preset(tmp_path):
    old = json.loads(DEFAULT_PROGNOSTICS_MODEL.read_text())
    old["params"].pop("design_fingerprint", None)  # as written before fingerprints
    path = tmp_path / "old.json"
    path.write_text(json.dumps(old))
    model = load_prognostics_model(path)
    assert model.design_id == ("paper01", design_fingerprint("paper01"))
    paper01 = _one_unit(design="paper01", design_fingerprint=design_fingerprint("paper01"))
    validate_history(paper01, model)
    with pytest.raises(HistoryError, match="another design"):
        validate_history(_one_unit(design="paper01", design_fingerprint=PRINT_B), model)
    # a design known by name only keeps the name rule
    named = RULModel(design="acme-ema-24")
    assert named.design_id == ("acme-ema-24", None)
