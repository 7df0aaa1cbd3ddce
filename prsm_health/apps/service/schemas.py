"""Request and response models of the API (pydantic), and the one formatting of their errors.

The models are fixed; the bounds that depend on :class:`ServiceLimits` are applied where the
limits are known: a request body is validated with ``context={"limits": limits}``
(:func:`parse_diagnose_request`), which checks ``sample_rate`` against the limits with
pydantic's own error types and messages, and :func:`document_limits` writes the same bounds
into the app's OpenAPI document.

The Diagnosis and Prognosis answers are not declared here: :func:`contract_model` generates
their models from the library's declarations (:mod:`prsm_health.diagnostics.contract`,
:mod:`prsm_health.prognostics.prognosis`), field by field. The query
parameters of a binary body are the JSON body's fields (:class:`DiagnoseParams`), checked by
the same model (:func:`parse_query_params`).
"""

from __future__ import annotations

import dataclasses
import types
import typing
from typing import Annotated

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    create_model,
    field_validator,
)
from pydantic_core import PydanticKnownError

from prsm_health.core.channels import CHANNEL_NAMES, CHANNELS, TRUTH_NAMES, TRUTH_PREFIX
from prsm_health.core.identifiers import ASSET_ID_PATTERN, RECORDING_ID_PATTERN
from prsm_health.diagnostics import contract
from prsm_health.prognostics import prognosis

from .limits import MAX_OPERATING_HOURS, ServiceLimits
from .responses import HTTPError

_DEFAULT_LIMITS = ServiceLimits()

Finite = Annotated[float, Field(allow_inf_nan=False)]
#: What ``operating_hours`` of a diagnose request means (JSON field and query parameter).
OPERATING_HOURS_DESCRIPTION = (
    "operating hours of the asset when the recording was made [h], 0 – 1e7; stored with the "
    "diagnosis and used by GET /v1/assets/{asset_id}/prognosis"
)

#: What ``healthy`` of a diagnose request means (JSON field, query parameter, form field).
HEALTHY_DESCRIPTION = (
    "with asset_id: the recording is of the asset in a known healthy state — true puts it in "
    "the asset's baseline (at any time), false keeps it out; absent: it joins a baseline that "
    "has fewer than `needed` recordings unless the diagnosis names a fault with healthy ruled "
    "out"
)
#: What ``recording_id`` of a diagnose request means.
RECORDING_ID_DESCRIPTION = (
    "with asset_id: the recording's identifier in the asset's history; a recording sent again "
    "with the same id is not counted twice (its answer carries the asset's state recorded "
    "then). Default: a hash of the recording's content (sample rate, start time, channels)"
)

# One optional array per measured contract channel; any other name is an error
# (extra="forbid"), simulator truth included: a diagnosis reads measurements only, and a truth
# signal silently dropped would hide a client's mistake.
Channels = create_model(
    "Channels",
    __config__=ConfigDict(strict=True, extra="forbid"),
    __doc__="Measured contract channels (docs/formats.md): equal-length arrays, SI units. "
    "Simulator truth (truth_* columns, carrier_speed, friction_torque) is not accepted.",
    **{
        c.name: (list[Finite], Field(None, description=f"{c.meaning} [{c.unit}]")) for c in CHANNELS
    },
)


class DiagnoseParams(BaseModel):
    """What a diagnose request says besides the recording: fields of a JSON body, query
    parameters of a binary body (:func:`parse_query_params`)."""

    model_config = ConfigDict(strict=True, extra="forbid")
    design: str | None = Field(
        None,
        min_length=1,
        max_length=128,
        description="name of the actuator's design — a preset or a design file's name — which "
        "must be the design the served model was trained on",
    )
    speed: Finite | None = Field(None, description="nominal screw speed [rad/s] (stored)")
    load: Finite | None = Field(None, description="nominal axial load [N] (stored)")
    gear_ratio: Finite | None = Field(
        None,
        gt=0,
        le=1000,
        description="reduction between the motor and the screw (drive_torque is the motor's "
        "torque): the efficiency indicator's input power is drive_torque × gear_ratio × "
        "screw_speed; default: the recording's gear_ratio label, else 1",
    )
    operating_hours: Finite | None = Field(
        None,
        ge=0,
        le=MAX_OPERATING_HOURS,
        description=OPERATING_HOURS_DESCRIPTION,
    )
    asset_id: str | None = Field(
        None,
        pattern=ASSET_ID_PATTERN,
        description="store the diagnosis in this asset's history, judge the recording against "
        "the asset's own baseline and add it to the asset's evidence (the answer's `asset`)",
    )
    healthy: bool | None = Field(
        None,
        description=HEALTHY_DESCRIPTION,
    )
    recording_id: str | None = Field(
        None,
        pattern=RECORDING_ID_PATTERN,
        description=RECORDING_ID_DESCRIPTION,
    )


class DiagnoseRequest(DiagnoseParams):
    """A recording to diagnose: uniformly sampled contract channels."""

    sample_rate: Finite = Field(description="sample rate [Hz]")
    channels: Channels  # type: ignore[valid-type]
    time_start: Finite = Field(0.0, ge=-1e7, le=1e7, description="time of the first sample [s]")

    @field_validator("sample_rate")
    @classmethod
    def _within_limits(cls, rate: float, info: ValidationInfo) -> float:
        # The limits of the validating service (context), else the defaults; same error types
        # and messages as Field(ge=..., le=...).
        limits = (info.context or {}).get("limits") or _DEFAULT_LIMITS
        if rate < limits.min_sample_rate:
            raise PydanticKnownError("greater_than_equal", {"ge": limits.min_sample_rate})
        if rate > limits.max_sample_rate:
            raise PydanticKnownError("less_than_equal", {"le": limits.max_sample_rate})
        return rate


def contract_model(cls: type, models: dict[str, type[BaseModel]] | None = None):
    """The pydantic model of a part of the Diagnosis or Prognosis contract, generated from its
    dataclass declaration (:mod:`prsm_health.diagnostics.contract`,
    :mod:`prsm_health.prognostics.prognosis`): one field per dataclass field, with
    its type (parts replaced by their models, recursively) and description; a field the JSON
    leaves out when empty (``omit_empty``) is not required, every other one is; no other key
    is allowed. ``models``: the models made so far, by class name (shared by the recursion)."""
    models = {} if models is None else models
    name = cls.__name__
    if name in models:
        return models[name]
    hints = typing.get_type_hints(cls)
    fields = {}
    for f in dataclasses.fields(cls):
        annotation = _contract_type(hints[f.name], models, name)
        description = f.metadata.get("description")
        if f.metadata.get("omit_empty"):
            # absent, never null: the type without None, and no default in the schema
            annotation = _without_none(annotation)
            fields[f.name] = (annotation, Field(default_factory=_absent, description=description))
        else:
            fields[f.name] = (annotation, Field(description=description))
    model = create_model(
        name,
        __config__=ConfigDict(extra="forbid"),
        __doc__=(cls.__doc__ or "").strip(),
        **fields,
    )
    models[name] = model
    model.model_rebuild(_types_namespace=models)  # a part that holds itself (``windows``)
    return model


def _absent():
    return None


def _contract_type(hint, models: dict, building: str):
    """``hint`` with contract dataclasses replaced by their models (the class being built by
    its name: a forward reference resolved when it is done)."""
    if dataclasses.is_dataclass(hint):
        if hint.__name__ == building:
            return hint.__name__
        return contract_model(hint, models)
    args = typing.get_args(hint)
    if not args:
        return hint
    new = tuple(_contract_type(a, models, building) for a in args)
    if _is_union(hint):
        return typing.Union[new]  # noqa: UP007 (X | "Name" fails: a name among the members)
    return typing.get_origin(hint)[new]


def _is_union(hint) -> bool:
    return isinstance(hint, types.UnionType) or typing.get_origin(hint) is typing.Union


def _without_none(annotation):
    if not _is_union(annotation):
        return annotation
    return typing.Union[tuple(a for a in typing.get_args(annotation) if a is not type(None))]  # noqa: UP007


#: The Diagnosis contract's models, generated once from its declaration.
_CONTRACT: dict[str, type[BaseModel]] = {}
Diagnosis = contract_model(contract.Diagnosis, _CONTRACT)
ClearanceInterval = _CONTRACT["ClearanceInterval"]
WindowSpan = _CONTRACT["WindowSpan"]
Observability = _CONTRACT["Observability"]
Undecided = _CONTRACT["Undecided"]
AssetState = _CONTRACT["AssetState"]


class RecordingInfo(BaseModel):
    filename: str
    samples: int
    sample_rate: float = Field(description="[Hz]")
    duration: float = Field(description="[s]")
    channels: list[str]


class FileDiagnosis(BaseModel):
    diagnosis: Diagnosis
    windows: list[Diagnosis]  # type: ignore[valid-type]
    recording: RecordingInfo
    warnings: list[str]


class HistoryEntry(BaseModel):
    id: int
    received_at: str = Field(description="server receive time, UTC ISO-8601")
    source: str = Field(description="'json' or 'file'")
    filename: str | None
    window: WindowSpan | None  # type: ignore[valid-type]
    speed: float | None = Field(description="[rad/s]")
    load: float | None = Field(description="[N]")
    operating_hours: float | None = Field(
        description="operating hours of the asset at the recording, as sent [h]"
    )
    diagnosis: dict


class History(BaseModel):
    asset_id: str
    count: int
    total: int = Field(description="diagnoses stored at or after `since`")
    truncated: bool
    diagnoses: list[HistoryEntry]


#: The Prognosis answer's models, generated once from its declaration
#: (:mod:`prsm_health.prognostics.prognosis`).
_PROGNOSIS: dict[str, type[BaseModel]] = {}
Prognosis = contract_model(prognosis.Prognosis, _PROGNOSIS)
RulHours = _PROGNOSIS["RulHours"]
Headline = _PROGNOSIS["Headline"]


class CheckReading(BaseModel):
    """One indicator a health-check phase was read for."""

    name: str
    value: float | None = Field(description="in its unit (null: not read)")
    unit: str
    z: float | None = Field(
        description="its robust z-score against the asset's baseline (null: no complete baseline)"
    )


class CheckVerdict(BaseModel):
    """One role a health check is read for, with the phase it was read in and its verdict
    (``prsm_health.diagnostics.check_verdicts.check_verdicts``)."""

    role: str = Field(description="'no_load', 'torque_pair', 'reversal' or 'high_load'")
    condition: str = Field(description="the condition the role needs")
    phase: str | None = Field(description="the phase(s) it was read in (null: the check lacks it)")
    read: bool = Field(description="whether any of its indicators has a value")
    readings: list[CheckReading]
    classes: dict[str, float] = Field(
        description="class → probability of the classes this role's phase shows"
    )
    clearance: ClearanceInterval | None = Field(  # type: ignore[valid-type]
        description="the reversal: the clearance interval when observable"
    )


class AssetStatus(BaseModel):
    """The asset at a glance (``prsm_health.monitoring.status.asset_status``; docs/service.md,
    Dashboard)."""

    level: str = Field(description="'healthy', 'unknown' (cannot tell yet), 'watch' or 'alarm'")
    reasons: list[str] = Field(description="why, worst first, and what it cannot tell yet")


class LatestDiagnosis(BaseModel):
    """The latest stored diagnosis of an asset, in brief."""

    received_at: str = Field(description="server receive time, UTC ISO-8601")
    source: str = Field(description="'json', 'arrow', 'parquet', 'mcap' or 'file'")
    filename: str | None
    window: WindowSpan | None  # type: ignore[valid-type]
    operating_hours: float | None = Field(description="[h], as sent")
    clearance: ClearanceInterval  # type: ignore[valid-type]
    fault_class: str | None
    class_probabilities: dict[str, float]
    warnings: list[str]
    model: dict | None = Field(description="name, version, design of the diagnosing model")
    observability: Observability | None = Field(  # type: ignore[valid-type]
        None,
        description="per target, whether the model could see it (the diagnosis' own); where "
        "not, the pages show 'not observable' instead of its numbers",
    )
    undecided: Undecided | None = Field(  # type: ignore[valid-type]
        None, description="why the class is cannot_tell (the diagnosis' own; null otherwise)"
    )
    check: list[CheckVerdict] | None = Field(
        None, description="a health check: each role's phase, readings and verdict"
    )


class PrognosisBrief(BaseModel):
    """The asset's prognosis in brief (``rul_hours``, ``headline``, ``method``, ``threshold``,
    ``current``, ``warnings``), or why there is none (``error`` and the ``status`` that
    ``GET /v1/assets/{asset_id}/prognosis`` answers)."""

    rul_hours: RulHours | None = None
    headline: Headline | None = Field(  # type: ignore[valid-type]
        None, description="what a maintainer reads: the prognosis' headline"
    )
    method: str | None = Field(None, description="the prognostics method used")
    threshold: float | None = Field(None, description="failure threshold of the clearance [m]")
    current: float | None = Field(None, description="latest clearance estimate used [m]")
    warnings: list[str] = Field(default_factory=list)
    error: str | None = Field(None, description="why there is no prognosis")
    status: int | None = Field(None, description="the prognosis endpoint's status: 422, 503")


class BaselineMember(BaseModel):
    """A recording in an asset's baseline."""

    recording_id: str
    received_at: str = Field(description="server receive time, UTC ISO-8601")
    source: str = Field(description="'json', 'arrow', 'parquet', 'mcap' or 'file'")
    filename: str | None
    operating_hours: float | None = Field(description="[h], as sent")
    healthy: bool | None = Field(
        description="as the client marked it (null: not said; the rule put it in)"
    )


class AssetBaseline(BaseModel):
    """An asset's own baseline: the recordings it is fitted on."""

    recordings: int = Field(description="recordings in the baseline")
    needed: int | None = Field(description="recordings a baseline needs before changes are scored")
    members: list[BaselineMember] = Field(description="the baseline's recordings, oldest first")


class AssetEvidence(BaseModel):
    """An asset's class evidence and change statistic after its latest recording (the
    contract's ``asset.evidence``, with the recording and its baseline distance)."""

    recordings: int = Field(description="recordings whose evidence has accumulated")
    posterior: dict[str, float] = Field(description="class → posterior probability (sum 1)")
    fault_class: str = Field(
        description="the class whose posterior reaches the naming threshold, else cannot_tell"
    )
    change_statistic: float | None = Field(
        description="CUSUM of the baseline distance (null until the baseline is complete)"
    )
    change_alarm: bool = Field(description="the change statistic crossed its threshold")
    name_probability: float = Field(description="posterior a class needs to be named")
    change_reference: float | None = Field(
        description="the change statistic's reference k: the distance a recording must exceed "
        "to add to it"
    )
    change_threshold: float | None = Field(
        description="the change statistic's threshold h: above it, the alarm"
    )
    latest_recording: str = Field(description="the recording id this state is after")
    distance: float | None = Field(
        description="that recording's distance from the baseline (null: baseline incomplete)"
    )


class AssetRecording(BaseModel):
    """One recording of an asset and the asset's state after it."""

    recording_id: str
    received_at: str = Field(description="server receive time, UTC ISO-8601 (the first time)")
    source: str
    filename: str | None
    operating_hours: float | None = Field(description="[h], as sent")
    healthy: bool | None = Field(description="as the client marked it (null: not said)")
    baseline: bool = Field(description="the recording is in the asset's baseline")
    distance: float | None = Field(
        description="its distance from the baseline (null: the baseline was incomplete)"
    )
    fault_class: str | None = Field(description="the recording's own diagnosis")
    class_probabilities: dict[str, float] = Field(description="the recording's own")
    asset: AssetState = Field(  # type: ignore[valid-type]
        description="the asset's state after the recording (the Diagnosis contract's `asset`)"
    )


class AssetRecordings(BaseModel):
    asset_id: str
    count: int
    total: int = Field(description="recordings in the asset's history")
    truncated: bool
    recordings: list[AssetRecording] = Field(description="in the order they were recorded")


class AssetSummary(BaseModel):
    """One asset: what is stored for it and its latest diagnosis."""

    asset_id: str
    diagnoses: int = Field(description="diagnoses stored")
    with_operating_hours: int = Field(description="of which sent with operating hours")
    operating_hours: float | None = Field(description="the largest operating hours sent [h]")
    first_received_at: str
    last_received_at: str
    latest: LatestDiagnosis
    spectra_received_at: str | None = Field(
        description="when the stored spectra of the latest window came (None: none stored)"
    )
    baseline: AssetBaseline | None = Field(
        description="the asset's own baseline (null: none of its recordings recorded yet)"
    )
    evidence: AssetEvidence | None = Field(
        description="its accumulated evidence after its latest recording (null: none recorded)"
    )
    status: AssetStatus = Field(description="healthy, unknown, watch or alarm, and why")
    prognosis: PrognosisBrief | None = Field(
        None, description="with `prognosis=true`: the RUL in brief, or why there is none"
    )


class AssetList(BaseModel):
    count: int
    total: int = Field(description="assets stored")
    truncated: bool
    assets: list[AssetSummary] = Field(description="most recently seen first")


class SpectrumPoints(BaseModel):
    frequency: list[float] = Field(description="[Hz]")
    amplitude: list[float] = Field(description="[m/s²]")


class EnvelopeSpectrum(SpectrumPoints):
    band: list[float] = Field(description="band-pass of the envelope (low, high) [Hz]")
    sk: float = Field(description="spectral kurtosis of the band")
    impulsive: bool = Field(description="whether the band's SK is above the noise threshold")
    modulation_limit: float = Field(description="highest frequency the band carries [Hz]")


class DefectLine(BaseModel):
    amplitude: float | None = Field(description="envelope amplitude at the frequency [m/s²]")
    ratio: float | None = Field(description="line-to-floor ratio")
    ratio_sum: float | None = Field(description="sum of the ratios of the first harmonics")


class Spectra(BaseModel):
    """Spectra of the latest window of an asset's latest recording with a nut axial
    acceleration (``prsm_health.signals.envelope_analysis.window_spectra``)."""

    asset_id: str
    received_at: str
    source: str
    filename: str | None
    window: WindowSpan | None  # type: ignore[valid-type]
    operating_hours: float | None = Field(description="[h]")
    channel: str = Field(description="nut_axial_accel")
    sample_rate: float = Field(description="[Hz]")
    samples: int = Field(description="samples in the window")
    screw_speed: float | None = Field(description="the window's mean screw speed [rad/s]")
    spectrum: SpectrumPoints = Field(
        description="amplitude spectrum (Hann), at most 2048 log-spaced peak-keeping points"
    )
    envelope: EnvelopeSpectrum | None = Field(
        description="envelope amplitude spectrum up to the band's modulation limit; None when "
        "no band fits (envelope_note says why)"
    )
    envelope_note: str | None = None
    frequencies: dict[str, float] = Field(
        description="defect frequencies at the window's mean screw speed, and gear_mesh [Hz]"
    )
    lines: dict[str, DefectLine] = Field(description="envelope lines at the defect frequencies")


class Health(BaseModel):
    status: str
    model: str
    version: str
    uptime_s: float
    warm: bool
    active_diagnoses: int


class ModelInfo(BaseModel):
    name: str
    version: str
    window: float = Field(description="window length [s]")
    design: str
    sample_rate: float | None = Field(description="training sample rate [Hz]")
    feature_names: list[str]
    classes: list[str]
    clearance_range: list[float] | None = Field(description="[m]")
    saved_at: str | None
    versions: dict
    metrics: dict | None


class CommissioningBody(BaseModel):
    """An asset's commissioning: its thread half-clearance as built, measured at assembly. Its
    baseline health checks then fix its own compliance chain, and every later check's
    clearance is measured against it (docs/diagnostics.md, "Clearance measured by physics")."""

    model_config = ConfigDict(extra="forbid")

    as_built_clearance: float = Field(
        ge=-20e-6, le=200e-6, description="the half-clearance as built [m], e.g. 6e-6"
    )


class Error(BaseModel):
    error: str


#: Error answers shared by the routes' OpenAPI documentation.
ERROR_RESPONSES = {
    401: {"model": Error, "description": "missing or invalid bearer token"},
    413: {"model": Error, "description": "request or recording too large"},
    422: {"model": Error, "description": "invalid request"},
    503: {"model": Error, "description": "too many diagnoses in progress"},
}


def parse_diagnose_request(body: bytes, limits: ServiceLimits) -> DiagnoseRequest:
    """The JSON body of ``POST /v1/diagnose``, validated against the model and ``limits``;
    :class:`HTTPError` 422 with one message otherwise."""
    try:
        return DiagnoseRequest.model_validate_json(body, context={"limits": limits})
    except ValidationError as exc:
        raise HTTPError(
            422, format_errors(exc.errors(include_url=False, include_input=False))
        ) from None


#: How a query parameter's pydantic error reads (by error type; others: pydantic's message).
_QUERY_WORDS = {
    "float_parsing": "{name} = {text!r}: a finite number expected",
    "finite_number": "{name} = {text!r}: a finite number expected",
    "string_pattern_mismatch": "{name} {text!r} must match {pattern}",
    "literal_error": "{name} = {text!r}: one of {expected}",
}


def parse_query_params(items: list[tuple[str, str]]) -> DiagnoseParams:
    """The query parameters of a binary body, checked by the model that checks a JSON body's
    fields (:class:`DiagnoseParams`, numbers parsed from text); :class:`HTTPError` 422
    naming the parameter otherwise."""
    names = list(DiagnoseParams.model_fields)
    values: dict[str, str] = {}
    for name, text in items:
        if name not in names:
            raise HTTPError(
                422, f"unknown query parameter {name!r}; a binary body takes {', '.join(names)}"
            )
        if name in values:
            raise HTTPError(422, f"query parameter {name!r} given twice")
        values[name] = text
    try:
        return DiagnoseParams.model_validate(values, strict=False)
    except ValidationError as exc:
        e = exc.errors(include_url=False)[0]
        name = str(e["loc"][0])
        ctx = {k: str(v).replace("'", "") for k, v in (e.get("ctx") or {}).items()}
        template = _QUERY_WORDS.get(e["type"], "{name} = {text!r}: {msg}")
        text = values[name][: 140 if name == "asset_id" else 40]
        raise HTTPError(422, template.format(name=name, text=text, msg=e["msg"], **ctx)) from None


def format_errors(errors: list[dict], prefix: str = "") -> str:
    """One message from pydantic errors: unknown channels first, then the first few others."""
    unknown_channels = [
        str(e["loc"][1])
        for e in errors
        if e["type"] == "extra_forbidden" and len(e["loc"]) == 2 and e["loc"][0] == "channels"
    ]
    parts = []
    if unknown_channels:
        names = ", ".join(repr(n) for n in unknown_channels)
        truth = [n for n in unknown_channels if n in TRUTH_NAMES or n.startswith(TRUTH_PREFIX)]
        hint = (
            f" ({', '.join(truth)}: simulator truth, not a measurement; leave it out)"
            if truth
            else ""
        )
        parts.append(
            f"unknown channel(s) {names}; contract channels: {', '.join(CHANNEL_NAMES)}{hint}"
        )
    others = [
        e for e in errors if not (e["type"] == "extra_forbidden" and e["loc"][:1] == ("channels",))
    ]
    for e in others[:3]:
        loc = ".".join(str(p) for p in e["loc"])
        where = f"{prefix}{loc}" if loc else (prefix.rstrip(".") or "body")
        if e["type"] == "extra_forbidden":
            parts.append(f"unknown field {where!r}")
        else:
            parts.append(f"{where}: {e['msg']}")
    if len(others) > 3:
        parts.append(f"and {len(others) - 3} more error(s)")
    return "; ".join(parts) or "invalid request"


def add_request_schema(schema: dict, limits: ServiceLimits) -> None:
    """Put the ``DiagnoseRequest`` schema (and its ``Channels``) into an OpenAPI document's
    components, with the sample-rate bounds of ``limits`` (the body is validated in a worker
    thread, not by FastAPI, so FastAPI does not document it)."""
    request = DiagnoseRequest.model_json_schema(ref_template="#/components/schemas/{model}")
    components = schema.setdefault("components", {}).setdefault("schemas", {})
    components.update(request.pop("$defs", {}))
    rate = request["properties"]["sample_rate"]
    rate["minimum"], rate["maximum"] = limits.min_sample_rate, limits.max_sample_rate
    components["DiagnoseRequest"] = request


def document_limits(schema: dict, limits: ServiceLimits) -> None:
    """Write the bounds of ``limits`` that routes check at run time into an OpenAPI document."""
    add_request_schema(schema, limits)
    for path in ("/v1/assets/{asset_id}/history", "/v1/assets", "/v1/assets/{asset_id}/evidence"):
        for parameter in schema["paths"][path]["get"]["parameters"]:
            if parameter["name"] == "limit":
                parameter["schema"]["maximum"] = limits.max_history
