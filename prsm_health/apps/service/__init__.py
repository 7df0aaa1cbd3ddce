"""HTTP diagnostics service: ``prsm-health serve`` (FastAPI on uvicorn).

The service only parses requests, calls the diagnosis library (:mod:`prsm_health.diagnostics.diagnosis`)
and formats its results; no physics and no feature logic live here. Endpoints (API reference
and curl examples in docs/service.md):

* ``POST /v1/diagnose`` — JSON body with ``sample_rate`` [Hz] and contract ``channels``, or
  the recording as a binary body (Arrow IPC stream, Parquet, MCAP: decoded by
  :mod:`prsm_health.io`, asset and operating point as query parameters); returns the Diagnosis
  contract (docs/service.md; ``windows`` only when the recording spans more than one model
  window);
* ``POST /v1/diagnose/file`` — multipart upload of a ``.mcap`` or ``.parquet`` recording;
  returns the whole-recording diagnosis and the per-window diagnoses;
* ``GET /v1/assets/{asset_id}/history`` — diagnoses stored for an asset, oldest first;
* ``GET /v1/assets/{asset_id}/prognosis`` — remaining useful life from the asset's diagnoses
  sent with ``operating_hours`` (:mod:`prsm_health.prognostics.rul`, the prognostics model loaded
  at start);
* ``GET /v1/health``, ``GET /v1/model``, and the OpenAPI document at ``/openapi.json``.

Safety: the service binds 127.0.0.1 by default; with a bearer token (``token`` argument or
the ``PRSM_HEALTH_TOKEN`` environment variable) every endpoint requires
``Authorization: Bearer <token>``, and :func:`serve` refuses a non-loopback address without
one. Request bodies, recording lengths and sample rates are bounded (:class:`ServiceLimits`);
user errors are 4xx responses ``{"error": "…"}``; a compressed body or upload is checked
against the limits from the sizes it declares before it is decoded. Uploads are streamed into a
private temporary directory removed after the request. Parsing and diagnosis run in worker threads
(at most :attr:`ServiceLimits.workers` at once) so ``/v1/health`` answers while they run.

History is kept in SQLite (:class:`HistoryStore`): WAL journal, one transaction per request,
the schema created when missing and migrated when older (version 1 → 2: ``operating_hours``).

Modules: :mod:`.limits` (ServiceLimits), :mod:`.history` (HistoryStore), :mod:`.schemas`
(pydantic models), :mod:`.uploads` (multipart streaming), :mod:`.security` (token and body
size guard), :mod:`.workers` (worker pool), :mod:`.diagnosing` (the work done in worker
threads), :mod:`.routes` (endpoints), :mod:`.handlers` (error answers), :mod:`.app`
(create_app), :mod:`.server` (serve).
"""

from prsm_health.monitoring.sqlite_store import (
    DB_ENV,
    HistoryStore,
    default_db_path,
    parse_time,
    utc_now,
)

from .app import create_app
from .limits import MAX_ABS_VALUE, ServiceLimits
from .schemas import ASSET_ID_PATTERN
from .server import TOKEN_ENV, bind_socket, check_bind, is_loopback, serve
from .uploads import UPLOAD_SUFFIXES

__all__ = [
    "ASSET_ID_PATTERN",
    "DB_ENV",
    "MAX_ABS_VALUE",
    "TOKEN_ENV",
    "UPLOAD_SUFFIXES",
    "HistoryStore",
    "ServiceLimits",
    "bind_socket",
    "check_bind",
    "create_app",
    "default_db_path",
    "is_loopback",
    "parse_time",
    "serve",
    "utc_now",
]
