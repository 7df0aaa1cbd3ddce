"""A :class:`~prsm_health.simulation.scenario.Scenario` of a recirculating design through its
dynamic model (:mod:`.model`): the same :class:`~prsm_health.core.run.Run` as the standard
PRSM's — measured channels through the scenario's instrumentation, truth, labels, energy — for
what the model covers, and one error naming the field for what it does not yet.

Covered: the profile's screw motion turning forward or at rest (constant, ramp, trapezoid, a
health check of such phases) under its axial load — constant, sinusoidal
or reversing —, the thread clearances, and the faults of a recirculating unit: a spall on the
nut's loaded flank (on one thread turn of the n_t engaged: share 1/n_t, as the standard model's),
cam-chamfer wear, platform height loss, re-entry-edge damage (:mod:`prsm_health.actuator.faults`).
Truth beyond the standard's: ``cam_force`` (the largest summed cam force within each sample's
interval) and ``reset_count``.
The drive train around it is ideal and stiff up to the nut: the motor turns N times the screw
through the reduction (torque × 1/(N·η) while driving), the screw's thrust bearing holds it
axially; beyond the nut the drive train's linkage and payload are modelled (the load acts on the
payload, ``axial_load`` is the linkage's force on the nut) unless its ``load_application`` is
``"nut"`` (an ideal force on the nut, no payload). The axial model has no lateral motion (the nut's tangential
and radial accelerations are zero) and no friction (``friction_torque`` truth is zero).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from prsm_health.actuator.states import HealthState
from prsm_health.core.channels import TRUTH_NAMES
from prsm_health.core.errors import require
from prsm_health.core.run import Run

from ..decimation import decimate
from ..dynamics.simulate import choose_step
from ..run_assembly import assemble_run, measure
from .model import LOAD_RAMP, STEP, NutSpall, simulate_recirculating


def simulate_recirculating_scenario(scenario, *, progress: bool = False) -> Run:
    """Simulate a scenario of a recirculating design; see :func:`prsm_health.simulate`.

    Raises
    ------
    ParameterError
        A profile or health state the recirculating model does not cover yet, named.
    """
    del progress  # a run of seconds: no bar
    design, health, profile = scenario.design, scenario.health, scenario.profile
    instrumentation, drive_train = scenario.instrumentation, scenario.drive_train
    _require_covered(profile, health)
    faults = _fault_arguments(design, health)
    h, factor = choose_step(STEP, instrumentation.sample_rate)  # 1/(m·f_s) ≤ the model's step
    knots, amplitude, frequency = profile.load_knots()
    # the load on the payload behind the drive train's linkage (the standard model's), or an
    # ideal force on the nut (paper 03's own case: no payload)
    on_payload = drive_train.load_application == "payload"
    linkage = (
        (drive_train.linkage_stiffness, drive_train.linkage_damping_ratio) if on_payload else None
    )
    run = simulate_recirculating(
        design,
        screw_speed=profile.motion_knots(),
        load=knots,
        load_sine=(amplitude, frequency),
        duration=profile.duration,
        clearance=health.clearance_screw,
        clearance_nut=health.clearance_nut,
        payload_mass=drive_train.payload_mass if on_payload else 0.0,
        linkage=linkage,
        load_ramp=LOAD_RAMP,
        step=h,
        **faults,
    )
    n = int(round(profile.duration / h))  # the standard run's sample count at this step
    ratio = drive_train.gear_ratio
    rod = run.linkage_force[:n]
    zero = np.zeros(n)
    truth_raw = {
        "motor_angle": ratio * run.screw_angle[:n],
        "motor_speed": ratio * run.screw_speed[:n],
        "motor_torque": run.drive_torque[:n] / (ratio * drive_train.gear_efficiency),
        "screw_angle": run.screw_angle[:n],
        "screw_speed": run.screw_speed[:n],
        "carrier_speed": run.carrier_speed[:n],
        "nut_position": run.nut_position[:n],
        "nut_axial_accel": run.nut_acceleration[:n],
        "nut_tangential_accel": zero,
        "nut_radial_x_accel": zero,
        "nut_radial_y_accel": zero,
        "friction_torque": zero,
        "axial_load": rod,
        "payload_position": run.payload_position[:n],
        "screw_axial_position": zero,
        "load_force": run.axial_load[:n],
    }
    channels = measure(scenario, truth_raw, 1.0 / h)
    names = [name for name in TRUTH_NAMES if name in truth_raw]
    decimated = decimate(np.column_stack([truth_raw[name] for name in names]), factor)
    truth = {name: decimated[:, k] for k, name in enumerate(names)}
    n_out = len(decimated)
    # pulses and counts are not band-limited signals: the largest force and the count reached
    # within each sample's interval
    cam = np.abs(run.cam_force[:, : n_out * factor]).sum(axis=0)
    truth["cam_force"] = cam.reshape(n_out, factor).max(axis=1)
    exits = run.in_sector[:, :-1] & ~run.in_sector[:, 1:]
    count = np.concatenate([[0], np.cumsum(exits.sum(axis=0))])[: n_out * factor]
    truth["reset_count"] = count.reshape(n_out, factor)[:, -1].astype(float)
    clearances = {
        f"clearance_{side}_realised_{stat}": value
        for side, value in (("screw", health.clearance_screw), ("nut", health.clearance_nut))
        for stat in ("mean", "min", "max")
    }
    return assemble_run(
        scenario,
        channels=channels,
        truth=truth,
        energy={
            "drive": float(run.work_in[n - 1]),
            "load": float(run.work_load[n - 1]),
            "dissipated": float(run.dissipated[n - 1]),
            "friction": 0.0,
        },
        labels=clearances,
        model_info={"integration_step": h, "model": "recirculating"},
    )


def _require_covered(profile, health) -> None:
    """One error naming the first field the recirculating model does not cover yet."""
    what = "the recirculating PRSM's model turns the screw forward or rests so far"
    require(profile.drive == "prescribed", "profile.drive", profile.drive, f"{what}: 'prescribed'")
    if profile.check is not None:
        for phase in profile.check.phases:
            require(
                phase.motion != "reversing" and phase.speed >= 0,
                "check.phases",
                f"{phase.name!r} ({phase.motion}, {phase.speed:g} rad/s)",
                f"{what}: every phase at a speed ≥ 0, none reversing",
            )
    else:
        require(
            profile.motion != "reversing",
            "profile.motion",
            profile.motion,
            f"{what}: 'constant', 'ramp' or 'trapezoid'",
        )
        require(profile.speed > 0, "profile.speed", profile.speed, f"{what}: > 0 (forward)")
    nominal = HealthState()
    for f in dataclasses.fields(HealthState):
        if f.name in ("clearance_screw", "clearance_nut", "clearance_gear", "faults"):
            continue
        value = getattr(health, f.name)
        require(
            value == getattr(nominal, f.name),
            f"health.{f.name}",
            value,
            f"not modelled for the recirculating PRSM yet (its default "
            f"{getattr(nominal, f.name)!r} only)",
        )


def _fault_arguments(design, health) -> dict:
    """The health state's faults as :func:`~.model.simulate_recirculating`'s arguments: one of
    each kind at most; a spall on the nut's loaded flank only (the axial model has no screw
    or roller surface to carry one)."""
    kinds = [f.kind for f in health.faults]
    for kind in set(kinds):
        require(
            kinds.count(kind) == 1,
            "faults.kind",
            kind,
            "one fault of each kind per run at most (the recirculating model has one of each)",
        )
    out = {}
    for fault in health.faults:
        if fault.kind == "spall":
            require(
                fault.location == "nut" and fault.flank == "loaded",
                "faults.location",
                f"{fault.location} ({fault.flank} flank)",
                "the recirculating model carries a spall on the nut's loaded flank only",
            )
            out["nut_spall"] = NutSpall(
                angle=fault.angle,
                length=fault.length,
                depth=fault.depth,
                share=1.0 / design.engaged_threads,
            )
        elif fault.kind == "cam_wear":
            out["cam_wear"] = fault.depth
        elif fault.kind == "platform_loss":
            out["platform_loss"] = fault.height
        elif fault.kind == "reentry_edge":
            out["reentry_edge"] = fault
    return out
