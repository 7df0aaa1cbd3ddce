"""The compliance chain against the simulated slow reversal, element by element.

The built-in check's slow reversal alone (±10 rad/s cosine, 0.25 s period, ±25 % C_a, 0.5 s),
paper-01 design, ``ideal`` instrumentation, seed 0: the lost-motion step
(:func:`prsm_health.signals.lost_motion.lost_motion_step`) at b = 0, 5, 10, 15 µm with the
default drive train — intercept and slope of a line fit —, then at b = 0 with one drive-train
figure changed at a time, each beside the chain's prediction
(:func:`prsm_health.physics.lost_motion_chain.compliance_chain`, read as the cosine reversal's
fitted step); last, at b = 0 the ``flight-ema`` sensors against ``ideal`` beside the chain's
sensor term (the LVDT's filter delay, :func:`prsm_health.simulation.sensors.channel_group_delay`).
Quoted in docs/diagnostics.md ("Clearance from the check's lost motion").

    python tools/studies/lost_motion_chain.py        # ≈ 30 s on one core
"""

from __future__ import annotations

import numpy as np

from prsm_health.actuator.design import preset
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.actuator.health_check import BUILT_IN, HealthCheck
from prsm_health.actuator.states import HealthState, OperatingProfile
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.physics.load_rating import load_ratings
from prsm_health.physics.lost_motion_chain import compliance_chain
from prsm_health.signals.lost_motion import lost_motion_step
from prsm_health.simulation.instrumentation import load_instrumentation
from prsm_health.simulation.scenario import simulate
from prsm_health.simulation.sensors import channel_group_delay

DESIGN = preset("paper01")
#: The built-in check's slow reversal alone (the phase the lost-motion step is read on).
REVERSAL = HealthCheck(
    "slow-reversal",
    tuple(p for p in BUILT_IN["health-check"].phases if p.name == "slow reversal"),
)
CHANGES = {
    "default": {},
    "thrust bearing 1e8 N/m": {"thrust_bearing_stiffness": 1e8},
    "thrust bearing 3e8 N/m": {"thrust_bearing_stiffness": 3e8},
    "bearing half-play 5 µm": {"thrust_bearing_play": 5e-6},
    "coupling 1e3 N·m/rad": {"coupling_stiffness": 1e3},
    "coupling 3e3 N·m/rad": {"coupling_stiffness": 3e3},
    "no gear backlash": {"gear_backlash": 0.0},
    "gear backlash ×4": {"gear_backlash": 4 * DriveTrain().gear_backlash},
}


def simulated_run(clearance: float, drive_train: DriveTrain, instrumentation: str = "ideal"):
    """(lost-motion step [m], integration rate [Hz]) of the slow reversal."""
    run = simulate(
        DESIGN,
        HealthState.uniform(clearance),
        OperatingProfile(check=REVERSAL),
        instrumentation,
        0,
        drive_train=drive_train,
    )
    c = run.phases()["slow reversal"].channels
    lead = speed_ratios(DESIGN).nut
    step = lost_motion_step(c["nut_position"], c["screw_angle"], lead, np.sign(c["screw_speed"]))
    return step, 1.0 / run.scenario["integration_step"]


def simulated_step(clearance: float, drive_train: DriveTrain) -> float:
    return simulated_run(clearance, drive_train)[0]


def main() -> None:
    load = 0.25 * load_ratings(DESIGN).dynamic
    clearances = np.array([0.0, 5e-6, 10e-6, 15e-6])
    steps = np.array([simulated_step(b, DriveTrain()) for b in clearances])
    slope, intercept = np.polyfit(clearances, steps, 1)
    chain = compliance_chain(DESIGN, DriveTrain(), load, reversal_shape="cosine")
    print(f"±{load:.0f} N, default drive train")
    print("  b [µm]  " + "  ".join(f"{b * 1e6:6.0f}" for b in clearances))
    print("  L [µm]  " + "  ".join(f"{s * 1e6:6.2f}" for s in steps))
    print(f"  fit: intercept {intercept * 1e6:.2f} µm, slope {slope:.3f}")
    peak = compliance_chain(DESIGN, DriveTrain(), load)
    print("  chain [µm]   as the step reads it / peak-to-peak at ±F")
    for name, value in chain.terms.items():
        print(f"    {name:20s} {value * 1e6:6.2f}  {peak.terms[name] * 1e6:6.2f}")
    print(f"    {'total':20s} {chain.total * 1e6:6.2f}  {peak.total * 1e6:6.2f}")
    print("\nb = 0, one change at a time: simulated, chain, difference [µm]")
    for label, change in CHANGES.items():
        dt = DriveTrain(**change)
        sim = simulated_step(0.0, dt)
        pred = compliance_chain(DESIGN, dt, load, reversal_shape="cosine").total
        print(f"  {label:24s} {sim * 1e6:6.2f}  {pred * 1e6:6.2f}  {(sim - pred) * 1e6:+5.2f}")

    phase = REVERSAL.phases[0]
    ideal, rate = simulated_run(0.0, DriveTrain())
    flight = simulated_run(0.0, DriveTrain(), "flight-ema")[0]
    instrumentation = load_instrumentation("flight-ema")
    delays = {
        c: channel_group_delay(instrumentation, c, 1.0 / phase.reversal_period, rate)
        for c in ("nut_position", "screw_angle")
    }
    sensed = compliance_chain(
        DESIGN,
        DriveTrain(),
        load,
        reversal_shape="cosine",
        speed_amplitude=phase.speed,
        sensor_delays=delays,
    )
    print(
        "\nb = 0, flight-ema sensors: group delays "
        + ", ".join(f"{c} {d * 1e3:.3f} ms" for c, d in delays.items())
    )
    print(
        f"  simulated {flight * 1e6:.2f} (ideal {ideal * 1e6:.2f}, +{(flight - ideal) * 1e6:.2f})"
        f"; chain {sensed.total * 1e6:.2f} (sensor lag +{sensed.sensor_lag * 1e6:.2f})"
    )


if __name__ == "__main__":
    main()
