"""The steps of monitoring an asset, the same for the CLI and the service: its **baseline**
(:func:`asset_baseline`) → the recording's **diagnosis** against it
(:func:`prsm_health.diagnostics.diagnosis.diagnose`) → the diagnosis **recorded** in its
history (:func:`record_diagnosis`: baseline membership, evidence, change statistic, the
asset's state attached to the diagnosis). :func:`diagnose_asset` runs the three under the
asset's lock; the service runs the diagnosis in a worker between the other two (the record is
made against the history as it is then, so a concurrent request's update is never lost).

Any :class:`~.store.AssetStore` works: the CLI's files, the service's SQLite database.
"""

from __future__ import annotations

from prsm_health.diagnostics.baseline import Baseline
from prsm_health.diagnostics.contract import Diagnosis

from .asset import bundle_priors, validate_asset_id
from .store import AssetStore


def asset_baseline(store: AssetStore, bundle, asset_id: str) -> Baseline | None:
    """The asset's baseline a recording is diagnosed against: that of its health checks,
    fitted with the model's prior scale (its within-unit repeatability, or the spread of its
    training windows: :func:`~.asset.bundle_priors`); None until it has enough recordings. Only a health
    check is read against a baseline (:func:`~prsm_health.diagnostics.diagnosis.diagnose`)."""
    return _check_baseline(store.load(asset_id).history, bundle)


def _check_baseline(history, bundle) -> Baseline | None:
    prior_scale, _, names = bundle_priors(bundle, check=True)
    return history.baseline(prior_scale, names)


def asset_reference(store: AssetStore, bundle, asset_id: str):
    """(baseline, commissioning) of an asset, what a recording of it is read against:
    :func:`asset_baseline` and its :meth:`~.asset.AssetHistory.commissioning` (None without an
    as-built clearance), from one load of its history."""
    history = store.load(asset_id).history
    return _check_baseline(history, bundle), history.commissioning()


def commission(store: AssetStore, asset_id: str, as_built_clearance: float) -> None:
    """Give an asset its as-built clearance [m] (measured at assembly): its baseline checks
    then fix the clearance gauge's constant offset (:meth:`~.asset.AssetHistory.commissioning`).
    Giving it again replaces it."""
    from dataclasses import replace

    from prsm_health.core.errors import require_range

    require_range("as_built_clearance", as_built_clearance, -20e-6, 200e-6, unit="m")

    def change(history):
        return replace(history, as_built_clearance=float(as_built_clearance)), None

    store.update(validate_asset_id(asset_id), change)


def record_diagnosis(
    store: AssetStore,
    bundle,
    asset_id: str,
    recording_id: str,
    diagnosis: Diagnosis,
    *,
    healthy: bool | None = None,
    operating_hours: float | None = None,
    time: str = "",
    source: str = "",
    filename: str | None = None,
    extra=None,
) -> Diagnosis:
    """Record ``diagnosis`` in the asset's history and save it: the diagnosis with the
    asset's state (``asset``) and the history's notes. Recording the same ``recording_id``
    again changes nothing (:meth:`~.asset.AssetHistory.record`).

    The baseline, evidence and priors are those of the kind of recording the diagnosis read:
    a health check read phase by phase (``check_phases``), else windows. ``extra``:
    ``extra(new history, recorded diagnosis)`` gives what the store keeps beside the history
    in the same write (:meth:`~.store.AssetStore.update`)."""
    prior_scale, training_prior, names = bundle_priors(bundle, check=bool(diagnosis.check_phases))

    def change(history):
        return history.record(
            recording_id,
            diagnosis,
            healthy=healthy,
            operating_hours=operating_hours,
            time=time,
            prior_scale=prior_scale,
            training_prior=training_prior,
            names=names,
            source=source,
            filename=filename,
        )

    _, recorded = store.update(validate_asset_id(asset_id), change, extra=extra)
    return recorded


def diagnose_asset(
    run,
    bundle,
    store: AssetStore,
    asset_id: str,
    recording_id: str,
    *,
    healthy: bool | None = None,
    operating_hours: float | None = None,
    time: str = "",
    window: float | None = None,
    source: str = "file",
    filename: str | None = None,
) -> Diagnosis:
    """Diagnose a recording of an asset against its baseline and record it (what
    ``prsm-health diagnose --asset`` does): :func:`asset_baseline` → ``diagnose`` →
    :func:`record_diagnosis`, under the asset's lock. A recording already recorded is
    diagnosed again and shown with the state stored then; the history is not written again."""
    from prsm_health.diagnostics.diagnosis import diagnose  # the model's dependencies here only

    validate_asset_id(asset_id)
    with store.locked(asset_id):
        baseline, commissioning = asset_reference(store, bundle, asset_id)
        diagnosis = diagnose(
            run, bundle, window=window, baseline=baseline, commissioning=commissioning
        )
        return record_diagnosis(
            store,
            bundle,
            asset_id,
            recording_id,
            diagnosis,
            healthy=healthy,
            operating_hours=operating_hours,
            time=time,
            source=source,
            filename=filename,
        )


__all__ = ["asset_baseline", "asset_reference", "commission", "diagnose_asset", "record_diagnosis"]
