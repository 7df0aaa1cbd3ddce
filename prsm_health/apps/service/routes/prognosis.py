"""``GET /v1/assets/{asset_id}/prognosis``: the asset's stored diagnoses with operating hours
→ the library's prognosis of them (:func:`prsm_health.prognostics.prognose_readings`, as
``prognose --asset`` makes it) with the service's prognostics model."""

import threading
from collections import OrderedDict
from typing import Annotated, Literal

import anyio
from fastapi import APIRouter, Query
from fastapi import Path as PathParam

from prsm_health.monitoring.sqlite_store import HistoryStore
from prsm_health.prognostics import METHODS, HistoryError, prognose_readings

from ..responses import HTTPError, encode, json_response
from ..schemas import ASSET_ID_PATTERN, Error, Prognosis
from .deps import RULModel, Store

router = APIRouter()

NO_MODEL = (
    "no prognostics model loaded: start the service with --prognostics-model FILE (a model "
    "saved by prsm_health.prognostics.save_prognostics_model; default models/prognostics.json)"
)


#: Prognoses already made, by (model, method, asset, its readings): a prognosis is a pure
#: function of them (every method is seeded), and the physics method runs a particle filter
#: (≈ 1 s for 10 checks) where the fleet page asks one per asset on every load.
_MADE: OrderedDict = OrderedDict()
_MADE_LOCK = threading.Lock()
MADE_SIZE = 1024


def asset_prognosis(store: HistoryStore, model, asset_id: str, method: str | None = None) -> dict:
    """The asset's prognosis (``Prognosis.as_dict()``, the history's notes first in its
    warnings); :class:`HTTPError` 503 without a model, 404 for an unknown asset, 422 when the
    history does not allow one. Runs in a worker thread (reads the store); made once per
    model, method and readings (:data:`MADE_SIZE` kept)."""
    if model is None:
        raise HTTPError(503, NO_MODEL)
    if not store.has_asset(asset_id):
        raise HTTPError(404, f"no diagnoses stored for asset {asset_id!r}")
    rows = tuple(store.operating_history(asset_id))
    key = (model, method, asset_id, rows)  # the model by identity
    with _MADE_LOCK:
        if key in _MADE:
            _MADE.move_to_end(key)
            return _MADE[key]
    try:
        prognosis, _ = prognose_readings(rows, model, method, asset=f"asset {asset_id!r}")
    except HistoryError as exc:
        raise HTTPError(422, str(exc)) from None
    answer = prognosis.as_dict()
    with _MADE_LOCK:
        _MADE[key] = answer
        while len(_MADE) > MADE_SIZE:
            _MADE.popitem(last=False)
    return answer


@router.get(
    "/v1/assets/{asset_id}/prognosis",
    summary="Remaining useful life of an asset from its stored diagnoses",
    response_model=None,
    responses={
        200: {"model": Prognosis},
        404: {"model": Error, "description": "no diagnosis stored for this asset"},
        422: {
            "model": Error,
            "description": "fewer than 2 diagnoses with operating hours, a design other than "
            "the prognostics model's, bad query parameters",
        },
        503: {"model": Error, "description": "no prognostics model loaded"},
    },
)
async def get_prognosis(
    asset_id: Annotated[str, PathParam(pattern=ASSET_ID_PATTERN)],
    store: Store,
    model: RULModel,
    method: Annotated[
        Literal[METHODS] | None,  # type: ignore[valid-type]
        Query(
            description="degradation (default: the form chosen when the model was fitted), "
            "similarity, physics (the progpy ageing model, in models fitted on a fleet "
            "dataset), or a forced degradation form"
        ),
    ] = None,
):
    """The RUL [h] with its 90 % interval, from the asset's diagnoses that were sent with
    `operating_hours`, ordered by operating hours (of several at the same hours, the latest
    received)."""
    if model is None:
        raise HTTPError(503, NO_MODEL)

    def compute() -> bytes:
        return encode(asset_prognosis(store, model, asset_id, method))

    return json_response(await anyio.to_thread.run_sync(compute))
