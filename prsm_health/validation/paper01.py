"""Paper 01 rows: kinematics and frequencies (§3.1–3.3).

Reference: paper 01 (docs/references.md).
"""

from __future__ import annotations

import math

import numpy as np

from prsm_health.actuator.design import preset
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.actuator.states import HealthState, ManufacturingVariation, OperatingProfile
from prsm_health.physics.kinematics import characteristic_frequencies, speed_ratios
from prsm_health.physics.stiffness.thread_load import roller_side_stiffness
from prsm_health.signals.spectra import amplitude_spectrum, dominant_frequency
from prsm_health.simulation.dynamics.model import SimulationOptions
from prsm_health.simulation.scenario import simulate

from . import Row, inconsistent, not_computable, reproduced

#: Paper 01's model: identical rollers and its constant friction coefficients.
IDEAL = SimulationOptions(variation=ManufacturingVariation.ideal(), lubrication="constant")


def _simulate(speed: float, clearance: float, duration: float = 0.4):
    """Paper 01's §3 case: identical rollers (assumption 2), F_a = 100 N on the nut, b_s = b_N = b,
    screw driven rigidly and axially fixed (the paper's model, ``DriveTrain.paper01()``)."""
    return simulate(
        "paper01",
        HealthState(clearance_screw=clearance, clearance_nut=clearance, clearance_gear=10e-6),
        OperatingProfile(duration=duration, speed=speed, load=100.0),
        "ideal",
        1,
        options=IDEAL,
        drive_train=DriveTrain.paper01(),
    )


def _steady(run, name, truth=False):
    """The last three quarters of a channel (or, with ``truth``, of a truth signal)."""
    return (run.truth if truth else run.channels)[name][len(run) // 4 :]


def rows() -> list[Row]:
    design = preset("paper01")
    ratio = speed_ratios(design).carrier
    freqs = characteristic_frequencies(design, 100.0)
    out = [
        reproduced(
            "01",
            "§3.2",
            "screw speed 100 rad/s in rpm",
            "rpm",
            955.0,
            100.0 * 60.0 / (2 * math.pi),
            5e-4,
            "unit conversion; tolerance = the paper's rounding to 3 digits",
        ),
        reproduced(
            "01",
            "§3.1",
            "carrier/screw speed ratio (rigid body)",
            "-",
            0.37,
            ratio,
            0.0136,
            "r_s/(2(r_s + r_c)) = 0.375; tolerance = half a unit of the paper's last printed "
            "digit (0.005/0.37). The paper's own 5.8 Hz and 377 Hz imply 0.364 (rows below)",
        ),
        inconsistent(
            "01",
            "§3.2",
            "carrier frequency f_p at 100 rad/s",
            "Hz",
            5.8,
            freqs.carrier,
            "100·0.375/2π = 5.97 Hz; the paper's 5.8 Hz implies a 0.364 speed ratio (3 % slip), "
            "contradicting its own 0.37 and the rigid-body 0.375 it claims to match",
        ),
        inconsistent(
            "01",
            "§3.2",
            "gear mesh frequency z2·f_p at 100 rad/s",
            "Hz",
            377.0,
            freqs.gear_mesh,
            "65 × 5.97 Hz = 388 Hz; 377 Hz follows from the inconsistent 5.8 Hz",
        ),
    ]
    slow = _simulate(1.0, 10e-6, duration=0.3)
    out.append(
        reproduced(
            "01",
            "§3.1",
            "carrier/screw speed ratio, simulated at 1 rad/s, F_a = 100 N",
            "-",
            0.37,
            float(
                np.mean(_steady(slow, "carrier_speed", truth=True))
                / np.mean(_steady(slow, "screw_speed", truth=True))
            ),
            0.0136,
            "dynamic model with the helix in the thread deformations; same rounding tolerance",
        )
    )
    out.append(
        inconsistent(
            "01",
            "§3.1",
            "settling time of the speed ratio",
            "ms",
            0.05,
            None,
            "the slowest structural modes are ~300–450 Hz (periods 2–3 ms): no response settles in "
            "1/50 of a period; the model starts on the rigid-body solution and settles its "
            "loaded state before t = 0 instead",
        )
    )
    fast = _simulate(100.0, 10e-6)
    f, a = amplitude_spectrum(_steady(fast, "nut_tangential_accel"), fast.sample_rate)
    out.append(
        inconsistent(
            "01",
            "§3.2",
            "strongest nut circumferential line at 100 rad/s (simulated)",
            "Hz",
            377.0,
            float(f[np.argmax(a * (f > 100))]),
            "identical rollers at staggered mesh phases (65 mod 7 = 2) cancel the mesh "
            "fundamental in the nut rotation: the strongest line is a mesh harmonic; with "
            "manufacturing variation the 388 Hz fundamental appears (tests/dynamics/test_dynamics.py)",
        )
    )
    d = preset("paper01")
    k_s, k_n = (
        roller_side_stiffness(d, 100.0 / 7, "screw"),
        roller_side_stiffness(d, 100.0 / 7, "nut"),
    )
    k_axial = 7 * k_s * k_n / (k_s + k_n)
    out.append(
        inconsistent(
            "01",
            "§3.3 table, b = 10 µm",
            "nut axial stiffness implied by 590 Hz with m_N = 20 kg",
            "N/m",
            20.0 * (2 * math.pi * 590.0) ** 2,
            k_axial,
            "the paper's 590 Hz needs 2.75e8 N/m; the paper-04 thread model of this geometry "
            "(10 engaged threads assumed: the paper gives none) gives this at 100 N / 7 rollers "
            "and reaches 2.75e8 N/m only near 700 N",
        )
    )
    for clearance, freq in ((10, 590.0), (20, 538.0), (30, 507.0)):
        run = fast if clearance == 10 else _simulate(100.0, clearance * 1e-6)
        out.append(
            inconsistent(
                "01",
                "§3.3 table",
                f"dominant nut axial frequency, b = {clearance} µm, F_a = 100 N steady",
                "Hz",
                freq,
                dominant_frequency(_steady(run, "nut_axial_accel"), run.sample_rate),
                "a steady 100 N load holds every roller on one flank, so clearance cannot change "
                "the frequency (the paper's own ±1 m/s² amplitudes mean 0.07 µm motion ≪ 2b); "
                "the drop appears when the load reverses (tests, docs/validation.md)",
            )
        )
    out.append(
        not_computable(
            "01",
            "§3.3",
            "FEA dominant axial frequency, b = 30 µm",
            "Hz",
            488.0,
            None,
            "FEA model not described in the paper",
        )
    )
    return out
