"""The recirculating PRSM's reset-comb indicators (prsm_health.signals.reset_comb): synthetic
pulse trains locked to the roller passages with known answers, a standard design without
resets, and one short simulated recirculating run through the scenario path."""

import math

import numpy as np
import pytest

from prsm_health import preset, speed_ratios
from prsm_health.actuator.states import OperatingProfile
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import Run
from prsm_health.signals.features import GROUPS, extract_features
from prsm_health.signals.indicator_table import SEARCH_SHARE
from prsm_health.signals.reset_comb import (
    MIN_PASSAGES,
    RESET_COMB,
    reset_comb_indicators,
    reset_window_share,
)
from prsm_health.simulation.scenario import Scenario

RATE = 20_000.0
SPEED = 40 * math.pi  # paper 03 §4.2: a passage every 10.3 ms for paper03
D = preset("paper03")
#: The pulses: a ring at the nut's axial mode (5 kHz) decaying over 1.5 ms (0.15 of the
#: passage period), like the simulated resets' (5.6 kHz, slower: what the window allows for).
RING, DECAY = 5000.0, 1.5e-3


def passage_rate() -> float:
    """N·f_c [Hz] at SPEED."""
    return D.n_rollers * speed_ratios(D).carrier * SPEED / (2 * math.pi)


def pulses(t, phase, amplitude=1.0):
    """A pulse train locked to the passages: a decaying ring starting at ``phase`` [share of
    the passage period] of every passage; ``amplitude`` a scalar or an array over ``t``."""
    period = 1.0 / passage_rate()
    since = ((t / period - phase) % 1.0) * period
    return amplitude * np.exp(-since / DECAY) * np.sin(2 * math.pi * RING * since)


def channels(x, t, seed=0, load=None):
    """The channels the group reads: the resolver's angle with an unknown zero (the sector's
    place relative to it is not known), the acceleration plus white noise at 1 % of the
    pulses' amplitude (non-synchronous), and the load when given."""
    rng = np.random.default_rng(seed)
    out = {
        "screw_angle": rng.uniform(0, 2 * math.pi) + SPEED * t,
        "nut_axial_accel": 50.0 * x + rng.normal(0.0, 0.5, len(t)),
    }
    if load is not None:
        out["axial_load"] = load
    return out


def times(duration=0.3):
    return np.arange(int(duration * RATE)) / RATE


# Tolerances. The pulses' energy per passage is 50² · τ/4 (the ring's mean square over its
# decay) against the noise's 0.5² · 10.3 ms: the noise holds ≈ 1 % of the power, so a locked
# train reads ≈ 99 % synchronous and its energy profile ≈ 0.6 % outside the 0.44-period window
# (the noise's share outside it) — the bounds (0.95, 0.03) leave 4× that. The second train's
# ring started 0.6 of the period later: the best window holds the second ring whole and the
# first ring's first 0.043 of the period (43 % of its energy), ≈ 29 % outside; the doublet
# reads the two starts 0.4 apart circularly, to a bin (1/206 of the period) plus the smoothing's
# same shift of both (±0.02).
def test_a_locked_pulse_train_is_synchronous_and_inside_the_reset_window():
    t = times()
    one = reset_comb_indicators(channels(pulses(t, 0.1), t), D, SEARCH_SHARE)
    assert list(one) == list(RESET_COMB)
    assert one["comb_sync_share"] > 0.95
    assert one["comb_outside_share"] < 0.03
    assert one["comb_rms"] > 0
    assert math.isnan(one["comb_load_slope"])  # no load channel
    # the same train at another phase of the resolver's zero reads the same (phase-invariant)
    other = reset_comb_indicators(channels(pulses(t, 0.1), t, seed=1), D, SEARCH_SHARE)
    for name in ("comb_sync_share", "comb_outside_share", "comb_rms"):
        assert other[name] == pytest.approx(one[name], rel=0.05, abs=0.005)
    # a second train at phase offset 0.6: energy outside the window, a doublet 0.4 apart
    two = reset_comb_indicators(channels(pulses(t, 0.1) + pulses(t, 0.7), t), D, SEARCH_SHARE)
    assert two["comb_outside_share"] > 0.2 > 5 * one["comb_outside_share"]
    assert two["comb_doublet_spacing"] == pytest.approx(0.4, abs=0.02)
    assert two["comb_peak_ratio"] == pytest.approx(1.0, abs=0.1)  # equal pulses
    assert reset_window_share(D) == pytest.approx(0.443, abs=0.005)  # paper03's: 2βN/2π + 0.25


# The load slope: the passages split at the median |load| of a 10 ± 8 kN, 5 Hz load, whose
# halves' means are ≈ 5.2 and 14.8 kN. A pulse ∝ load: each half's peak is the RMS of its
# passages' amplitudes (the energy profile averages power), not their mean — the halves'
# spreads put that within ≈ 5 % of the mean's ratio — and a passage's mean load differs from
# the load at its pulse by ≤ 1.3 kN: 1 ± 0.15. A constant pulse: only the noise's 1 % of the
# power differs between the halves, |slope| < 0.05.
def test_the_load_slope_tells_a_strike_that_scales_with_the_load_from_one_that_does_not():
    t = times()
    load = 10e3 + 8e3 * np.sin(2 * math.pi * 5.0 * t)
    scaled = pulses(t, 0.2, load / 10e3)
    constant = pulses(t, 0.2)
    slope = reset_comb_indicators(channels(scaled, t, load=load), D, SEARCH_SHARE)
    assert slope["comb_load_slope"] == pytest.approx(1.0, abs=0.15)
    flat = reset_comb_indicators(channels(constant, t, load=load), D, SEARCH_SHARE)
    assert abs(flat["comb_load_slope"]) < 0.05
    # a load held (its noise only) does not vary enough: no slope
    steady = 10e3 + np.random.default_rng(3).normal(0.0, 20.0, len(t))
    held = reset_comb_indicators(channels(scaled, t, load=steady), D, SEARCH_SHARE)
    assert math.isnan(held["comb_load_slope"]) and math.isfinite(held["comb_rms"])


def test_windows_that_cannot_support_the_group_leave_it_nan():
    t = times()
    x = channels(pulses(t, 0.0), t)
    # too few passages
    short = int(0.9 * MIN_PASSAGES / passage_rate() * RATE)
    cut = {k: v[:short] for k, v in x.items()}
    assert all(math.isnan(v) for v in reset_comb_indicators(cut, D, SEARCH_SHARE).values())
    # the screw turns back in the window: no angle domain
    back = dict(x, screw_angle=np.sin(2 * math.pi * 2 * t) * 50)
    assert all(math.isnan(v) for v in reset_comb_indicators(back, D, SEARCH_SHARE).values())
    # a recording too slow for the harmonics the doublet needs
    assert all(math.isnan(v) for v in reset_comb_indicators(x, D, 0.005).values())
    # no resets in a standard PRSM
    standard = reset_comb_indicators(x, preset("paper01"), SEARCH_SHARE)
    assert all(math.isnan(v) for v in standard.values())


def test_the_feature_table_carries_the_group_for_recirculating_designs_only():
    t = times()
    ch = channels(pulses(t, 0.0), t)
    ch["screw_speed"] = np.full(len(t), SPEED)
    row = extract_features(Run(t, ch, RATE, operating=OperatingPoint(design="paper03")))
    assert GROUPS["reset_comb"] == list(RESET_COMB)
    assert all(math.isfinite(row[name]) for name in RESET_COMB if name != "comb_load_slope")
    row = extract_features(Run(t, ch, RATE, operating=OperatingPoint(design="paper01")))
    assert all(math.isnan(row[name]) for name in GROUPS["reset_comb"])


def test_a_simulated_recirculating_run_carries_the_comb():
    profile = OperatingProfile(duration=0.1, speed=SPEED, load=20e3)
    run = Scenario(design="paper03", profile=profile, seed=5).simulate()
    row = extract_features(run)
    # 9 whole passages in 0.1 s: the group is read. The comb is there: the accelerometer's
    # noise alone (25 µg/√Hz over 10 kHz, 0.025 m/s² RMS) would average to ≈ 0.01 m/s² over
    # them, the resets' comb reads 100–350 m/s² (payload 0–10 kg, clearance 3–10 µm)
    assert math.isfinite(row["comb_rms"]) and row["comb_rms"] > 10.0
    assert math.isfinite(row["comb_outside_share"]) and math.isfinite(row["comb_peak_ratio"])
