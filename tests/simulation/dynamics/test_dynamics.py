"""The paper-01 dynamic model: kinematics, spectra, clearance signature, energy, determinism.

Runs are short (0.2–0.5 s simulated); each costs well under a second once numba has compiled.
"""

import numpy as np
import pytest
from scipy import signal

from prsm_health import (
    HealthState,
    ManufacturingVariation,
    OperatingProfile,
    SimulationError,
    SimulationOptions,
    characteristic_frequencies,
    preset,
    simulate,
    speed_ratios,
)
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.physics.stiffness.thread_load import roller_side_stiffness
from prsm_health.signals.spectra import amplitude_spectrum, dominant_frequency
from prsm_health.simulation.dynamics.model import build_model
from prsm_health.simulation.dynamics.simulate import linearised_eigenvalues, max_stable_step

IDEAL = SimulationOptions(variation=ManufacturingVariation.ideal())


#: Paper 01's own actuator: rigid screw drive, axially fixed screw, ideal force on the nut.
PAPER = DriveTrain.paper01()


def run(
    speed=100.0,
    load=100.0,
    clearance=10e-6,
    duration=0.3,
    seed=1,
    options=None,
    drive_train=PAPER,
    **profile,
):
    return simulate(
        "paper01",
        HealthState.uniform(clearance),
        OperatingProfile(duration=duration, speed=speed, load=load, **profile),
        "ideal",
        seed,
        options=options,
        drive_train=drive_train,
    )


@pytest.mark.parametrize("speed", [1.0, 100.0])
def test_carrier_speed_ratio_matches_rigid_body(speed):
    # Issue: within 0.5 % of r_s/(2(r_s + r_c)) = 0.375 at 1 and 100 rad/s, steady state.
    # Ideal geometry: over the 0.1 rad a 1 rad/s run turns, the local slope of the lead errors
    # and waviness (≈ 0.3 % of the lead) would modulate the ratio.
    r = run(speed=speed, duration=0.2, options=IDEAL)
    half = len(r) // 2
    ratio = np.mean(r.truth["carrier_speed"][half:]) / np.mean(r.truth["screw_speed"][half:])
    assert ratio == pytest.approx(speed_ratios(preset("paper01")).carrier, rel=5e-3)


def test_nut_travel_follows_the_lead():
    # Nut position advances one screw lead per screw turn (kinematics), up to the µm-level
    # elastic offset of the loaded threads.
    r = run(duration=0.2)
    travel = r["nut_position"][-1] - r["nut_position"][0]
    expected = preset("paper01").screw_lead / (2 * np.pi) * 100.0 * (r.time[-1] - r.time[0])
    assert travel == pytest.approx(expected, rel=1e-3)


def _peak_near(x, rate, target, rel=0.02):
    f, a = amplitude_spectrum(x, rate)
    band = (f > target * (1 - rel)) & (f < target * (1 + rel))
    k = np.argmax(np.where(band, a, 0.0))
    background = np.median(a[(f > 100) & (f < 3000)])
    return f[k], a[k], background


def test_mesh_line_appears_with_manufacturing_variation():
    # Issue: at 100 rad/s a line at z_ring·f_carrier ≈ 388 Hz within 1 % in the nut tangential
    # or radial acceleration when manufacturing variation is on.
    mesh = characteristic_frequencies(preset("paper01"), 100.0).gear_mesh
    r = run(duration=0.5)
    found = []
    for name in ("nut_tangential_accel", "nut_radial_x_accel"):
        x = r[name][len(r) // 5 :]  # after the residual settling transient
        f, a, background = _peak_near(x, r.sample_rate, mesh)
        found.append((abs(f - mesh) / mesh, a / background))
    # Resolution: 0.4 s → 2.5 Hz bins = 0.64 % of 388 Hz, inside the 1 % tolerance. A line is a
    # peak at least 10× the median spectral level.
    assert any(err <= 0.01 and snr >= 10 for err, snr in found), found


def test_ideal_rollers_cancel_the_mesh_fundamental():
    # With identical rollers at staggered phases (65 mod 7 = 2) the nut torque is periodic in
    # T_carrier/7, so the mesh fundamental (65·f_c) cancels (docs/validation.md).
    # Friction is switched off here: the screw–roller Coulomb friction couples the rollers'
    # normal-load fluctuations and breaks that symmetry even for identical rollers
    # (docs/validation.md). Manufacturing variation brings the line back.
    mesh = characteristic_frequencies(preset("paper01"), 100.0).gear_mesh
    frictionless = dict(friction_coefficient=0.0, rolling_friction=0.0)
    ideal = run(
        duration=0.5,
        options=SimulationOptions(variation=ManufacturingVariation.ideal(), **frictionless),
    )
    real = run(duration=0.5, options=SimulationOptions(**frictionless))
    a_ideal = _peak_near(ideal["nut_tangential_accel"][2000:], 20_000, mesh, rel=0.01)[1]
    a_real = _peak_near(real["nut_tangential_accel"][2000:], 20_000, mesh, rel=0.01)[1]
    assert a_real > 100 * a_ideal


def _dominant(x, rate):
    # Welch PSD, Hann, 512-sample segments (39 Hz bins), parabolic sub-bin peak, 150–1500 Hz.
    return dominant_frequency(x, rate, (150.0, 1500.0), 512)


def test_nut_axial_mode_matches_thread_stiffness():
    # Independent check: the dominant axial frequency equals √(k/m_N) with k the static axial
    # stiffness of paper 04's thread model (7 rollers, screw and nut sides in series, at the
    # operating load). Ideal rollers share load equally. Tolerance: one Welch bin (39 Hz) of ~450.
    d = preset("paper01")
    load = 100.0
    k_s = roller_side_stiffness(d, load / 7, "screw")
    k_n = roller_side_stiffness(d, load / 7, "nut")
    k = 7 * k_s * k_n / (k_s + k_n)
    expected = np.sqrt(k / d.masses.nut_mass) / (2 * np.pi)
    # A reversing load kicks the mode; zero clearance keeps the system linear.
    r = run(
        load=0.0,
        clearance=0.0,
        duration=0.4,
        options=SimulationOptions(variation=ManufacturingVariation.ideal(), operating_load=load),
        load_profile="sinusoidal",
        load_amplitude=load,
        load_frequency=5.0,
    )
    eig = linearised_eigenvalues(
        build_model(d, HealthState.uniform(0.0), OperatingProfile(load=load), IDEAL, 1)
    )
    modal = np.abs(eig.imag) / (2 * np.pi)
    # The linearised model has that mode within 5 %: the static estimate leaves out the nut
    # rotation through the lead, the radial flank compliance and the traction compliance.
    assert np.min(np.abs(modal - expected)) / expected < 0.05
    assert _dominant(r["nut_axial_accel"], r.sample_rate) == pytest.approx(expected, abs=40.0)


def test_clearance_raises_impact_amplitude_under_reversing_load(reversing_run):
    # Documented regime (docs/validation.md): a ±300 N load reversing at 10 Hz makes the nut
    # cross the 2b gap and strike the other flanks. With the default drive train (payload on a
    # linkage) and lubricated contacts (restitution 0.6) the peak-to-peak acceleration rose by
    # ≥ 1.3× per step b = 10 → 20 → 30 µm in every run tried; the assertion asks for 1.1×, far
    # beyond what another impact sequence on another CPU changes. Paper 01's second signature,
    # a dominant axial frequency falling with b, is not asserted: with the drive train it is
    # not monotone (docs/validation.md, clearance-signature map).
    amps = [
        np.ptp(reversing_run(b, duration=0.5, seed=1)["nut_axial_accel"])
        for b in (10e-6, 20e-6, 30e-6)
    ]
    assert amps[1] > 1.1 * amps[0] and amps[2] > 1.1 * amps[1], amps


def test_clearance_invisible_while_preload_holds_contact():
    # Documented counter-regime: a steady 100 N load keeps every roller on one thread flank, so
    # the thread clearance does not change the response (docs/validation.md). Gear
    # backlash held at 10 µm; the first 0.1 s (settling) is skipped.
    rms, dominant = [], []
    for b in (10e-6, 30e-6):
        health = HealthState(clearance_screw=b, clearance_nut=b, clearance_gear=10e-6)
        r = simulate(
            "paper01",
            health,
            OperatingProfile(duration=0.3, load=100.0),
            "ideal",
            1,
            options=IDEAL,
        )
        x = r["nut_axial_accel"][2000:]
        rms.append(np.std(x))
        f, p = signal.welch(x - x.mean(), fs=r.sample_rate, nperseg=2048)
        dominant.append(f[np.argmax(p * (f > 150))])
    assert dominant[0] == dominant[1]
    assert rms[1] == pytest.approx(rms[0], rel=1e-4)


def test_energy_balance():
    # Issue: mean drive power = output power + dissipated power within 1 %. The energy book is
    # integrated with the state; the kinetic-energy change over the window is added explicitly
    # (constant speed: ~0) — potential energy is bounded and periodic.
    r = run(duration=0.3)
    e = r.energy
    output = -e["load"]
    assert e["drive"] == pytest.approx(output + e["dissipated"], rel=1e-2)
    assert e["dissipated"] >= 0 and e["friction"] >= 0


def test_same_seed_bit_identical_and_seeds_differ():
    a = run(duration=0.05, seed=7)
    b = run(duration=0.05, seed=7)
    c = run(duration=0.05, seed=8)
    for name in a.channels:
        assert np.array_equal(a[name], b[name]), name
    assert not np.array_equal(a["nut_tangential_accel"], c["nut_tangential_accel"])


def test_step_guard_refuses_unstable_step():
    model = build_model(
        preset("paper01"), HealthState(), OperatingProfile(load=100.0), SimulationOptions(), 0
    )
    h_max, f_max = max_stable_step(model)
    assert 1e-6 < h_max < 1e-4 and f_max > 1e3
    with pytest.raises(SimulationError, match="stable limit"):
        run(duration=0.01, options=SimulationOptions(max_step=min(1e-4, 3 * h_max)))


@pytest.mark.parametrize("damping", [0.03, 0.2])
def test_auto_step_stays_stable_and_survives_realistic_contact_damping(damping):
    # "auto": the largest 1/(m·f_s) below 0.6 of the stable step (and 10 µs). A contact
    # damping ratio of 0.2 (restitution ≈ 0.5, docs/validation.md) makes the stable step
    # ≈ 1.3 µs: the fixed 5 µs step is refused there, the automatic one runs it, and the energy
    # book closes within 1 % (constant speed and load: drive = output + dissipated).
    from prsm_health.simulation.dynamics.model import AUTO_MAX_STEP, AUTO_STABLE_FRACTION

    options = SimulationOptions(contact_damping_ratio=damping, max_step="auto")
    r = run(load=300.0, duration=0.05, options=options)
    h, stable = r.scenario["integration_step"], r.scenario["stable_step"]
    assert h <= min(AUTO_MAX_STEP, AUTO_STABLE_FRACTION * stable) * (1 + 1e-12)
    m = 1.0 / (h * r.sample_rate)
    assert m == pytest.approx(round(m), abs=1e-6)  # a whole number of steps per sample
    assert all(np.all(np.isfinite(v)) for v in r.channels.values())
    e = r.energy
    assert e["drive"] == pytest.approx(-e["load"] + e["dissipated"], rel=1e-2)
    if damping > 0.1:
        with pytest.raises(SimulationError, match="stable limit"):
            run(
                duration=0.01,
                options=SimulationOptions(contact_damping_ratio=damping, max_step=5e-6),
            )


def test_speed_loop_tracks_reference():
    # PI speed loop on the screw instead of prescribed motion: tracks 50 rad/s within 1 %.
    r = run(speed=50.0, duration=0.3, drive="speed_loop")
    assert np.mean(r["screw_speed"][len(r) // 2 :]) == pytest.approx(50.0, rel=1e-2)


@pytest.mark.parametrize("drive_train", [None, PAPER], ids=["default", "paper01"])
def test_speed_loop_takes_over_at_speed(drive_train):
    # The loop takes over at t = 0 from the settling's prescribed motion, its integrator holding
    # the settling's mean drive torque: the run starts at speed. Measured under 3000 N, the
    # first 4 ms average within 0.2 % of 50 rad/s with either drive train. Before: the
    # integrator restarted at 0 (default drive train −5.8 %), or wound up during the settling
    # against its nut damper too slowly (paper 01's: −63 %). 1 % lies a factor
    # ≥ 5 from either.
    r = run(speed=50.0, load=3000.0, duration=0.02, drive="speed_loop", drive_train=drive_train)
    start = r.truth["screw_speed"][: int(0.004 * r.sample_rate)]
    assert np.mean(start) == pytest.approx(50.0, rel=1e-2)


def test_reversing_motion_reverses_nut():
    r = run(duration=0.2, motion="reversing", motion_period=0.1, accel_time=0.01)
    v = np.gradient(r["nut_position"], r.time)
    assert v.max() > 0.1 and v.min() < -0.1


def test_blow_up_is_reported_with_its_time():
    # Bypass the guard with a step 20× beyond the stable limit: the run must stop with an error
    # naming the time, not return NaNs.
    from prsm_health.simulation.dynamics.model import initial_state
    from prsm_health.simulation.dynamics.simulate import integrate

    model = build_model(
        preset("paper01"), HealthState(), OperatingProfile(load=100.0), SimulationOptions(), 0
    )
    h = 20 * max_stable_step(model)[0]
    with pytest.raises(SimulationError, match=r"non-finite at t = [0-9.e-]+ s"):
        integrate(model, initial_state(model), h, 20_000)


def test_friction_torque_is_paper02_reduction():
    # The kernel's friction: paper 02's Coulomb μ2·N against the rollers' axial sliding on the
    # screw plus μ3·N. With μ3 = 0, roller equilibrium f_screw − μN = F/n and N = f_screw/sin β
    # give T_f = F·μ·p_eff/(sin β − μ) (p_eff = nut travel per screw radian). Tolerance 3 %:
    # the tangential traction that spins the carrier and the lead angle are left out. Constant
    # μ (paper 02's model; the lubrication regime is tests/test_lubrication.py's).
    d = preset("paper01")
    p_eff = speed_ratios(d).nut
    mu, beta = 0.1, d.contact_angle
    for load in (100.0, 500.0):
        options = SimulationOptions(rolling_friction=0.0, lubrication="constant")
        r = run(load=load, duration=0.2, options=options)
        t_f = np.mean(r.truth["friction_torque"][len(r) // 2 :])
        assert t_f == pytest.approx(load * mu * p_eff / (np.sin(beta) - mu), rel=0.03)


def test_torque_signal_follows_load_lubricant_and_wear():
    base = run(duration=0.2)
    heavier = run(load=300.0, duration=0.2)
    worn_oil = simulate(
        "paper01",
        HealthState.uniform(10e-6, friction_scale=2.0),
        OperatingProfile(duration=0.2),
        "ideal",
        1,
    )
    half = len(base) // 2
    t0 = np.mean(base.truth["friction_torque"][half:])
    assert np.mean(heavier.truth["friction_torque"][half:]) > 2.5 * t0
    assert np.mean(worn_oil.truth["friction_torque"][half:]) > 1.5 * t0
    assert np.mean(worn_oil["drive_torque"][half:]) > np.mean(base["drive_torque"][half:])
    # Wear: at motion reversals a larger clearance lets the nut lag (lost motion) and the
    # drive torque swings harder when the threads re-engage.
    swings = []
    for b in (5e-6, 40e-6):
        r = run(clearance=b, duration=0.2, motion="reversing", motion_period=0.1, accel_time=0.01)
        swings.append(np.ptp(np.diff(r["drive_torque"])))
    assert swings[1] > swings[0]


def test_new_screw_has_no_interference_and_labels_carry_realised_clearances():
    # b = 0 is a new screw whose assembly takes up the rollers' pitch errors: steady running
    # vibrates like b = 10 µm (it was 60× louder when pitch errors became preload). Factor 1.5
    # on RMS over 0.2 s of steady running (seen: 1.07).
    rms, labels = [], []
    for b in (0.0, 10e-6):
        r = run(clearance=b, duration=0.3, drive_train=DriveTrain())
        rms.append(float(np.std(r["nut_axial_accel"][len(r) // 3 :])))
        labels.append(r.labels)
    assert rms[0] < 1.5 * rms[1]
    for b, lab in zip((0.0, 10e-6), labels):
        for side in ("screw", "nut", "gear"):
            lo, mean, hi = (lab[f"clearance_{side}_realised_{s}"] for s in ("min", "mean", "max"))
            assert b <= lo <= mean <= hi < b + 10e-6, (side, lo, mean, hi)
