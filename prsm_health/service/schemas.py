"""Request and response models of the API (pydantic), and the one formatting of their errors.

The models are fixed; the bounds that depend on :class:`ServiceLimits` are applied where the
limits are known: a request body is validated with ``context={"limits": limits}``
(:func:`parse_diagnose_request`), which checks ``sample_rate`` against the limits with
pydantic's own error types and messages, and :func:`document_limits` writes the same bounds
into the app's OpenAPI document.
"""

from __future__ import annotations

from typing import Annotated, Literal

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

from ..channels import CHANNEL_NAMES, CHANNELS, TRUTH_NAMES, TRUTH_PREFIX
from ..design import PRESETS
from .limits import MAX_OPERATING_HOURS, ServiceLimits
from .responses import HTTPError

#: Pattern of an asset id (also a URL path segment).
ASSET_ID_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9._:-]{0,127}$"
_DEFAULT_LIMITS = ServiceLimits()

Finite = Annotated[float, Field(allow_inf_nan=False)]
#: What ``operating_hours`` of a diagnose request means (JSON field and query parameter).
OPERATING_HOURS_DESCRIPTION = (
    "operating hours of the asset when the recording was made [h], 0 – 1e7; stored with the "
    "diagnosis and used by GET /v1/assets/{asset_id}/prognosis"
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


class DiagnoseRequest(BaseModel):
    """A recording to diagnose: uniformly sampled contract channels."""

    model_config = ConfigDict(strict=True, extra="forbid")
    sample_rate: Finite = Field(description="sample rate [Hz]")
    channels: Channels  # type: ignore[valid-type]
    design: Literal[tuple(sorted(PRESETS))] | None = Field(  # type: ignore[valid-type]
        None, description="design preset of the actuator (must match the model's)"
    )
    speed: Finite | None = Field(None, description="nominal screw speed [rad/s] (stored)")
    load: Finite | None = Field(None, description="nominal axial load [N] (stored)")
    operating_hours: Finite | None = Field(
        None,
        ge=0,
        le=MAX_OPERATING_HOURS,
        description=OPERATING_HOURS_DESCRIPTION,
    )
    asset_id: str | None = Field(
        None,
        pattern=ASSET_ID_PATTERN,
        description="store the diagnosis in this asset's history",
    )
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


class Clearance(BaseModel):
    estimate: float | None = Field(description="clearance estimate [m]")
    lower: float | None = Field(description="lower bound of the 90 % interval [m]")
    upper: float | None = Field(description="upper bound of the 90 % interval [m]")


class ModelRef(BaseModel):
    name: str
    version: str
    design: str = Field(description="design the model was trained for")


class WindowRef(BaseModel):
    index: int
    start: float = Field(description="[s]")
    end: float = Field(description="[s]")


class WindowDiagnosis(BaseModel):
    clearance: Clearance
    fault_class: str | None = Field(
        description="the class, or cannot_tell (fault not observable, or several classes in "
        "the class set)"
    )
    class_probabilities: dict[str, float]
    class_set: list[str] = Field(
        default_factory=list,
        description="classes the evidence cannot rule out (the model's conformal class set)",
    )
    observability: dict[str, bool] = Field(
        description="clearance, fault: whether the window lets the model see them"
    )
    ood_score: float | None = Field(
        description="out-of-distribution score (1 = training 99th percentile; > 1.5 unlike it)"
    )
    indicators: dict[str, float | None]
    indicator_groups: dict[str, str] = Field(description="group → computed, or why not")
    model: ModelRef
    window: WindowRef
    warnings: list[str] = Field(description="sentences a person can act on")


class Diagnosis(BaseModel):
    """The Diagnosis contract (docs/service.md)."""

    clearance: Clearance
    fault_class: str | None = Field(
        description="the class, or cannot_tell (fault not observable, or several classes in "
        "the class set)"
    )
    class_probabilities: dict[str, float]
    class_set: list[str] = Field(
        default_factory=list,
        description="classes the evidence cannot rule out (the model's conformal class set)",
    )
    observability: dict[str, float] = Field(
        description="clearance, fault: fraction of the windows that let the model see them"
    )
    ood_score: float | None = Field(description="median out-of-distribution score of the windows")
    indicators: dict[str, float | None]
    indicator_groups: dict[str, str] = Field(description="group → computed, or why not")
    model: ModelRef
    warnings: list[str] = Field(
        description="sentences a person can act on: why a target is not observable, a missing "
        "channel, a recording outside the trained range, a tail left undiagnosed"
    )
    windows: list[WindowDiagnosis] | None = Field(
        None, description="per-window diagnoses, present when there is more than one window"
    )


class RecordingInfo(BaseModel):
    filename: str
    samples: int
    sample_rate: float = Field(description="[Hz]")
    duration: float = Field(description="[s]")
    channels: list[str]


class FileDiagnosis(BaseModel):
    diagnosis: Diagnosis
    windows: list[WindowDiagnosis]
    recording: RecordingInfo
    warnings: list[str]


class HistoryEntry(BaseModel):
    id: int
    received_at: str = Field(description="server receive time, UTC ISO-8601")
    source: str = Field(description="'json' or 'file'")
    filename: str | None
    window: WindowRef | None
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


class RulHours(BaseModel):
    estimate: float = Field(description="median remaining useful life [h]")
    lower: float = Field(description="5 % quantile [h] (lower bound of the 90 % interval)")
    upper: float = Field(description="95 % quantile [h] (upper bound of the 90 % interval)")


class HealthIndicator(BaseModel):
    name: str = Field(description="clearance")
    unit: str = Field(description="m")
    threshold: float = Field(description="clearance at which the unit fails [m]")
    ages_hours: list[float] = Field(description="operating hours of the diagnoses used [h]")
    values: list[float] = Field(description="their clearance estimates [m]")
    lower: list[float] = Field(description="their 90 % interval lower bounds [m]")
    upper: list[float] = Field(description="their 90 % interval upper bounds [m]")
    current: float = Field(description="the latest clearance estimate [m]")


class PrognosisModel(BaseModel):
    """The prognostics model and, by method, its posterior or similarity details."""

    model_config = ConfigDict(extra="allow")
    name: str = Field(
        description="degradation-exponential, degradation-linear or similarity (the method used)"
    )
    version: str
    design: str = Field(description="design the prognostics model is for")
    units_trained: int
    threshold: float = Field(description="[m]")
    horizon_hours: float = Field(description="RUL cap [h]")


class Prognosis(BaseModel):
    """Remaining useful life of an asset (``prsm_health.prognostics.Prognosis.as_dict``)."""

    rul_hours: RulHours
    health_indicator: HealthIndicator
    model: PrognosisModel
    warnings: list[str] = Field(description="what limits the answer")


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
    history = schema["paths"]["/v1/assets/{asset_id}/history"]["get"]
    for parameter in history["parameters"]:
        if parameter["name"] == "limit":
            parameter["schema"]["maximum"] = limits.max_history
