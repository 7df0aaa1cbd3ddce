"""Acceptance check of a simulation fidelity against the full model at a small step.

A cheaper way to simulate (a larger or fast-math step, a condensed model) is acceptable when
what a diagnosis reads from its runs cannot be told from the full model's: the same cases run
with the candidate's options and with the reference (the full model at
:data:`REFERENCE_STEP`), and compared on

- **band power**: third-octave bands of the measured vibration and torque, seed means, within
  ±10 % below 3 kHz and ±20 % from 3 to 8 kHz (bands holding ≥ :data:`BAND_SHARE` of the
  channel's power: below that, no indicator reads them);
- **lines**: the gear-mesh line and the case's spall line (envelope) at the same frequency
  within 0.1 %;
- **indicators**: every indicator of :func:`~prsm_health.signals.features.extract_features`,
  seed means within max(the reference's seed spread, 2 %) — and, since two means of three
  seeds differ by more than one spread for ≈ 22 % of indicators even when the candidate is the
  reference with other seeds, also within max(3 standard errors of the difference, 2 %);
- **energy**: drive and dissipated work within 1 % of the reference's;
- **modes**: the linearised eigenfrequencies below 5 kHz within 0.5 %.

Runs are impact-dominated at load reversals, so single trajectories diverge at any change of
round-off: seed means are compared, never samples. Band power and lines are read from the
truth signals (the nut's true acceleration, the motor's true torque: no sensor noise to hide a
difference), the indicators from the measured channels of the default instrumentation (what a
diagnosis reads).
"""

from __future__ import annotations

import math
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

#: The reference: the full model at this RK4 step [s] (a tenth of the default's).
REFERENCE_STEP = 0.5e-6
#: Contact damping ratios of the cases (options.contact_damping_ratio).
DAMPINGS = (0.03, 0.1, 0.2)
#: The duties (screw speed [rad/s], mean load, swing, reversal ramp [s]; loads as shares of C_a):
#: a steady stroke under a working load, and load reversals at the top of an EMA's duty.
DUTIES = {
    "steady 20 % C_a": dict(speed=100.0, load="20 % C_a", load_profile="constant"),
    "reversing ±25 % C_a": dict(
        speed=100.0,
        load=0.0,
        load_profile="reversing",
        load_amplitude="25 % C_a",
        load_frequency=10.0,
        load_ramp_time=0.01,
    ),
}
#: Tolerances: (band power below 3 kHz, 3–8 kHz), line frequency, indicator floor, energy, modes.
BAND_TOLERANCE = (0.10, 0.20)
LINE_TOLERANCE = 1e-3
INDICATOR_FLOOR = 0.02
#: Standard errors of the difference of two seed means an indicator may move by (second rule).
STANDARD_ERRORS = 3.0
ENERGY_TOLERANCE = 0.01
MODE_TOLERANCE = 0.005
#: A third-octave band is judged when it holds at least this share of its channel's power.
BAND_SHARE = 1e-4
#: Third-octave centre frequencies [Hz], IEC 61260 base-10 (10^(n/10)): 25 Hz … 7.94 kHz.
THIRD_OCTAVES = 10.0 ** (np.arange(14, 40) / 10.0)
#: The truth signals whose band power is compared: the true values of the measured vibration
#: and drive torque.
BAND_CHANNELS = ("nut_axial_accel", "motor_torque")


@dataclass(frozen=True)
class Case:
    """One simulated case: duty, contact damping, seed."""

    duty: str
    damping: float
    seed: int
    duration: float


def case_scenario(case: Case, options: dict, design="paper01"):
    """The Scenario of one case simulated with ``options`` (SimulationOptions fields) and
    ``design``: a 0.5 mm nut spall, 10 µm clearance, Hertzian flanks, the case's damping."""
    from prsm_health.actuator.faults import Spall
    from prsm_health.actuator.states import HealthState, OperatingProfile
    from prsm_health.simulation.dynamics.model import SimulationOptions
    from prsm_health.simulation.scenario import Scenario

    merged = {"contact_law": "hertz", "contact_damping_ratio": case.damping, **options}
    return Scenario(
        design=design,
        health=HealthState.uniform(10e-6, faults=(Spall(location="nut"),)),
        profile=OperatingProfile(duration=case.duration, **DUTIES[case.duty]),
        options=SimulationOptions(**merged),
        seed=case.seed,
    )


def _third_octaves(x: np.ndarray, sample_rate: float) -> np.ndarray:
    """Band powers of the third-octave bands :data:`THIRD_OCTAVES`,
    from a Welch PSD of the linearly detrended signal."""
    from scipy import signal

    f, psd = signal.welch(signal.detrend(x), sample_rate, nperseg=min(len(x), 4096))
    df = f[1] - f[0]
    lo, hi = THIRD_OCTAVES * 10.0**-0.05, THIRD_OCTAVES * 10.0**0.05
    power = np.array([psd[(f >= a) & (f < b)].sum() * df for a, b in zip(lo, hi)])
    return power


def _line(x: np.ndarray, sample_rate: float, expected: float, envelope: bool) -> float:
    """Frequency [Hz] of the largest line within ±3 % of ``expected`` (of the envelope)."""
    from prsm_health.signals.spectra import amplitude_spectrum, hilbert_envelope

    y = hilbert_envelope(x - x.mean()) if envelope else x
    f, a = amplitude_spectrum(y - y.mean(), sample_rate)
    band = (f >= 0.97 * expected) & (f <= 1.03 * expected)
    return float(f[band][np.argmax(a[band])]) if band.any() else math.nan


def measure(case: Case, options: dict, design="paper01") -> dict:
    """Everything the check compares, for one case simulated with ``options`` (and ``design``,
    a name or a PRSMDesign)."""
    from prsm_health.physics.kinematics import characteristic_frequencies, defect_frequencies
    from prsm_health.signals.features import extract_features
    from prsm_health.simulation.dynamics.model import build_model
    from prsm_health.simulation.dynamics.simulate import linearised_eigenvalues

    scenario = case_scenario(case, options, design)
    run = scenario.simulate()
    design, rate = scenario.design, run.sample_rate
    speed = float(scenario.profile.speed)
    accel = run.truth["nut_axial_accel"]
    bands = {ch: _third_octaves(run.truth[ch], rate) for ch in BAND_CHANNELS}
    lines = {
        "gear mesh": _line(accel, rate, characteristic_frequencies(design, speed).gear_mesh, False),
        "nut spall (envelope)": _line(
            accel, rate, defect_frequencies(design, speed)["nut_flank"], True
        ),
    }
    model = build_model(
        design, scenario.health, scenario.profile, scenario.options, case.seed,
        scenario.drive_train,
    )  # fmt: skip
    eig = linearised_eigenvalues(model)
    freqs = np.sort(np.abs(eig.imag[eig.imag > 0])) / (2.0 * math.pi)
    features = {k: v for k, v in extract_features(run, design).items() if np.isfinite(v)}
    return {
        "bands": bands,
        "lines": lines,
        "features": features,
        "energy": {k: run.energy[k] for k in ("drive", "dissipated")},
        "modes": freqs[freqs < 5000.0],
        "step": run.scenario["integration_step"],
    }


def _measure_both(args) -> tuple[dict, dict]:
    case, candidate, design = args
    return measure(case, candidate, design), measure(case, {"max_step": REFERENCE_STEP})


def acceptance(
    candidate: dict,
    *,
    seeds: int = 3,
    duration: float = 0.5,
    dampings: tuple = DAMPINGS,
    duties: tuple = tuple(DUTIES),
    workers: int = 1,
    candidate_design="paper01",
) -> list[dict]:
    """The acceptance check of ``candidate`` (SimulationOptions fields, e.g.
    ``{"max_step": "auto"}``; simulated with ``candidate_design``, a name or a PRSMDesign)
    against the reference (paper01), one row per (duty, damping, criterion):
    ``duty``, ``damping``, ``criterion``, ``worst`` (the largest deviation, relative),
    ``tolerance``, ``passed``, ``detail`` (where the worst one is)."""
    groups = [(d, c) for d in duties for c in dampings]
    cases = [Case(d, c, s, duration) for d, c in groups for s in range(seeds)]
    jobs = [(case, candidate, candidate_design) for case in cases]
    if workers > 1:
        with ProcessPoolExecutor(workers) as pool:
            results = list(pool.map(_measure_both, jobs))
    else:
        results = [_measure_both(job) for job in jobs]
    rows = []
    for duty, damping in groups:
        pairs = [
            r for case, r in zip(cases, results) if (case.duty, case.damping) == (duty, damping)
        ]
        rows += [
            dict(duty=duty, damping=damping, **row)
            for row in _compare([p[0] for p in pairs], [p[1] for p in pairs])
        ]
    return rows


def markdown_table(rows: list[dict]) -> str:
    """:func:`acceptance`'s rows as one Markdown table, a row per duty, damping and criterion."""
    lines = [
        "| duty | contact damping | criterion | worst deviation | tolerance | where | passed |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        tol = r["tolerance"]
        tol = tol if isinstance(tol, tuple) else (tol,)
        lines.append(
            f"| {r['duty']} | {r['damping']:g} | {r['criterion']} | {100 * r['worst']:.2f} % | "
            + " / ".join(f"{100 * t:g} %" for t in tol)
            + f" | {r['detail']} | {'yes' if r['passed'] else '**no**'} |"
        )
    return "\n".join(lines)


def _row(criterion, deviations: dict, tolerance) -> dict:
    """Row of one criterion: ``deviations`` maps where → (deviation, its tolerance)."""
    if not deviations:
        return dict(criterion=criterion, worst=0.0, tolerance=tolerance, passed=True, detail="")
    where = max(deviations, key=lambda k: deviations[k][0] / deviations[k][1])
    worst, allowed = deviations[where]
    failing = sum(d > t for d, t in deviations.values())
    detail = f"{where} ({failing} of {len(deviations)} outside)" if failing else where
    return dict(
        criterion=criterion, worst=worst, tolerance=allowed, passed=not failing, detail=detail
    )


def _compare(candidate: list[dict], reference: list[dict]) -> list[dict]:
    band_dev = {}
    for ch in BAND_CHANNELS:
        cand = np.mean([r["bands"][ch] for r in candidate], axis=0)
        ref = np.mean([r["bands"][ch] for r in reference], axis=0)
        judged = ref >= BAND_SHARE * ref.sum()
        for fc, c, r, use in zip(THIRD_OCTAVES, cand, ref, judged):
            if use and fc < 8000.0:
                tol = BAND_TOLERANCE[0] if fc < 3000.0 else BAND_TOLERANCE[1]
                band_dev[f"{ch} {fc:.0f} Hz"] = (abs(c - r) / r, tol)
    line_dev = {}
    for name in reference[0]["lines"]:
        for k, (c, r) in enumerate(zip(candidate, reference)):
            fc, fr = c["lines"][name], r["lines"][name]
            if np.isfinite(fr):
                line_dev[f"{name}, seed {k}"] = (abs(fc - fr) / fr, LINE_TOLERANCE)
    feature_dev, feature_se = {}, {}
    for name in reference[0]["features"]:
        ref = np.array([r["features"].get(name, np.nan) for r in reference])
        cand = np.array([r["features"].get(name, np.nan) for r in candidate])
        mean = np.nanmean(ref)
        if not np.isfinite(mean) or mean == 0.0 or not np.isfinite(np.nanmean(cand)):
            continue
        spread = np.nanstd(ref) / abs(mean)
        deviation = abs(np.nanmean(cand) - mean) / abs(mean)
        feature_dev[name] = (deviation, max(spread, INDICATOR_FLOOR))
        # the same, sized for two means of n seeds each: a candidate that differs from the
        # reference only as another seed would exceeds one spread for ≈ 22 % of indicators at
        # n = 3, and STANDARD_ERRORS standard errors of the difference for ≈ 0.3 %
        n = np.sum(np.isfinite(ref))
        bound = STANDARD_ERRORS * np.nanstd(ref, ddof=1) * np.sqrt(2.0 / n) if n > 1 else 0.0
        feature_se[name] = (deviation, max(bound / abs(mean), INDICATOR_FLOOR))
    energy_dev = {}
    for key in ("drive", "dissipated"):
        c = np.mean([r["energy"][key] for r in candidate])
        r = np.mean([r["energy"][key] for r in reference])
        energy_dev[f"{key} work"] = (abs(c - r) / max(abs(r), 1e-12), ENERGY_TOLERANCE)
    mode_dev = {}
    for k, (c, r) in enumerate(zip(candidate, reference)):
        n = min(len(c["modes"]), len(r["modes"]))
        if len(c["modes"]) != len(r["modes"]):
            mode_dev[f"seed {k}: mode count"] = (math.inf, MODE_TOLERANCE)
        for j in range(n):
            dev = abs(c["modes"][j] - r["modes"][j]) / r["modes"][j]
            mode_dev[f"seed {k}: {r['modes'][j]:.0f} Hz"] = (dev, MODE_TOLERANCE)
    return [
        _row("third-octave band power", band_dev, BAND_TOLERANCE),
        _row("mesh and defect lines", line_dev, LINE_TOLERANCE),
        _row("indicators (seed means, the issue's rule)", feature_dev, INDICATOR_FLOOR),
        _row("indicators (seed means, 3 standard errors)", feature_se, INDICATOR_FLOOR),
        _row("energy (drive, dissipated work)", energy_dev, ENERGY_TOLERANCE),
        _row("eigenfrequencies below 5 kHz", mode_dev, MODE_TOLERANCE),
    ]
