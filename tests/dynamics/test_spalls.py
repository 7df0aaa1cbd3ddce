"""Localised flank spalls (issue 12, item 1): impacts at the defect-passing rate of their
location, seen in the envelope spectrum of the flight-ema axial accelerometer.

The envelope is computed here, independently of the feature code: band-pass 2–8 kHz
(4th-order Butterworth, zero phase), Hilbert magnitude, Welch spectrum (8192-sample segments,
2.4 Hz bins). A line is the largest of the 3 bins around the predicted frequency over the median
of ±40 % around it — a ratio over a 1 s run, not a sample of the trajectory.
"""

import numpy as np
import pytest
from scipy import signal

from prsm_health import HealthState, OperatingProfile, defect_frequencies, preset, simulate
from prsm_health.errors import ParameterError
from prsm_health.faults import Spall

pytestmark = pytest.mark.slow  # six 1 s runs

FREQUENCY = {"screw": "screw_flank", "nut": "nut_flank", "roller": "roller_flank"}


def envelope_line(x, rate, f0):
    sos = signal.butter(4, (2000.0, 8000.0), btype="bandpass", fs=rate, output="sos")
    envelope = np.abs(signal.hilbert(signal.sosfiltfilt(sos, x - np.mean(x))))
    f, p = signal.welch(envelope - envelope.mean(), fs=rate, nperseg=8192)
    k = int(np.argmin(np.abs(f - f0)))
    peak = p[k - 1 : k + 2].max()
    return peak / np.median(p[(f > 0.6 * f0) & (f < 1.4 * f0)]), peak


def line(location, depth):
    spalls = (Spall(location=location, depth=depth),) if depth else ()
    run = simulate(
        "paper01", HealthState(faults=spalls), OperatingProfile(duration=1.0, load=300.0), None, 4
    )
    e = run.energy
    assert e["drive"] == pytest.approx(-e["load"] + e["dissipated"], rel=1e-2)
    f0 = defect_frequencies(preset("paper01"), 100.0)[FREQUENCY[location]]
    return envelope_line(run["nut_axial_accel"], run.sample_rate, f0)


@pytest.mark.parametrize("location", ["screw", "nut", "roller"])
def test_spall_makes_a_line_at_its_defect_frequency_growing_with_severity(location):
    # Default severity (20 µm deep, 1.5 mm long): the line stands ≥ 3× over the local median
    # (seen 10–40×). A 40 µm spall's line carries more envelope power (seen 2.2–3.7× more); its
    # ratio to the median need not grow, as deeper impacts also raise the broadband envelope.
    ratio, power = line(location, Spall().depth)
    _, severe_power = line(location, 40e-6)
    assert ratio >= 3.0, ratio
    assert severe_power > power, (power, severe_power)


def test_spall_errors_name_the_field():
    with pytest.raises(ParameterError, match="faults.location"):
        Spall(location="ring")
    with pytest.raises(ParameterError, match="faults.depth"):
        Spall(depth=-1e-6)
    with pytest.raises(ParameterError, match="faults.size"):
        HealthState(faults=({"kind": "spall", "size": 1.0},))
    with pytest.raises(ParameterError, match="faults.roller"):
        simulate(health=HealthState(faults=(Spall(location="roller", roller=9),)))
