"""What an MCAP recording of a run declares: the topics' JSON schemas, built from the channel
contract (:mod:`prsm_health.core.channels`), the diagnosis topic's schema, and the metadata records.

Schemas are JSON Schema draft-07 (MCAP schema encoding ``jsonschema``), one per topic; each
signal field's description gives the channel's meaning and SI unit from the contract. The
measured channels are on :data:`TOPIC_NUT_ACCEL` and :data:`TOPIC_DRIVE`, the simulator's truth
signals on :data:`TOPIC_TRUTH` (one field per truth signal, named like it).

Metadata: MCAP metadata values are strings. A label that is a string is stored as is, unless it
would itself parse as JSON (``"1.5"``, ``"true"``, ``"null"``, ``'"x"'``), in which case it is
stored JSON-encoded; every other value (numbers, booleans, None, lists, dicts, numpy scalars) is
stored JSON-encoded (:func:`encode_metadata_value`). The reader JSON-decodes each value and
keeps the raw string when that fails (:func:`decode_metadata_value`), so labels round-trip
exactly and a human reading the metadata in Foxglove sees ``paper01``, not ``"paper01"``.

The run labels are the Metadata record :data:`LABELS_METADATA`; a second record,
:data:`INFO_METADATA`, holds what the reader needs to rebuild the run exactly (sample rate [Hz],
run start [ns], energy book [J], channel units, name of the scenario attachment), kept apart
so that the labels equal :attr:`Run.labels` after a round trip.
"""

from __future__ import annotations

import json

import numpy as np

from prsm_health.core.channels import (
    TOPIC_DRIVE,
    TOPIC_NUT_ACCEL,
    TOPIC_TRUTH,
    channel,
    truth_channel,
)
from prsm_health.core.jsonable import dumps

__all__ = [
    "CHECK_PHASE_SCHEMA_NAME",
    "DIAGNOSIS_SCHEMA_NAME",
    "FORMAT_VERSION",
    "INFO_METADATA",
    "LABELS_METADATA",
    "SCHEMA_NAMES",
    "check_phase_schema",
    "decode_metadata_value",
    "diagnosis_schema",
    "encode_metadata_value",
    "encode_schema",
    "topic_schema",
]

#: Name of the Metadata record holding the run labels.
LABELS_METADATA = "labels"
#: Name of the Metadata record holding what the reader needs to rebuild the run.
INFO_METADATA = "prsm_health"
#: Version of the :data:`INFO_METADATA` layout.
FORMAT_VERSION = "1"

#: Schema name of each signal topic.
SCHEMA_NAMES = {
    TOPIC_NUT_ACCEL: "prsm_health.NutAccel",
    TOPIC_DRIVE: "prsm_health.Drive",
    TOPIC_TRUTH: "prsm_health.Truth",
}
#: Schema name of the diagnosis topic.
DIAGNOSIS_SCHEMA_NAME = "prsm_health.Diagnosis"
#: Schema name of the health-check phase topic.
CHECK_PHASE_SCHEMA_NAME = "prsm_health.CheckPhase"

_DRAFT_07 = "http://json-schema.org/draft-07/schema#"
# Units of the numbers under a diagnosis' "clearance" object.
_DIAGNOSIS_UNITS = {"estimate": "m", "lower": "m", "upper": "m"}


def encode_schema(schema: dict) -> bytes:
    """Schema record data of a JSON schema (indented, for people reading it in Foxglove)."""
    return json.dumps(schema, indent=2).encode()


def topic_schema(topic: str, pairs: list[tuple[str, str]]) -> dict:
    """JSON schema of a signal topic whose messages have the (field, name) ``pairs``: measured
    channels, or truth signals on :data:`TOPIC_TRUTH`."""
    truth = topic == TOPIC_TRUTH
    entries = [(field, (truth_channel if truth else channel)(name)) for field, name in pairs]
    properties = {
        field: {
            "type": "number",
            "description": f"{c.meaning} [{c.unit}] ({'truth' if truth else 'channel'} "
            f"{c.name}); null when the sample is not finite",
        }
        for field, c in entries
    }
    what = "simulator truth, not a measurement; " if truth else ""
    return {
        "$schema": _DRAFT_07,
        "title": SCHEMA_NAMES[topic],
        "description": f"One sample of {topic}, {what}SI units (prsm_health MCAP contract)",
        "type": "object",
        "properties": properties,
        "required": [field for field, _ in pairs],
    }


def check_phase_schema() -> dict:
    """JSON schema of the health-check phase topic: one message per phase change."""
    return {
        "$schema": _DRAFT_07,
        "title": CHECK_PHASE_SCHEMA_NAME,
        "description": "The health-check phase from this message's log time on, until the "
        "next message (prsm_health MCAP contract)",
        "type": "object",
        "properties": {
            "index": {
                "type": "integer",
                "description": "phase index in the check (-1: outside any phase, a ramp)",
            },
            "name": {"type": "string", "description": "phase name (empty outside any phase)"},
        },
        "required": ["index", "name"],
    }


def diagnosis_schema(example: dict | None) -> dict:
    """JSON schema of diagnosis messages, inferred from a first message ``example``.

    Nested objects are described field by field; the numbers of a ``clearance`` object are
    documented in m. Without an example the messages are declared as plain objects.
    """
    inferred = _infer_schema(example) if example is not None else {"type": "object"}
    return {
        "$schema": _DRAFT_07,
        "title": DIAGNOSIS_SCHEMA_NAME,
        "description": "Diagnosis of the preceding window (SI units)",
        **inferred,
    }


def _infer_schema(value, key: str | None = None, parent: str | None = None) -> dict:
    if isinstance(value, dict):
        return {
            "type": "object",
            "properties": {str(k): _infer_schema(v, str(k), key) for k, v in value.items()},
        }
    if isinstance(value, bool | np.bool_):
        return {"type": "boolean"}
    if isinstance(value, (int, float, np.integer, np.floating)):
        schema = {"type": "number"}
        if parent == "clearance" and key in _DIAGNOSIS_UNITS:
            schema["description"] = f"clearance {key} [{_DIAGNOSIS_UNITS[key]}]"
        return schema
    if isinstance(value, str):
        return {"type": "string"}
    if isinstance(value, (list, tuple, np.ndarray)):
        return {"type": "array"}
    return {}


def encode_metadata_value(value) -> str:
    """A label value as an MCAP metadata string (see the module notes)."""
    if isinstance(value, str):
        try:
            json.loads(value)
        except ValueError:
            return value
    return dumps(value)


def decode_metadata_value(text: str):
    """The label value of an MCAP metadata string: its JSON value, else the string itself."""
    try:
        return json.loads(text)
    except ValueError:
        return text
