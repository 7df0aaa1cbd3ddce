"""The work done in worker threads or diagnosis processes: a request body (JSON, or a binary
recording decoded by :mod:`prsm_health.io`) or an upload (with its column map) → a
:class:`~prsm_health.core.run.Run` → the library's diagnosis (:class:`Answer`). Recordings are
read by the library's one reader (:func:`prsm_health.io.read_with_warnings`: the reader
``diagnose`` and ``import`` use), recording checks are :meth:`Run.validate
<prsm_health.core.run.Run.validate>`'s, and each request cuts its recording into windows once
(:func:`~prsm_health.diagnostics.diagnosis.split_windows`).

A request without an asset comes back as its encoded answer. A request naming an asset comes
back as the recording's diagnosis and what the asset's history needs (:class:`AssetRequest`);
the server records it with :func:`prsm_health.monitoring.record_diagnosis` — the step ``prsm-health
diagnose --asset`` takes too — and encodes the answer once (:func:`record_and_encode`).
Everything that crosses to and from a diagnosis process is plain data (bytes, frozen values).
"""

from __future__ import annotations

import dataclasses
import logging
import re
from dataclasses import dataclass

import numpy as np

from prsm_health.core.channels import CHANNEL_NAMES
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.identifiers import content_id, run_content_id
from prsm_health.core.jsonable import json_ready
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import MIN_SAMPLES, Run
from prsm_health.diagnostics.baseline import Baseline
from prsm_health.diagnostics.check_model import is_check
from prsm_health.diagnostics.clearance_gauge import Commissioning
from prsm_health.diagnostics.contract import Diagnosis
from prsm_health.diagnostics.diagnosis import diagnose, split_windows
from prsm_health.io import read_with_warnings
from prsm_health.io.column_map import column_map_from_text
from prsm_health.io.derived import derive_channels
from prsm_health.monitoring.sqlite_store import HistoryStore, history_rows, spectra_row
from prsm_health.monitoring.steps import record_diagnosis
from prsm_health.signals.envelope_analysis import window_spectra

from .limits import MAX_ABS_VALUE, MAX_TIME, ServiceLimits
from .responses import HTTPError, encode
from .schemas import DiagnoseRequest, parse_diagnose_request
from .uploads import ReceivedUpload, precheck_recording, precheck_upload

log = logging.getLogger("prsm_health.apps.service")


def diagnosis_json(run: Run, bundle, windows: tuple | None = None) -> dict:
    """The library's diagnosis of ``run`` as a JSON-ready dict (with ``windows``);
    ``windows``: ``run`` already cut by :func:`split_windows` with the model's window."""
    return json_ready(diagnose(run, bundle, windows=windows).to_json())


def check_run(run: Run, limits: ServiceLimits, *, max_samples: int, what: str = "") -> None:
    """The service's sample-rate range, then the library's recording checks (``RecordingError``:
    422, ``RecordingTooLongError``: 413)."""
    limits.check_sample_rate(run.sample_rate, what)
    run.validate(
        min_samples=MIN_SAMPLES,
        max_samples=max_samples,
        max_abs=MAX_ABS_VALUE,
        max_time=MAX_TIME,
        what=what or "recording",
    )


def warm_up(bundle) -> None:
    """Diagnose recordings of noise: walks the whole diagnosis path (JIT compilation, caches),
    so the first request does not pay for it. Not blank ones: constant channels skip compiled
    kernels that a measured recording runs (8 s at the first request). Twice, two windows
    each: with writable channels (JSON bodies, uploads) and with read-only ones (as an Arrow or
    Parquet body decodes to: numba compiles its kernels again for read-only arrays)."""
    rate = float(bundle.metadata.get("sample_rate") or 20000.0)
    n = 2 * max(MIN_SAMPLES, int(round(bundle.window * rate)))
    rng = np.random.default_rng(0)
    noise = {name: rng.standard_normal(n) for name in CHANNEL_NAMES}
    time = np.arange(n) / rate
    diagnosis_json(Run(time, noise, rate), bundle)
    for values in noise.values():
        values.flags.writeable = False
    diagnosis_json(Run(time, noise, rate), bundle)


#: The channel whose spectra are stored for each asset's latest window.
SPECTRA_CHANNEL = "nut_axial_accel"


@dataclass(frozen=True)
class AssetRequest:
    """What a diagnose request says about its recording's asset: the asset, the recording's
    id (given, else from its content: :func:`~prsm_health.core.identifiers.content_id`), how it
    came (``source``: the body format or ``file``), its file name, the label ``healthy``, the
    asset's operating hours [h] and the nominal speed [rad/s] and load [N] given with it."""

    asset_id: str
    recording_id: str
    source: str
    filename: str | None = None
    healthy: bool | None = None
    operating_hours: float | None = None
    speed: float | None = None
    load: float | None = None


@dataclass(frozen=True)
class Answer:
    """What a diagnose request gives back to the route: without an asset, the encoded JSON
    answer (``encoded``); with one, the recording's ``diagnosis`` (its windows kept), the
    ``asset`` request, the spectra row of its last window (None without a nut axial
    acceleration) and, for an upload, the answer's other parts (``upload``: ``recording`` and
    ``warnings``), made into the answer once the diagnosis is recorded
    (:func:`record_and_encode`)."""

    encoded: bytes = b""
    diagnosis: Diagnosis | None = None
    asset: AssetRequest | None = None
    spectra: tuple | None = None
    upload: dict | None = None


def record_and_encode(store: HistoryStore, bundle, answer: Answer, received_at: str) -> bytes:
    """Record an asset's recording in its history (:func:`prsm_health.monitoring.record_diagnosis`)
    with the request's diagnosis rows and spectra in the same transaction, and encode the
    answer — the diagnosis with the asset's state — once. A JSON or binary body is stored as
    one row; an upload as one row per window, or one for the whole recording when it was read
    whole (a health check read phase by phase)."""
    a = answer.asset
    windows = answer.diagnosis.windows
    made = {}

    def rows(_history, recorded: Diagnosis):
        result = json_ready(dataclasses.replace(recorded, windows=windows).to_json())
        texts = None
        if answer.upload is None:  # one row: the answer itself, stored as sent
            if len(result.get("windows", [])) <= 1:
                result.pop("windows", None)
            made["answer"] = encode(result)
            stored, texts = [result], [made["answer"].decode()]
        else:
            per_window = result.pop("windows", [])
            made["answer"] = encode({"diagnosis": result, "windows": per_window, **answer.upload})
            stored = per_window or [result]
        history = history_rows(
            a.asset_id,
            stored,
            received_at=received_at,
            source=a.source,
            filename=a.filename,
            speed=a.speed,
            load=a.load,
            operating_hours=a.operating_hours,
            texts=texts,
        )
        return history, answer.spectra

    record_diagnosis(
        store,
        bundle,
        a.asset_id,
        a.recording_id,
        dataclasses.replace(answer.diagnosis, windows=[]),
        healthy=a.healthy,
        operating_hours=a.operating_hours,
        time=received_at,
        source=a.source,
        filename=a.filename,
        extra=rows,
    )
    return made["answer"]


def last_window_spectra(
    last: Run, bundle, asset_id: str, window: dict | None, **row
) -> tuple | None:
    """The spectra row of the recording's last window ``last`` (the one the diagnosis was
    given: :func:`split_windows` with the model's window):
    :func:`prsm_health.signals.envelope_analysis.window_spectra` of its nut axial acceleration
    at its mean screw speed, with the model's design. None when the recording has no nut axial
    acceleration. ``window``: the last window's index and span in the recording (stored; None
    for a recording read whole); ``row``: :func:`spectra_row`'s keywords."""
    if SPECTRA_CHANNEL not in last.channels:
        return None
    speed = last.channels.get("screw_speed")
    try:
        spectra = window_spectra(
            last.channels[SPECTRA_CHANNEL],
            float(last.sample_rate),
            bundle.design,
            None if speed is None else float(np.mean(speed)),
        )
    except PRSMHealthError:  # the diagnosis stands; the asset keeps its previous spectra
        log.warning("no spectra for asset %r", asset_id, exc_info=True)
        return None
    return spectra_row(asset_id, spectra, window=window, channel=SPECTRA_CHANNEL, **row)


@dataclass(frozen=True)
class BodyParams:
    """The query parameters of a binary body (a JSON body carries them as fields)."""

    asset_id: str | None = None
    speed: float | None = None
    load: float | None = None
    design: str | None = None
    operating_hours: float | None = None
    gear_ratio: float | None = None
    healthy: bool | None = None
    recording_id: str | None = None


def check_design(design: str | None, bundle) -> None:
    if design is not None and design != bundle.design_name:
        raise HTTPError(
            422,
            f"design = {design!r}: model {bundle.name!r} was trained on design "
            f"{bundle.design_name!r}; load a model for {design!r} (prsm-health serve --model)",
        )


def run_from_request(req: DiagnoseRequest, bundle) -> Run:
    """The recording a validated request describes (channels of equal length, the model's
    design); the nominal speed, load and the reduction its operating point."""
    given = {name: getattr(req.channels, name) for name in CHANNEL_NAMES}
    channels = {
        name: np.asarray(values, dtype=float)
        for name, values in given.items()
        if values is not None
    }
    if not channels:
        raise HTTPError(
            422, f"channels: give at least one contract channel ({', '.join(CHANNEL_NAMES)})"
        )
    lengths = {name: len(v) for name, v in channels.items()}
    if len(set(lengths.values())) > 1:
        described = ", ".join(f"{k} {v}" for k, v in lengths.items())
        raise HTTPError(422, f"channels must have equal lengths; got {described}")
    check_design(req.design, bundle)
    n = next(iter(lengths.values()))
    rate = float(req.sample_rate)  # range checked by the request's validation
    operating = OperatingPoint(
        design=bundle.design_name,
        screw_speed=req.speed,
        axial_load=req.load,
        gear_ratio=1.0 if req.gear_ratio is None else req.gear_ratio,
    )
    # the channels a file reader derives (screw speed from the angle), derived here too
    return derive_channels(
        Run(float(req.time_start) + np.arange(n) / rate, channels, rate, operating=operating)
    )[0]


def _too_long(n: int, rate: float, limits: ServiceLimits) -> HTTPError:
    return HTTPError(
        413,
        f"recording too long: {n} samples = {n / rate:.6g} s at {rate:g} Hz; /v1/diagnose "
        f"accepts at most {limits.max_window_seconds:g} s per request (upload longer "
        "recordings to /v1/diagnose/file)",
    )


def read_body(body: bytes, fmt: str, limits: ServiceLimits) -> tuple[Run, list[str]]:
    """A binary body of ``POST /v1/diagnose`` (``fmt``: ``arrow``, ``parquet``, ``mcap``,
    ``csv`` with contract column names) as a measured recording, and the reader's notes. What
    the body declares (rows, decompressed size) is checked against the limits before it is
    decoded."""
    name = f"{fmt} body"
    if not body:
        raise HTTPError(400, f"empty request body: send the recording ({fmt})")
    precheck_recording(
        body,
        fmt,
        max_samples=limits.max_body_samples,
        max_decoded_bytes=limits.max_body_decoded_bytes,
        samples_hint=(
            f" by /v1/diagnose ({limits.max_window_seconds:g} s at "
            f"{limits.max_sample_rate:g} Hz; upload longer recordings to /v1/diagnose/file)"
        ),
        decoded_hint=" (max_body_decoded_bytes)",
        name=name,
    )
    return read_measured(body, fmt=fmt, name=name)


def read_measured(source, *, fmt: str, name: str, column_map=None) -> tuple[Run, list[str]]:
    """A recording (a file or bytes) through the library's reader: the measured run (a
    simulated file's truth is neither checked nor used) and the reader's notes. Anything the
    reader refuses is the client's: 422, naming the recording as the client did."""
    try:
        recording = read_with_warnings(source, fmt=fmt, name=name, column_map=column_map)
    except PRSMHealthError as exc:
        raise HTTPError(422, str(exc)) from None
    except (ValueError, TypeError, OverflowError, KeyError, IndexError) as exc:
        # Decoding client bytes: the readers let a few of these through for damaged files;
        # the file is at fault, not the server (no server path in the message: the reader
        # was given the client's name).
        log.warning("unreadable recording %r", name, exc_info=True)
        text = str(exc).replace(str(source), name) if not isinstance(source, bytes) else str(exc)
        raise HTTPError(
            422, f"{name}: not a readable recording ({type(exc).__name__}: {text})"
        ) from None
    return recording.run.without_truth(), list(recording.warnings)


def _windows(run: Run, cut: tuple) -> tuple | None:
    """The cut a diagnosis is given: none for a health-check recording, which the library reads
    phase by phase (with a model that has a check part) rather than window by window."""
    return None if is_check(run) else cut


def check_asset_fields(asset_id, healthy, recording_id, operating_hours=None) -> None:
    """``healthy``, ``recording_id`` and ``operating_hours`` are about the asset's history:
    422 without an asset."""
    given = [
        name
        for name, value in (
            ("healthy", healthy),
            ("recording_id", recording_id),
            ("operating_hours", operating_hours),
        )
        if value is not None
    ]
    if asset_id is None and given:
        given = given[0]
        raise HTTPError(
            422, f"{given} is about an asset's history: give asset_id with it (or leave it out)"
        )


def diagnose_body(
    bundle,
    body: bytes,
    fmt: str,
    params: BodyParams | None,
    limits: ServiceLimits,
    received_at: str,
    baseline: BaselineFor | None = None,
) -> Answer:
    """``POST /v1/diagnose``: a JSON body (``fmt`` ``"json"``, fields in the body) or a binary
    recording (``params`` from the query) → the Diagnosis contract (``windows`` only when the
    recording spans more than one model window); with an ``asset_id``, the diagnosis made
    with the asset's ``baseline`` (loaded for the asset the request names) for the server to
    record."""
    notes: list[str] = []
    if fmt == "json":
        req = parse_diagnose_request(body, limits)
        run = run_from_request(req, bundle)
        params = BodyParams(**{f: getattr(req, f) for f in BodyParams.__dataclass_fields__})
    else:
        params = params or BodyParams()
        check_design(params.design, bundle)
        run, notes = read_body(body, fmt, limits)
        given = {
            "design": params.design,
            "screw_speed": params.speed,
            "axial_load": params.load,
            "gear_ratio": params.gear_ratio,
        }
        operating = dataclasses.replace(
            run.operating, **{k: v for k, v in given.items() if v is not None}
        )
        run = dataclasses.replace(run, operating=operating)  # a check's phases kept
        limits.check_sample_rate(run.sample_rate, _what(fmt))  # a JSON body's is validated
    max_samples = limits.max_json_samples(run.sample_rate)
    if len(run) > max_samples:
        raise _too_long(len(run), run.sample_rate, limits)
    check_run(run, limits, max_samples=max(max_samples, MIN_SAMPLES), what=_what(fmt))
    check_asset_fields(params.asset_id, params.healthy, params.recording_id)
    cut = split_windows(run, bundle.window)  # once: the diagnosis and the spectra share it
    base = None if baseline is None else baseline.get(params.asset_id)
    commissioning = None if baseline is None else baseline.commissioning_of(params.asset_id)
    diagnosis = diagnose(
        run, bundle, windows=_windows(run, cut), baseline=base, commissioning=commissioning
    )
    if notes:
        diagnosis.warnings[:0] = notes
    if params.asset_id is None:
        result = json_ready(diagnosis.to_json())
        if len(result.get("windows", [])) <= 1:
            result.pop("windows", None)
        return Answer(encode(result))
    asset = AssetRequest(
        params.asset_id,
        params.recording_id or (content_id(body) if fmt != "json" else run_content_id(run)),
        source=fmt,
        healthy=params.healthy,
        operating_hours=params.operating_hours,
        speed=params.speed,
        load=params.load,
    )
    return Answer(
        diagnosis=diagnosis,
        asset=asset,
        spectra=_spectra(cut, bundle, diagnosis, asset, received_at),
    )


def _spectra(cut, bundle, diagnosis: Diagnosis, asset: AssetRequest, received_at: str):
    """The spectra row of the recording's last window (:func:`last_window_spectra`)."""
    window = diagnosis.windows[-1].to_json().get("window") if diagnosis.windows else None
    return last_window_spectra(
        cut[0][-1],
        bundle,
        asset.asset_id,
        window,
        received_at=received_at,
        source=asset.source,
        filename=asset.filename,
        operating_hours=asset.operating_hours,
    )


def _what(fmt: str) -> str:
    return "" if fmt == "json" else f"{fmt} body"


# ----------------------------------------------------------------------------- upload
def read_upload(upload: ReceivedUpload, limits: ServiceLimits) -> tuple[Run, list[str]]:
    """The uploaded recording, read through its column map when one came with it, and the
    reader's notes (truncated recording); messages name the client's file names, never the
    server path."""
    if upload.path is None or upload.file_bytes == 0:
        raise HTTPError(422, "no recording: send the file in the multipart field 'file'")
    column_map = None
    if upload.column_map is not None:
        try:
            column_map = column_map_from_text(upload.column_map, upload.map_name or "map")
        except PRSMHealthError as exc:
            raise HTTPError(422, str(exc)) from None
    precheck_upload(upload.path, upload.suffix, limits)
    return read_measured(
        upload.path,
        fmt=upload.suffix.lstrip("."),
        name=upload.filename or "upload",
        column_map=column_map,
    )


def diagnose_upload(
    bundle,
    upload: ReceivedUpload,
    limits: ServiceLimits,
    asset_id: str | None = None,
    received_at: str | None = None,
    baseline: BaselineFor | None = None,
    healthy: bool | None = None,
    recording_id: str | None = None,
    operating_hours: float | None = None,
) -> Answer:
    """``POST /v1/diagnose/file``: the whole-recording diagnosis, the per-window ones, what
    was read and the reader's notes; with an ``asset_id``, the diagnosis made with the asset's
    ``baseline`` for the server to record (at its ``operating_hours`` [h])."""
    run, notes = read_upload(upload, limits)
    check_run(run, limits, max_samples=limits.max_upload_samples, what=upload.filename or "upload")
    cut = split_windows(run, bundle.window)  # once: the diagnosis and the spectra share it
    base = None if baseline is None else baseline.get(asset_id)
    commissioning = None if baseline is None else baseline.commissioning_of(asset_id)
    diagnosis = diagnose(
        run, bundle, windows=_windows(run, cut), baseline=base, commissioning=commissioning
    )
    recording = {
        "filename": upload.filename,
        "samples": len(run),
        "sample_rate": float(run.sample_rate),
        "duration": float(len(run) / run.sample_rate),
        "channels": [c for c in CHANNEL_NAMES if c in run.channels],
    }
    rest = {"recording": recording, "warnings": notes}
    if asset_id is None:
        result = json_ready(diagnosis.to_json())
        per_window = result.pop("windows", [])
        return Answer(encode({"diagnosis": result, "windows": per_window, **rest}))
    if recording_id is None:  # the file's content, with its column map's
        recording_id = content_id(upload.path, upload.column_map)
    asset = AssetRequest(
        asset_id,
        recording_id,
        source="file",
        filename=upload.filename,
        healthy=healthy,
        operating_hours=operating_hours,
    )
    spectra = _spectra(cut, bundle, diagnosis, asset, received_at)
    return Answer(diagnosis=diagnosis, asset=asset, spectra=spectra, upload=rest)


@dataclass(frozen=True)
class BaselineFor:
    """The baseline of the asset a request names, as it crosses to the diagnosis worker
    (:func:`prsm_health.monitoring.asset_baseline`, loaded in the server; None while the
    asset's baseline is incomplete)."""

    asset_id: str
    baseline: Baseline | None = None
    commissioning: Commissioning | None = None

    def get(self, asset_id: str | None) -> Baseline | None:
        """The baseline, when the request's asset is the one it was loaded for (a JSON
        body's asset id is found before the body is parsed: :func:`peek_asset_id`)."""
        return self.baseline if asset_id == self.asset_id else None

    def commissioning_of(self, asset_id: str | None) -> Commissioning | None:
        """The asset's commissioning (:meth:`AssetHistory.commissioning
        <prsm_health.monitoring.asset.AssetHistory.commissioning>`), as :meth:`get`."""
        return self.commissioning if asset_id == self.asset_id else None


_ASSET_KEY = re.compile(rb'"asset_id"\s*:\s*"([A-Za-z0-9][A-Za-z0-9._:-]{0,127})"')


def peek_asset_id(body: bytes) -> str | None:
    """The asset id of a JSON body, found without parsing it (megabytes of samples): the last
    ``"asset_id": "…"`` key and plain value. Only a hint for loading the baseline before the
    diagnosis — the worker uses the baseline only for the asset id it parses
    (:meth:`BaselineFor.get`)."""
    at = body.rfind(b'"asset_id"')
    if at < 0:
        return None
    found = _ASSET_KEY.match(body, at)
    return None if found is None else found.group(1).decode()
