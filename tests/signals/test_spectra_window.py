"""``prsm_health.signals.envelope_analysis.window_spectra``: the bounded spectra of one window that the
service stores for its dashboard, against signals with a known answer and against the
library's own spectra, envelope band and defect frequencies."""

import json
import math

import numpy as np
import pytest

from prsm_health.actuator.design import preset
from prsm_health.core.errors import PRSMHealthError
from prsm_health.physics.kinematics import characteristic_frequencies, defect_frequencies
from prsm_health.signals.envelope_analysis import (
    SPECTRUM_POINTS,
    defect_lines,
    envelope_amplitude_spectrum,
    window_spectra,
)
from prsm_health.signals.features import extract_features
from prsm_health.signals.spectra import amplitude_spectrum

RATE = 20_000.0
T = np.arange(10_000) / RATE  # 0.5 s: the shipped model's window, 2 Hz bins
DESIGN = preset("paper01")


def _am(m=0.4, f_m=98.0, f_c=5000.0, tone=(1234.0, 3.0), noise=0.05, seed=0):
    """An amplitude-modulated carrier (envelope line m at f_m), a tone of amplitude A at f_t
    on a bin, and a little noise."""
    rng = np.random.default_rng(seed)
    f_t, a_t = tone
    x = (1 + m * np.cos(2 * np.pi * f_m * T)) * np.cos(2 * np.pi * f_c * T)
    return x + a_t * np.sin(2 * np.pi * f_t * T) + noise * rng.standard_normal(len(T))


def test_bounded_and_peaks_kept():
    x = _am()
    out = window_spectra(x, RATE, DESIGN, 100.0)
    f, a = np.array(out["spectrum"]["frequency"]), np.array(out["spectrum"]["amplitude"])
    full_f, full_a = amplitude_spectrum(x, RATE)
    assert len(f) <= SPECTRUM_POINTS < len(full_f)
    assert np.all(np.diff(f) > 0) and f[0] > 0  # increasing, no DC bin (log axis)
    assert set(f) <= set(full_f) and set(a) <= set(full_a)  # points of the full spectrum
    # the tone keeps its height and its place (max in bin, not mean or subsampling)
    k = int(np.argmax(a))
    assert f[k] == pytest.approx(1234.0) and a[k] == pytest.approx(3.0, rel=1e-3)
    assert a[k] == full_a[1:].max()
    # every bin of the full spectrum is represented by a point at least as high nearby
    for i in np.linspace(1, len(full_f) - 1, 50).astype(int):
        j = np.searchsorted(f, full_f[i])
        near = a[max(0, j - 1) : j + 1]
        assert near.max() >= full_a[i] or full_f[i] < f[0]
    assert out["samples"] == len(x) and out["sample_rate"] == RATE


def test_envelope_is_the_library_envelope_in_the_indicator_band():
    x = _am()
    out = window_spectra(x, RATE, DESIGN, 100.0)
    frequencies = defect_frequencies(DESIGN, 100.0)
    lines = defect_lines(x, RATE, frequencies)
    env = out["envelope"]
    assert env["band"] == list(lines["band"])  # the kurtogram's band, as the indicators read it
    assert env["sk"] == lines["sk"] and env["impulsive"] == lines["impulsive"]
    assert env["modulation_limit"] == pytest.approx(0.5 * (env["band"][1] - env["band"][0]))
    f_env, a_env = envelope_amplitude_spectrum(x, RATE, lines["band"])
    keep = (f_env > 0) & (f_env <= env["modulation_limit"])
    if keep.sum() <= SPECTRUM_POINTS:  # short enough: the spectrum as it is
        assert env["frequency"] == f_env[keep].tolist()
        assert env["amplitude"] == a_env[keep].tolist()
    assert max(env["frequency"]) <= env["modulation_limit"]
    # the defect lines are defect_lines' own
    for name, line in lines["lines"].items():
        for key, value in line.items():
            got = out["lines"][name][key]
            assert (math.isnan(got) and math.isnan(value)) or got == value


def _impacts(rate_hz=97.0, resonance=6000.0, seed=0):
    """Decaying resonance bursts at rate_hz in Gaussian noise (a spall's signature)."""
    x = np.zeros_like(T)
    tail = np.arange(int(0.004 * RATE)) / RATE
    burst = np.exp(-tail / 0.0005) * np.sin(2 * np.pi * resonance * tail)
    for t0 in np.arange(0.001, T[-1] - 0.005, 1 / rate_hz):
        i = int(t0 * RATE)
        x[i : i + len(burst)] += burst
    return x / np.std(x) + np.random.default_rng(seed).standard_normal(len(T))


def test_impact_rate_stands_out_in_the_envelope():
    out = window_spectra(_impacts(), RATE, DESIGN, 100.0)
    env = out["envelope"]
    assert env["impulsive"] and env["band"][0] < 6000.0 < env["band"][1]
    f, a = np.array(env["frequency"]), np.array(env["amplitude"])
    near = np.abs(f - 97.0) <= 2.0
    assert a[near].max() > 5 * np.median(a)


def test_defect_frequencies_and_gear_mesh_at_the_speed():
    out = window_spectra(_am(), RATE, DESIGN, -100.0)  # sign: frequencies are magnitudes
    expected = defect_frequencies(DESIGN, 100.0)
    expected["gear_mesh"] = characteristic_frequencies(DESIGN, 100.0).gear_mesh
    assert out["frequencies"] == pytest.approx(expected)
    assert list(out["frequencies"])[-1] == "gear_mesh"
    assert out["screw_speed"] == -100.0
    json.dumps(out)  # plain data (NaN ratios are encoded as null by the service's encoder)


@pytest.mark.parametrize("design, speed", [(None, 100.0), (DESIGN, None), (DESIGN, 0.0)])
def test_without_design_or_speed_no_frequencies(design, speed):
    out = window_spectra(_am(), RATE, design, speed)
    assert out["frequencies"] == {} and out["lines"] == {}
    assert out["envelope"] is not None  # the band still comes from the kurtogram


def test_no_band_fits_gives_the_spectrum_and_says_why():
    rate = 500.0
    x = np.random.default_rng(1).standard_normal(256)
    out = window_spectra(x, rate, DESIGN, 100.0)  # 3 × 69.6 Hz is above 0.45 × 500 Hz - band
    assert out["envelope"] is None
    assert "kurtogram band" in out["envelope_note"]
    assert len(out["spectrum"]["frequency"]) == 128  # 129 bins less DC


def test_matches_the_indicators_band_on_a_simulated_window(reversing_run):
    run = reversing_run(20e-6, duration=0.4, seed=3)
    speed = float(np.mean(run.channels["screw_speed"]))
    out = window_spectra(run.channels["nut_axial_accel"], run.sample_rate, DESIGN, speed)
    features = extract_features(run.without_truth(), DESIGN)
    assert 0.5 * sum(out["envelope"]["band"]) == pytest.approx(features["ax_sk_band_centre"])
    assert out["envelope"]["sk"] == pytest.approx(features["ax_sk_max"])
    assert out["lines"]["nut_flank"]["ratio"] == pytest.approx(
        features["ax_env_nut_flank_ratio"], nan_ok=True
    )


def test_bad_arguments():
    x = _am()
    with pytest.raises(PRSMHealthError, match="max_points"):
        window_spectra(x, RATE, DESIGN, 100.0, max_points=8)
    with pytest.raises(PRSMHealthError, match="screw_speed"):
        window_spectra(x, RATE, DESIGN, math.nan)
    with pytest.raises(PRSMHealthError, match="finite"):
        window_spectra(np.r_[x, np.inf], RATE, DESIGN, 100.0)
    with pytest.raises(PRSMHealthError, match="sample rate"):
        window_spectra(x, 0.0, DESIGN, 100.0)


@pytest.mark.parametrize("log", [True, False])
def test_peak_bins_is_the_maximum_of_each_bin(log):
    from prsm_health.signals.envelope_analysis import _peak_bins

    rng = np.random.default_rng(2)
    freq = np.arange(1, 5001) * 2.0
    amp = rng.exponential(size=len(freq))
    amp[[10, 11, 4000]] = amp.max() + 1  # ties: the first of a bin is kept
    got = _peak_bins(freq, amp, 300, log=log)
    edges = np.geomspace(freq[0], freq[-1], 301) if log else np.linspace(freq[0], freq[-1], 301)
    group = np.clip(np.searchsorted(edges, freq, side="right") - 1, 0, 299)
    expected = [
        int(np.flatnonzero(group == g)[np.argmax(amp[group == g])]) for g in np.unique(group)
    ]
    assert got["frequency"] == freq[expected].tolist()
    assert got["amplitude"] == amp[expected].tolist()
    small = _peak_bins(freq[:100], amp[:100], 300, log=log)  # fewer points than bins: as is
    assert small["frequency"] == freq[:100].tolist()
