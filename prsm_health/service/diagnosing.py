"""The work done in worker threads: a request body or an upload → a :class:`~prsm_health.run.Run`
→ the library's diagnosis → JSON. The service's calls into :mod:`prsm_health.diagnosis`
(``diagnose`` in :func:`diagnosis_json`, ``read_recording`` in :func:`read_upload`) are here;
recording checks are :meth:`Run.validate <prsm_health.run.Run.validate>`'s.
"""

from __future__ import annotations

import logging
import threading
import warnings

import numpy as np

from ..channels import CHANNEL_NAMES
from ..diagnosis import diagnose
from ..errors import PRSMHealthError
from ..io import read_recording
from ..jsonable import json_ready
from ..run import MIN_SAMPLES, Run
from .limits import MAX_ABS_VALUE, MAX_TIME, ServiceLimits
from .responses import HTTPError, encode
from .schemas import DiagnoseRequest, parse_diagnose_request
from .uploads import ReceivedUpload, precheck_upload

log = logging.getLogger("prsm_health.service")

# warnings.catch_warnings changes process-wide state: one upload is read under it at a time.
_warnings_lock = threading.Lock()


def diagnosis_json(run: Run, bundle) -> dict:
    """The library's diagnosis of ``run`` as a JSON-ready dict (with ``windows``)."""
    return json_ready(diagnose(run, bundle).to_json())


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
    """Diagnose a blank recording: walks the whole diagnosis path once (JIT compilation,
    caches), so the first request does not pay for it."""
    rate = float(bundle.metadata.get("sample_rate") or 20000.0)
    n = max(MIN_SAMPLES, int(round(bundle.window * rate)))
    blank = {name: np.zeros(n) for name in CHANNEL_NAMES}
    diagnosis_json(Run(np.arange(n) / rate, blank, rate), bundle)


# ----------------------------------------------------------------------------- JSON body
def run_from_request(req: DiagnoseRequest, bundle) -> Run:
    """The recording a validated request describes (channels of equal length, the model's
    design); the nominal speed and load become labels."""
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
    if req.design is not None and req.design != bundle.design_name:
        raise HTTPError(
            422,
            f"design = {req.design!r}: model {bundle.name!r} was trained on design "
            f"{bundle.design_name!r}; load a model for {req.design!r} (prsm-health serve --model)",
        )
    n = next(iter(lengths.values()))
    rate = float(req.sample_rate)  # range checked by the request's validation
    labels = {"design": bundle.design_name}
    if req.speed is not None:
        labels["screw_speed"] = float(req.speed)
    if req.load is not None:
        labels["axial_load"] = float(req.load)
    return Run(float(req.time_start) + np.arange(n) / rate, channels, rate, labels)


def diagnose_body(bundle, body: bytes, limits: ServiceLimits):
    """``POST /v1/diagnose``: ``(request, diagnosis dict, encoded answer)``; ``windows`` only
    when the recording spans more than one model window."""
    req = parse_diagnose_request(body, limits)
    run = run_from_request(req, bundle)
    max_samples = limits.max_json_samples(run.sample_rate)
    if len(run) > max_samples:
        raise HTTPError(
            413,
            f"recording too long: {len(run)} samples = {len(run) / run.sample_rate:.6g} s at "
            f"{run.sample_rate:g} Hz; /v1/diagnose accepts at most "
            f"{limits.max_window_seconds:g} s per request (upload longer recordings to "
            "/v1/diagnose/file)",
        )
    check_run(run, limits, max_samples=max(max_samples, MIN_SAMPLES))
    result = diagnosis_json(run, bundle)
    if len(result.get("windows", [])) <= 1:
        result.pop("windows", None)
    return req, result, encode(result)


# ----------------------------------------------------------------------------- upload
def read_upload(upload: ReceivedUpload, limits: ServiceLimits) -> tuple[Run, list[str]]:
    """The uploaded recording and the reader's notes (truncated recording); messages name the
    client's file name, never the server path."""
    from ..errors import TruncatedRecordingWarning

    def hide_path(text: str) -> str:
        return text.replace(str(upload.path), upload.filename or "upload")

    if upload.path is None or upload.file_bytes == 0:
        raise HTTPError(422, "no recording: send the file in the multipart field 'file'")
    precheck_upload(upload.path, upload.suffix, limits)
    with _warnings_lock, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", TruncatedRecordingWarning)
        try:
            run = read_recording(upload.path)
        except PRSMHealthError as exc:
            raise HTTPError(422, hide_path(str(exc))) from None
        except (ValueError, TypeError, OverflowError, KeyError, IndexError) as exc:
            # Decoding client bytes: the readers let a few of these through for files
            # with non-numeric channel columns; the file is at fault, not the server.
            log.warning("unreadable upload %r", upload.filename, exc_info=True)
            raise HTTPError(
                422,
                f"{upload.filename}: not a readable recording "
                f"({type(exc).__name__}: {hide_path(str(exc))})",
            ) from None
    notes = [
        hide_path(str(w.message))
        for w in caught
        if issubclass(w.category, TruncatedRecordingWarning)
    ]
    # The service diagnoses measurements: a simulated file's truth is neither checked nor used.
    return run.without_truth(), notes


def diagnose_upload(bundle, upload: ReceivedUpload, limits: ServiceLimits):
    """``POST /v1/diagnose/file``: ``(answer dict, encoded answer)`` — the whole-recording
    diagnosis, the per-window ones, what was read and the reader's notes."""
    run, notes = read_upload(upload, limits)
    check_run(run, limits, max_samples=limits.max_upload_samples, what=upload.filename or "upload")
    result = diagnosis_json(run, bundle)
    per_window = result.pop("windows")
    recording = {
        "filename": upload.filename,
        "samples": len(run),
        "sample_rate": float(run.sample_rate),
        "duration": float(len(run) / run.sample_rate),
        "channels": [c for c in CHANNEL_NAMES if c in run.channels],
    }
    answer = {"diagnosis": result, "windows": per_window, "recording": recording, "warnings": notes}
    return answer, encode(answer)
