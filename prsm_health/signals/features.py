"""Condition indicators of a run or a window: gear mesh, shifted axial frequency, classic, torque.

Every indicator is a named float with a documented unit (:data:`FEATURES`); an indicator that a
window cannot support (no reversal for lost motion, no speed for mesh lines) is NaN — the
estimators handle missing values. Spectra use Hann windows with explicit scaling:

* amplitude spectra are corrected for the window's coherent gain (a sinusoid of amplitude A
  reads A) — :func:`prsm_health.signals.spectra.amplitude_spectrum`;
* power spectral densities are Welch estimates (Hann, 75 % overlap, density scaling, units²/Hz);
  band energies integrate them (units², i.e. the band's mean-square value).

Indicators are computed from the measured channels (:attr:`Run.channels`) only. A channel the
recording lacks (an instrumentation profile without the load cell, without some accelerometer
axes) makes the indicators that need it NaN: the indicator set is always :data:`FEATURES`.
Truth signals (:attr:`Run.truth`, simulator only) are read only when the caller names them
(``extract_features(run, truth=("friction_torque",))``, :data:`TRUTH_FEATURES`): research
indicators, never a model input by default.

Gear-mesh lines are located from the measured screw speed through the design's rigid-body
carrier ratio (from the true carrier speed only when ``"carrier_speed"`` is asked for); when the
speed varies by more than 5 % in a window the signal is resampled to uniform screw angle (order
domain) before the spectrum.

The shifted-axial-frequency indicator compares the dominant nut axial frequency with the physics'
healthy baseline √(k_axial/m_N)/2π (paper-04 thread stiffness, all rollers, at the mean load);
the contact-mode indicators track that mode inside the band the linearised model predicts for the
duty and clearance range instead of the largest peak (:mod:`prsm_health.signals.axial_mode`).

References
----------
Paper 01 §3.2–3.3 (mesh frequency, axial frequency shift with clearance); paper 04 (axial
stiffness); paper 02 (friction torque, efficiency).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy.ndimage import uniform_filter1d

from prsm_health.actuator.design import DEFAULT_PRESET, PRSMDesign, preset
from prsm_health.actuator.design_files import design_of, load_design
from prsm_health.core.channels import CHANNEL_NAMES
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.operating_point import NO_DESIGN
from prsm_health.core.run import Run
from prsm_health.physics.kinematics import defect_frequencies, speed_ratios

from .channel_statistics import channel_statistics
from .envelope_analysis import defect_lines_batch
from .gear_indicators import synchronous_averages, tsa_indicators
from .generic_indicators import generic_indicators
from .indicator_table import (  # the indicators' table, declared there
    AXIAL_SEARCH,
    BANDS,
    DEFECTS,
    ENVELOPE_CHANNELS,
    FEATURES,
    GROUP_CHANNELS,
    GROUPS,
    MESH_CHANNELS,
    ORDER_TRACKING_SPREAD,
    SEARCH_SHARE,
    SHORT,
    TRUTH_FEATURES,
    TSA_CHANNELS,
    TSA_INDICATORS,
)
from .kernels import hysteresis_crossings, moment_sums, screw_power_sums
from .lost_motion import lost_motion_spread
from .percentiles import percentiles
from .reset_comb import reset_comb_indicators
from .spectra import amplitude_spectrum, peak_frequency, welch_psd

#: Most windows processed together by :func:`extract_features_batch` (memory: the
#: mean-removed vibration of a window of 20,000 samples takes 0.64 MB).
BATCH_WINDOWS = 16


@lru_cache(maxsize=256)
def axial_baseline_frequency(design: PRSMDesign, load: float) -> float:
    """Healthy nut axial frequency √(k_axial/m_N)/2π [Hz] at an axial load [N] (paper 04 stiffness)."""
    from prsm_health.physics.stiffness.thread_load import roller_side_stiffness

    per_roller = max(abs(load), 20.0) / design.n_rollers
    k_s = float(roller_side_stiffness(design, per_roller, "screw"))
    k_n = float(roller_side_stiffness(design, per_roller, "nut"))
    k = design.n_rollers * k_s * k_n / (k_s + k_n)
    return math.sqrt(k / design.masses.nut_mass) / (2 * math.pi)


def _classic(centred: np.ndarray, rate: float) -> tuple[dict[str, np.ndarray], tuple]:
    """Classic indicators of mean-removed signals (..., n): name suffix → array (...), and the
    Welch spectra their bands integrate: (frequencies, PSD (..., bins), segment length)."""
    # moments about the mean, biased (scipy.stats.kurtosis(fisher=False) and skew): the sums
    # of x², x³, x⁴ and the extremes in one compiled pass (numpy made five over the batch)
    sums = np.empty(centred.shape[:-1] + (5,))
    moment_sums(centred.reshape(-1, centred.shape[-1]), sums.reshape(-1, 5))
    m2, m3, m4 = (sums[..., k] / centred.shape[-1] for k in range(3))
    rms = np.sqrt(m2)
    peak = np.maximum(sums[..., 3], -sums[..., 4])
    live = rms > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        out = {
            "rms": rms,
            "peak": peak,
            "crest": np.where(live, peak / rms, np.nan),
            "kurtosis": np.where(live, m4 / m2**2, np.nan),
            "skewness": np.where(live, m3 / m2**1.5, np.nan),
        }
    nperseg = min(1024, centred.shape[-1])
    f, psd = welch_psd(centred, rate, nperseg, 3 * nperseg // 4)
    df = f[1] - f[0]
    for lo, hi in BANDS:
        a, b = np.searchsorted(f, (lo, min(hi, rate / 2)))  # the bins lo ≤ f < hi
        out[f"band_{int(lo)}_{int(hi)}"] = (
            np.sum(psd[..., a:b], axis=-1) * df if b > a else np.full(psd.shape[:-1], np.nan)
        )
    return out, (f, psd, nperseg)


def _lines(freq: np.ndarray, amp: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """The largest amplitude within ±max(2 bins, 0.5 %) of each target [Hz] (the line may fall
    between bins and the speed estimate carries its own error): ``amp`` (spectra, bins) and
    ``targets`` (spectra, lines) → (spectra, lines); NaN for a target outside (0, freq[-1])."""
    valid = np.isfinite(targets) & (targets > 0) & (targets < freq[-1])
    target = np.where(valid, targets, 0.0)
    half = np.maximum(2 * (freq[1] - freq[0]), 0.005 * target)
    a = np.searchsorted(freq, target - half, side="left")
    b = np.searchsorted(freq, target + half, side="right")
    out = np.full(targets.shape, np.nan)
    for i, k in zip(*np.nonzero(valid & (b > a))):
        out[i, k] = amp[i, a[i, k] : b[i, k]].max()
    return out


def _order_resample(x: np.ndarray, angle: np.ndarray) -> tuple[np.ndarray, float]:
    # Uniform screw-angle grid with the same number of samples: spectrum in orders per radian.
    grid = np.linspace(angle[0], angle[-1], len(angle))
    return np.interp(grid, angle, x), (grid[1] - grid[0])


def _truth_request(run: Run, truth) -> tuple[str, ...]:
    """The truth signals asked for, checked: known to :data:`TRUTH_FEATURES` and in the run."""
    if isinstance(truth, str):
        raise PRSMHealthError(f"truth = {truth!r}: give a tuple of names, e.g. ({truth!r},)")
    truth = tuple(truth)
    unknown = [n for n in truth if n not in TRUTH_FEATURES]
    if unknown:
        raise PRSMHealthError(
            f"no truth indicator reads {', '.join(map(repr, unknown))}; "
            f"available: {', '.join(TRUTH_FEATURES)}"
        )
    missing = [n for n in truth if n not in run.truth]
    if missing:
        raise PRSMHealthError(
            f"truth {', '.join(missing)} asked for, but the run has no such truth signal "
            "(only simulated runs have truth)"
        )
    return truth


def extract_features(
    run: Run,
    design: PRSMDesign | str | dict | None = None,
    *,
    truth: tuple[str, ...] = (),
    lead: float | None = None,
) -> dict[str, float]:
    """All indicators of one run or window.

    Parameters
    ----------
    run : Run
        Measured channels at ``run.sample_rate``; missing channels give NaN indicators.
        ``run.truth`` is not read unless named in ``truth``.
    design : PRSMDesign, preset name, design TOML file, dict form, :data:`NO_DESIGN` or None
        Default (None): the run's own design (:func:`run_design`: its scenario's, else a
        preset its operating point names, else paper01 for a run that names none).
        :data:`NO_DESIGN` (or a run whose operating point says so, an imported rig that is not
        a PRSM): the indicators that need the design's kinematics (mesh, gear, envelope, axial
        baseline) are NaN.
    lead : float or None [m per revolution of screw_angle]
        Without a design, the lead lost motion needs (default the run's ``operating.lead``).
    truth : tuple of str
        Truth signals to use (keys of :data:`TRUTH_FEATURES`), research only: each adds its
        indicators; ``"carrier_speed"`` locates the mesh lines from the true carrier speed.

    Returns
    -------
    dict of name → float, in :data:`FEATURES` order and units, then the indicators of the
    truth signals asked for.

    Raises
    ------
    RecordingError
        The measured channels (or the truth signals asked for) cannot be processed.
    PRSMHealthError
        No nut acceleration and no nut position; an unknown or absent truth signal asked for;
        a run that names a design that is not a preset and carries no design, no ``design``
        given.
    ParameterError
        A ``design`` that is not a preset, a design file or a valid dict form.
    """
    return extract_features_batch([run], design, truth=truth, lead=lead)[0]


def extract_features_batch(
    runs: list[Run],
    design: PRSMDesign | str | dict | None = None,
    *,
    truth: tuple[str, ...] = (),
    lead: float | None = None,
) -> list[dict[str, float]]:
    """:func:`extract_features` of several windows, one dict each, equal to one at a time.

    Windows of one length, sample rate, channel set and design (the windows of a recording)
    are processed together, up to :data:`BATCH_WINDOWS` at a time: each step takes all their
    channels in one call (the Welch spectra, kurtograms and envelopes then transform them row
    by row, where a row's frames stay in the cache).
    """
    given = _given_design(design)
    # windows of one recording share its scenario and operating point: resolve its design once
    designs: dict[tuple[int, int], PRSMDesign | None] = {}
    prepared = [_prepare(run, given, truth, lead, designs) for run in runs]
    groups: dict[tuple, list[int]] = {}
    for i, (run, window_design, run_lead) in enumerate(prepared):
        key = (len(run), run.sample_rate, tuple(sorted(run.channels)), window_design, run_lead)
        groups.setdefault(key, []).append(i)
    rows: list = [None] * len(runs)
    for index in groups.values():
        for start in range(0, len(index), BATCH_WINDOWS):
            chunk = index[start : start + BATCH_WINDOWS]
            _, window_design, run_lead = prepared[chunk[0]]
            found = _extract([prepared[i][0] for i in chunk], window_design, run_lead)
            for i, row in zip(chunk, found):
                rows[i] = row
    return rows


#: :func:`_prepare` takes the design from the run.
_FROM_RUN = object()


def _given_design(design) -> PRSMDesign | None | object:
    """The ``design`` argument resolved once: :data:`_FROM_RUN` (None given), None
    (:data:`NO_DESIGN`) or the design (a preset name, a design file, a dict or a design)."""
    if design is None:
        return _FROM_RUN
    if isinstance(design, str) and design == NO_DESIGN:
        return None
    return load_design(design)


def run_design(run: Run) -> PRSMDesign | None:
    """The design a run's indicators are computed for, from the run alone.

    Its scenario's design (a simulated run's, a dataset run's), else a preset its operating
    point names (:func:`~prsm_health.actuator.design_files.design_of`); None for a run whose
    operating point names :data:`NO_DESIGN` (a rig that is not a PRSM); paper01 for a run that
    names no design at all.

    Raises
    ------
    PRSMHealthError
        The run names a design that is not a preset and carries no design.
    """
    found = design_of(run)
    if found is not None:
        return found
    name = run.operating.design
    if name is None:
        return preset(DEFAULT_PRESET)
    if name == NO_DESIGN:
        return None
    raise PRSMHealthError(
        f"run of design {name!r} carries no design and it is not a preset: "
        "pass design=<PRSMDesign or design file>"
    )


def _prepare(
    run: Run, design, truth, lead, designs: dict | None = None
) -> tuple[Run, PRSMDesign | None, float | None]:
    """(the window with only what is read, checked; its design; the lead without a design).

    ``design``: what :func:`_given_design` made of the argument; ``designs`` memoises
    :func:`run_design` by the identity of the run's scenario and operating point."""
    if design is _FROM_RUN:
        # ids are unique here: every run of the batch is alive while it is prepared
        key, memo = (id(run.scenario), id(run.operating)), {} if designs is None else designs
        if key not in memo:
            memo[key] = run_design(run)
        design = memo[key]
    truth = _truth_request(run, truth)
    # Only what is read: the measured channels and the truth signals asked for.
    run = Run(
        run.time,
        run.channels,
        run.sample_rate,
        truth={name: run.truth[name] for name in truth},
        operating=run.operating,
    ).validate(what="window")
    if not any(name in CHANNEL_NAMES for name in run.channels):
        raise PRSMHealthError(
            "no usable channels: the recording has no measured channel of the contract "
            f"({', '.join(CHANNEL_NAMES)})"
        )
    if design is None:
        lead = lead if lead is not None else run.operating.lead
    return run, design, lead


def _extract(runs: list[Run], design: PRSMDesign | None, lead: float | None) -> list[dict]:
    """The indicators of windows of one length, rate, channel set and design."""
    rate = runs[0].sample_rate
    rows = []
    for run in runs:
        row = dict.fromkeys(FEATURES, np.nan)
        for name in run.truth:
            row.update(dict.fromkeys(TRUTH_FEATURES[name], np.nan))
        rows.append(row)
    present = runs[0].channels
    vibration = [name for name in SHORT if name in present]
    # mean-removed vibration (channel, window, sample): what every spectral indicator reads
    centred = {}
    if vibration:
        stacked = np.stack([[run.channels[name] for run in runs] for name in vibration])
        stacked -= np.mean(stacked, axis=-1, keepdims=True)  # a fresh copy: centred in place
        centred = dict(zip(vibration, stacked))
        classic, (f, psd, nperseg) = _classic(stacked, rate)
        welch = {name: (f, psd[c], nperseg) for c, name in enumerate(vibration)}
        for suffix, values in classic.items():
            for c, name in enumerate(vibration):
                for row, value in zip(rows, values[c]):
                    row[f"{SHORT[name]}_{suffix}"] = float(value)

    ratios = speed_ratios(design) if design is not None else None
    for run, row in zip(runs, rows):
        _operating(run, row)
    _mesh(runs, rows, design, ratios, centred)
    # ---- time-synchronous averages and the gear indicators (docs/gear-indicators.md)
    if "screw_angle" in present and design is not None:
        _gear(runs, design, ratios, rows)
        if design.variant == "recirculating":  # the resets' comb (signals.reset_comb)
            for run, row in zip(runs, rows):
                row.update(reset_comb_indicators(run.channels, design, SEARCH_SHARE))
    # ---- envelope lines at the defect frequencies, band by spectral kurtosis
    if design is not None:
        _envelope(runs, rows, design)
    # ---- shifted axial frequency
    if "nut_axial_accel" in centred:
        _axial(centred["nut_axial_accel"], rate, design, rows, welch["nut_axial_accel"])
    # nut travel per screw radian: the design's kinematics, or the rig's lead
    nut_per_rad = ratios.nut if ratios is not None else (lead / (2 * math.pi) if lead else None)
    for run, row in zip(runs, rows):
        _torque_and_reversals(run, nut_per_rad, row)
        row.update(generic_indicators(run, nut_per_rad))
        row.update(channel_statistics(run))
    # what a group measures lies above the recording's band: not a value, NaN
    for group, needs in GROUP_CHANNELS.items():
        if needs.too_slow(rate):
            for row in rows:
                row.update(dict.fromkeys(GROUPS[group], np.nan))
    return rows


def _operating(run: Run, out: dict) -> None:
    speed, load = run.channels.get("screw_speed"), run.channels.get("axial_load")
    if speed is not None:
        out["speed_mean"] = float(np.mean(speed))
    if load is not None:
        out["load_mean"] = float(np.mean(load))
        out["load_range"] = float(np.ptp(load))
    # the measured housing temperature: the lubricant's confounder (docs/faults.md)
    temperature = run.channels.get("housing_temperature")
    if temperature is not None:
        out["housing_temperature_mean"] = float(np.mean(temperature))


def _carrier_frequency(run: Run, ratios) -> float:
    """Carrier rotation frequency [Hz]: measured screw speed × carrier ratio, or the truth."""
    speed = run.channels.get("screw_speed")
    if "carrier_speed" in run.truth:
        return abs(float(np.mean(run.truth["carrier_speed"]))) / (2 * math.pi)
    if speed is not None and ratios:
        return abs(ratios.carrier * float(np.mean(speed))) / (2 * math.pi)
    return np.nan


def _mesh(runs, rows, design, ratios, centred: dict) -> None:
    """Gear mesh lines: the windows at steady speed share one spectrum call per channel."""
    if design is None or design.gear is None:
        return
    z = design.gear.ring_teeth
    rate = runs[0].sample_rate
    steady = []
    for w, (run, row) in enumerate(zip(runs, rows)):
        f_c = _carrier_frequency(run, ratios)
        if not (np.isfinite(f_c) and f_c > 0):
            continue
        row["mesh_frequency"] = z * f_c
        ch = run.channels
        speed = ch.get("screw_speed")
        varying = speed is not None and np.std(speed) > ORDER_TRACKING_SPREAD * abs(np.mean(speed))
        if (
            varying
            and "screw_angle" in ch
            and np.all(np.diff(ch["screw_angle"]) * np.sign(np.mean(speed)) > 0)
        ):
            # order domain: mesh order = z·(carrier/screw) per screw radian
            for name in MESH_CHANNELS:
                if name in ch:
                    x, d_angle = _order_resample(ch[name], ch["screw_angle"])
                    orders, amp = amplitude_spectrum(x, 1.0 / d_angle)
                    per_rad = abs(ratios.carrier) / (2 * math.pi)
                    _mesh_lines(orders, amp[None], [z * per_rad], [per_rad], SHORT[name], [row])
        else:
            steady.append((w, f_c))
    for name in MESH_CHANNELS:
        if name in centred and steady:
            freq, amp = amplitude_spectrum(centred[name][[w for w, _ in steady]], rate)
            f_c = [f for _, f in steady]
            found = [rows[w] for w, _ in steady]
            _mesh_lines(freq, amp, [z * f for f in f_c], f_c, SHORT[name], found)


def _mesh_lines(freq, amp, bases, sides, prefix: str, rows: list[dict]) -> None:
    """The mesh harmonics and sidebands of each spectrum of ``amp`` (spectra, bins) at its
    mesh frequency ``bases`` and sideband spacing ``sides``, into its row."""
    base, side = np.asarray(bases, float)[:, None], np.asarray(sides, float)[:, None]
    lines = _lines(freq, amp, np.hstack([base * np.arange(1, 4), base - side, base + side]))
    sidebands = np.nansum(lines[:, 3:], axis=1)
    for out, harmonics, sideband in zip(rows, lines, sidebands):
        for k in (1, 2, 3):
            out[f"{prefix}_mesh_h{k}"] = float(harmonics[k - 1])
        out[f"{prefix}_mesh_sidebands"] = float(sideband)


def _axial(centred: np.ndarray, rate: float, design, rows, welch: tuple) -> None:
    """Dominant nut axial frequency and its shift from the healthy baseline, every window's
    Welch spectrum in one call; the contact mode (:mod:`prsm_health.signals.axial_mode`),
    from the classic indicators' Welch spectra ``welch`` (frequencies, PSD, segment) when its
    tracking segment is theirs (1024 samples at 20 kHz: the same spectrum, computed once)."""
    nperseg = min(512, centred.shape[-1])
    f, psds = welch_psd(centred, rate, nperseg, 3 * nperseg // 4)
    for psd, out in zip(psds, rows):
        f_dom = peak_frequency(f, psd, (AXIAL_SEARCH[0], min(AXIAL_SEARCH[1], SEARCH_SHARE * rate)))
        out["axial_dominant_frequency"] = f_dom
        band = (f > 0.9 * f_dom) & (f < 1.1 * f_dom)
        out["axial_dominant_amplitude"] = (
            float(np.sqrt(np.sum(psd[band]) * (f[1] - f[0]))) if band.any() else np.nan
        )
        mean_load = abs(out["load_mean"]) if np.isfinite(out["load_mean"]) else 100.0
        if design is not None and design.gear is not None:
            f0 = axial_baseline_frequency(design, round(mean_load, 1))
            out["axial_baseline_frequency"] = f0
            out["axial_frequency_shift"] = f_dom - f0
            out["axial_frequency_shift_relative"] = (f_dom - f0) / f0
    if design is not None and design.gear is not None:  # paper 01's mode, tracked in its band
        from .axial_mode import contact_indicators, tracking_segment

        f_classic, psd_classic, nperseg = welch
        shared = nperseg == tracking_segment(centred.shape[-1], rate)
        spectra = (f_classic, psd_classic) if shared else None
        for out, values in zip(
            rows, contact_indicators(centred, rate, design, rows, welch=spectra)
        ):
            out.update(values)


def _torque_and_reversals(run: Run, nut_per_rad: float | None, out: dict) -> None:
    ch = run.channels
    speed, load = ch.get("screw_speed"), ch.get("axial_load")
    rate = run.sample_rate
    # ---- torque
    if "friction_torque" in run.truth:
        out["friction_torque_mean"] = float(np.mean(run.truth["friction_torque"]))
        out["friction_torque_ripple"] = float(np.std(run.truth["friction_torque"]))
    if "drive_torque" in ch:
        out["drive_torque_mean"] = float(np.mean(ch["drive_torque"]))
        out["drive_torque_ripple"] = float(np.std(ch["drive_torque"]))
        if speed is not None and load is not None and "nut_position" in ch:
            # drive_torque is the motor's, screw_speed the gearbox output's: the input power
            # is T_m·N·ω_s: the efficiency is the drive's from the motor shaft (reduction, screw)
            out["efficiency"] = _window_efficiency(
                ch["drive_torque"] * run.operating.gear_ratio,
                speed,
                load,
                ch["nut_position"],
                run.time,
            )

    # ---- reversals: of the motion, of the load (load cell), or of the drive torque when no
    # load cell is fitted (the motor current reverses with the load it carries)
    torque = ch.get("drive_torque")
    # the motor torque averaged over 5 ms: current noise and ripple out, load reversals kept
    # (read only without a load cell)
    slow_torque = None
    if load is None and torque is not None:
        slow_torque = uniform_filter1d(torque, max(1, int(0.005 * rate)))
    reversal = (
        (speed is not None and np.min(speed) < 0 < np.max(speed))
        or (load is not None and np.min(load) < 0 < np.max(load))
        or (load is None and slow_torque is not None and _reverses(slow_torque))
    )
    if speed is not None or load is not None or torque is not None:
        out["reversal"] = float(reversal)
    if reversal and torque is not None:
        out["torque_rattle_rate"] = _rattle_rate(torque, rate)
    # lost motion: nut lag behind the rigid kinematics across a reversal
    if "nut_position" in ch and "screw_angle" in ch and nut_per_rad is not None:
        if reversal:
            if speed is not None and np.min(speed) < 0 < np.max(speed):
                side = np.sign(speed)
            else:  # the load's sign, from the load cell or else the drive torque
                force = load if load is not None else slow_torque
                side = np.sign(force - 0.5 * (np.max(force) + np.min(force)))
            out["lost_motion"] = lost_motion_spread(
                ch["nut_position"], ch["screw_angle"], nut_per_rad, side
            )


def _envelope(runs, rows, design: PRSMDesign) -> None:
    """Envelope lines of every window with a speed: all windows' and channels' kurtograms and
    envelope spectra together."""
    present = [name for name in ENVELOPE_CHANNELS if name in runs[0].channels]
    jobs = []  # (window, channel, its defect frequencies)
    for w, run in enumerate(runs):
        speed = run.channels.get("screw_speed")
        if speed is not None and abs(float(np.mean(speed))) > 0:
            frequencies = defect_frequencies(design, float(np.mean(speed)))
            names = {k: v for k, v in frequencies.items() if k in DEFECTS}
            jobs += [(w, name, names) for name in present]
    if not jobs:
        return
    x = np.stack([runs[w].channels[name] for w, name, _ in jobs])
    results = defect_lines_batch(x, runs[0].sample_rate, [names for _, _, names in jobs])
    for (w, name, _), result in zip(jobs, results):
        if isinstance(result, PRSMHealthError):  # no band fits (low sample rate, short window)
            continue
        s, out = SHORT[name], rows[w]
        out[f"{s}_sk_max"] = result["sk"]
        out[f"{s}_sk_band_centre"] = 0.5 * sum(result["band"])
        for defect, line in result["lines"].items():
            out[f"{s}_env_{defect}"] = line["amplitude"]
            out[f"{s}_env_{defect}_ratio"] = line["ratio"]
            out[f"{s}_env_{defect}_ratio_sum"] = line["ratio_sum"]


def _gear(runs, design: PRSMDesign, ratios, rows) -> None:
    """TSA indicators over carrier and roller periods: each period's TSAs of every window
    and channel in one call."""
    periods = {"carrier": (ratios.carrier, None), "roller": (ratios.roller_spin_relative, None)}
    if design.gear is not None and design.variant != "recirculating":
        periods = {
            "carrier": (ratios.carrier, design.gear.ring_teeth),
            "roller": (ratios.roller_spin_relative, design.gear.roller_teeth),
        }
    present = [name for name in TSA_CHANNELS if name in runs[0].channels]
    if not present:
        return
    # periods averaged → [(window, TSAs of its channels)], per period
    by_count: dict[str, dict[int, list]] = {period: {} for period in periods}
    angles = [2 * math.pi / abs(ratio) for ratio, _ in periods.values()]
    for w, run in enumerate(runs):
        x = np.stack([run.channels[name] for name in present])
        averages = synchronous_averages(x, run.channels["screw_angle"], angles)
        for period, (tsa, count) in zip(periods, averages or ()):
            by_count[period].setdefault(count, []).append((w, tsa))
    for period, (_, teeth) in periods.items():
        for count, found in by_count[period].items():
            values = tsa_indicators(np.concatenate([tsa for _, tsa in found]), count, teeth)
            for k, (w, name) in enumerate((w, name) for w, _ in found for name in present):
                for key in TSA_INDICATORS:
                    rows[w][f"{SHORT[name]}_tsa_{period}_{key}"] = float(values[key][k])


def _reverses(x: np.ndarray) -> bool:
    # A sign change beyond the noise: both signs reached by a tenth of the range or more (of a
    # smoothed signal: a steady run's noise around a small mean must not count).
    margin = 0.1 * float(np.ptp(x))
    low, high = percentiles(x, [2, 98])
    return float(low) < -margin and float(high) > margin


def _window_efficiency(torque, speed, load, position, time) -> float:
    """A window's efficiency from its energy balance: the power through the screw over itself
    plus the friction loss, ⟨|F·v|⟩ / (⟨|F·v|⟩ + ⟨T·ω − F·v⟩) [-].

    Paper 02's form, F·p_s / (F·p_s + 2π·T_loss), with the loss measured as input minus output
    power: under a steady driving load it is the efficiency η; under a load that reverses it
    stays defined (the ratio of mean powers ⟨F·v⟩/⟨T·ω⟩ does not: both means swing through 0)
    and falls as the friction rises — 1 / (1 + (1/η − η)/2) for a load driving and back-driving
    half the time each. The inertias' kinetic energy is taken as unchanged over the window (a
    speed held by the drive). NaN without power through the screw. T·ω: drive torque × screw
    speed; F·v: axial load × nut speed (``np.gradient`` of the position over time), both
    summed in one compiled pass.
    """
    arrays = (np.ascontiguousarray(a, float) for a in (torque, speed, load, position, time))
    through, loss = screw_power_sums(*arrays)
    through, total = through / len(time), (through + loss) / len(time)
    return through / total if through > 0 and total > 0 else np.nan


def _rattle_rate(torque: np.ndarray, rate: float) -> float:
    """Crossings per second of the drive torque's mid level, with ±10 % hysteresis [1/s].

    Across a reversal the nut crosses the 2b gap and strikes the other flanks; each bounce
    unloads and reloads the screw, so the motor torque swings through its mid level once per
    bounce. More clearance, faster impacts, more bounces (docs/validation.md, clearance-
    signature map). The hysteresis (10 % of the 5–95 % range) keeps sensor noise from counting.
    """
    lo, hi = percentiles(torque, [5, 95])
    mid, band = 0.5 * (lo + hi), 0.1 * (hi - lo)
    crossings = hysteresis_crossings(np.ascontiguousarray(torque, float), mid - band, mid + band)
    return crossings / (len(torque) / rate)


def windows(run: Run, length: float, hop: float | None = None):
    """Split a run into complete windows of ``length`` seconds (hop defaults to length), as
    Runs: :meth:`Run.windows <prsm_health.core.run.Run.windows>`, the one place windows are
    cut."""
    yield from run.windows(length, hop=hop)[0]


def dataset_features(dataset, run_ids=None, progress: bool = False, truth: tuple[str, ...] = ()):
    """Indicators of every run of a :class:`~prsm_health.datasets.Dataset` as a DataFrame.

    Columns: :data:`FEATURES` (then the indicators of the truth signals named in ``truth``, see
    :func:`extract_features`) plus the run labels (run_id, split, fault_class, clearances, …).
    The indicators are computed for the dataset's own design (``dataset.design``: a preset or
    the full design it was generated with); a dataset without one (an imported rig that is
    not a PRSM) leaves it to each run's labels.
    """
    import pandas as pd

    # resolved once, and what makes a dataset of one's own design work: its runs are
    # labelled with the design's name, which is not a preset
    design = getattr(dataset, "design", None)
    rows = []
    ids = list(dataset.runs["run_id"] if run_ids is None else run_ids)
    iterator = ids
    if progress:
        from tqdm import tqdm

        iterator = tqdm(ids, unit="run", desc="features")
    for run_id in iterator:
        run = dataset.run(int(run_id), truth=bool(truth))
        row = extract_features(run, design, truth=truth)
        row.update(run.labels)
        rows.append(row)
    return pd.DataFrame(rows)
