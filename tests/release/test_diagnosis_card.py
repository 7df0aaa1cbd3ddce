"""prsm_health.release.diagnosis_card: the diagnosis model's card, from its metrics alone."""

import json
import types

from prsm_health.diagnostics.diagnosis import DEFAULT_MODEL
from prsm_health.release.diagnosis_card import check_card_section, model_card, write_model_card
from prsm_health.training.check_evaluation import _accumulated, _class_scores, _sensitivity

SHIPPED_METRICS = DEFAULT_MODEL.with_name("default.metrics.json")
SHIPPED_CARD = DEFAULT_MODEL.with_name("MODEL_CARD.md")


def test_card_of_the_shipped_metrics_is_the_shipped_card(tmp_path):
    # The card is generated from the metrics file, never edited by hand: regenerating it from
    # the shipped metrics gives the shipped card, character for character.
    metrics = json.loads(SHIPPED_METRICS.read_text())
    size = DEFAULT_MODEL.stat().st_size
    assert model_card(metrics, size) == SHIPPED_CARD.read_text()
    model = tmp_path / "m.skops"
    model.write_bytes(b"x" * 1234)
    path = write_model_card(metrics, model)
    assert path == tmp_path / "MODEL_CARD.md"
    assert "File size\n0.00 MB" in path.read_text()


MODEL = types.SimpleNamespace(not_observable={"preload_loss": "measured reason"})


def record(state, truth, alone, top, noise):
    return {
        "state": state,
        "fault_class": truth,
        "unit_id": 0,
        "predicted_alone": alone,
        "top_alone": top,
        "predicted_against": alone,
        "top_against": top,
        "clearance": 5e-6,
        "estimate": 6e-6,
        "lower": 0.0,
        "upper": 1e-5,
        "conditions": {"instrumentation.nut_axial_accel.noise_density_ug": noise},
    }


def test_the_check_section_shows_the_evaluation_tables():
    records = [
        record("healthy", "healthy", "healthy", 0.9, 20.0),
        record("healthy", "healthy", "cannot_tell", 0.45, 30.0),
        record("healthy", "healthy", "healthy", 0.55, 40.0),
        record("wear", "wear", "wear", 0.95, 50.0),
        record("wear", "wear", "spall", 0.7, 60.0),
        record("spall_nut", "spall", "spall", 0.65, 25.0),
    ]
    units = [
        {"state": "healthy", "fault_class": "healthy", "named": "healthy",
         "posterior": {"healthy": 0.95, "spall": 0.05}},
        {"state": "spall_nut", "fault_class": "spall", "named": "spall",
         "posterior": {"healthy": 0.02, "spall": 0.98}},
    ]  # fmt: skip
    evaluation = {
        "single": _class_scores(records, "predicted_alone", MODEL),
        "against_baseline_single": _class_scores(records, "predicted_against", MODEL),
        "accumulated": _accumulated(units, MODEL, 0.9),
        "clearance": {"n": 6, "mae": 1e-6, "coverage": 1.0, "mean_width": 1e-5},
        "sensitivity": _sensitivity(records, MODEL),
    }
    text = check_card_section(
        {"training": {"not_observable": MODEL.not_observable}, "evaluation": evaluation}
    )
    assert text.startswith("\n## Health-check recordings")
    assert "| 0.8 | " in text  # the naming-threshold table
    assert "accelerometer noise [µg/√Hz] | 20 – 28.3 | 2 |" in text  # tercile edge of 20…60
    assert "spall_nut 1.000" in text  # the AUC of the spall posterior
    assert "MAE 1.00 µm, 90 % coverage 1.000" in text
    # the one-check table: a row per evaluated state, a column per class the diagnosis gave
    assert "| state | cannot_tell | healthy | spall | wear |" in text
    assert "| wear | 0 | 0 | 1 | 1 |" in text
    # numbers the training did not give print as missing
    assert "Held-out units: clearance MAE\n–, coverage –;" in text


def test_no_check_section_before_the_check_part_is_evaluated():
    assert check_card_section({}) == ""
    assert check_card_section({"training": {"runs": {"train": 3}}}) == ""
