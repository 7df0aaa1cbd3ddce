"""Envelope analysis at the defect frequencies, with the band chosen by spectral kurtosis.

A localised defect (a spall, a cracked tooth) strikes once per passage: short impacts that
ring the structure's resonances. Band-passing around such a resonance and taking the envelope
(Hilbert magnitude) turns the impacts into a train at the defect frequency, whose line the
envelope spectrum shows even when the raw spectrum buries it (Randall & Antoni 2011, §3).

* **Band selection — spectral kurtosis (SK).** SK(f) = ⟨|X(t, f)|⁴⟩ / ⟨|X(t, f)|²⟩² − 2 of the
  short-time Fourier transform X [Antoni 2006, eq. 8 with the STFT estimator of §4]: 0 for
  stationary Gaussian noise, large in a band where impacts come and go. A kurtogram evaluates
  it for several window lengths N_w (frequency resolutions, the band width ≈ 2·f_s/N_w of the
  Hann main lobe); the (N_w, f) of largest SK gives the band. We use the STFT kurtogram over
  N_w = 16 … 256 rather than Antoni's fast 1/3-binary filter tree (2007): for one-second windows
  both find the same band within a bin, and the STFT form is a few lines of scipy. The SK
  estimate of Gaussian noise has a standard deviation ≈ 2/√K over K frames [Antoni 2006, §4.1];
  the largest of ~N_w/2 bins per level then reaches ≈ 3.5 of them, so a band counts as impulsive
  only above :data:`SK_THRESHOLD_SIGMAS` (5) × 2/√K — otherwise the default band is used and
  the result says so.
* **Envelope amplitude spectrum.** 4th-order Butterworth band-pass (zero phase), Hilbert
  magnitude, mean removed, Hann window over the whole signal, amplitude scaling corrected for
  the window's coherent gain — so x = (1 + m·cos 2π f_m t)·cos 2π f_c t (f_c in the band) gives a
  line of amplitude m at f_m. A band of width B only carries modulation up to B/2: lines above
  that are NaN.
* **Line-to-floor ratio** at a frequency: the largest envelope amplitude within ±max(2 bins,
  1 %) of it (the speed estimate and the line's leakage spread it), over the median of the
  envelope spectrum from 0.5× to 1.5× the frequency — dimensionless, immune to sensor gain.

References
----------
J. Antoni, "The spectral kurtosis: a useful tool for characterising non-stationary signals",
MSSP 20 (2006) 282–307. J. Antoni, "Fast computation of the kurtogram for the detection of
transient faults", MSSP 21 (2007) 108–124. R. B. Randall, J. Antoni, "Rolling element bearing
diagnostics — a tutorial", MSSP 25 (2011) 485–520.
"""

from __future__ import annotations

import math

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.core.errors import PRSMHealthError
from prsm_health.physics.kinematics import characteristic_frequencies, defect_frequencies

from .kernels import frame_power_sums, line_floors
from .spectra import amplitude_spectrum, band_envelope, hann

#: STFT window lengths of the kurtogram [samples].
KURTOGRAM_WINDOWS = (16, 32, 64, 128, 256)
#: A band is impulsive when its SK exceeds this many standard deviations of the Gaussian-noise
#: estimate (2/√K over K frames).
SK_THRESHOLD_SIGMAS = 5.0
#: Harmonics summed by the ``_sum`` indicators.
HARMONICS = 3
#: Rows band-passed, enveloped and transformed per call (8 rows of a 0.5 s window at 20 kHz
#: are 0.6 MB an array: measured 25–30 % faster than row by row and than 40 rows at once).
ENVELOPE_ROWS = 8


def _check(x: np.ndarray, rate: float) -> np.ndarray:
    if not (isinstance(rate, (int, float)) and math.isfinite(rate) and rate > 0):
        raise PRSMHealthError(f"rate = {rate!r} must be a positive sample rate [Hz]")
    x = np.asarray(x, float)
    if x.ndim != 1 or not np.all(np.isfinite(x)):
        raise PRSMHealthError("x must be a 1-D array of finite values")
    return x


def kurtogram(x: np.ndarray, rate: float, low: float = 0.0) -> dict:
    """Spectral kurtosis for each window length of :data:`KURTOGRAM_WINDOWS`, and its best band.

    Parameters
    ----------
    x : ndarray
    rate : float [Hz]
    low : float [Hz]
        Lowest band edge allowed (e.g. above the defect frequencies and the shaft harmonics).

    Returns
    -------
    dict
        ``band`` (f_lo, f_hi) [Hz], ``sk`` (its spectral kurtosis), ``impulsive`` (bool: above
        the noise threshold), ``threshold``, and ``levels``: per window length its frequencies
        [Hz] and SK values (for plots).
    """
    x = _check(x, rate)
    levels = spectral_kurtosis(x[None], rate)
    best = _best_band({n_w: (f, sk[0], k) for n_w, (f, sk, k) in levels.items()}, rate, low, len(x))
    best["levels"] = {n_w: (f, sk[0]) for n_w, (f, sk, _) in levels.items()}
    return best


def spectral_kurtosis(x: np.ndarray, rate: float) -> dict[int, tuple]:
    """Spectral kurtosis of each row of ``x`` (rows, n) at every window length of
    :data:`KURTOGRAM_WINDOWS` that fits 8 times: n_w → (frequencies [Hz], SK (rows, bins),
    frames K).

    The STFT is ``scipy.signal.stft(x, window="hann", nperseg=n_w, noverlap=3·n_w/4)``'s: Hann
    frames, the signal extended by n_w/2 zeros at both ends and zero-padded to whole frames
    (its scaling, a constant factor, cancels in the SK). Only Σ|X|² and Σ|X|⁴ over the frames
    are kept, summed block by block as the frames are transformed
    (:func:`prsm_health.signals.kernels.frame_power_sums`)."""
    x = np.ascontiguousarray(x - np.mean(x, axis=-1, keepdims=True))
    levels = {}
    for n_w in KURTOGRAM_WINDOWS:
        if x.shape[-1] < 8 * n_w:
            continue
        step = n_w - 3 * n_w // 4
        extended = x.shape[-1] + 2 * (n_w // 2)
        extended += (-(extended - n_w)) % step
        frames = (extended - n_w) // step + 1
        sk = np.empty((len(x), n_w // 2 + 1))
        for row, out in zip(x, sk):
            s2, s4 = frame_power_sums(
                row, hann(n_w), step, -(n_w // 2), frames, detrend=False, fourth=True
            )
            mean2 = s2 / frames
            with np.errstate(invalid="ignore", divide="ignore"):
                out[:] = np.where(mean2 > 0, (s4 / frames) / mean2**2 - 2.0, 0.0)
        levels[n_w] = (np.fft.rfftfreq(n_w, 1.0 / rate), sk, frames)
    return levels


def _best_band(levels: dict, rate: float, low: float, n: int) -> dict:
    """The (window length, frequency) of largest SK above its noise threshold, of one row."""
    levels = {n_w: (f, sk[None], frames) for n_w, (f, sk, frames) in levels.items()}
    best = _best_bands(levels, rate, np.array([low], float), n)[0]
    if isinstance(best, PRSMHealthError):
        raise best
    return best


def _best_bands(levels: dict, rate: float, lows: np.ndarray, n: int) -> list:
    """:func:`_best_band` of every row of the SK arrays (rows, bins) of ``levels``, each above
    its own lowest edge ``lows`` (rows,): level by level for all rows at once. A row where no
    band fits gets the :class:`PRSMHealthError` instead."""
    rows = len(lows)
    score = np.full(rows, -math.inf)  # the best SK so far, above its threshold
    sk_best = np.full(rows, -math.inf)
    threshold = np.full(rows, math.inf)
    edges = np.full((rows, 2), np.nan)
    window = np.zeros(rows, int)
    found = np.zeros(rows, bool)
    for n_w, (f, sk, frames) in levels.items():
        half_width = rate / n_w  # Hann main lobe: ±f_s/N_w
        usable = ((f - half_width)[None, :] >= lows[:, None]) & (f + half_width <= 0.45 * rate)
        some = usable.any(axis=1)
        if not some.any():
            continue
        k = np.argmax(np.where(usable, sk, -math.inf), axis=1)
        level_threshold = SK_THRESHOLD_SIGMAS * 2.0 / math.sqrt(frames)
        value = sk[np.arange(rows), k]
        better = some & (value - level_threshold > score)
        score = np.where(better, value - level_threshold, score)
        sk_best = np.where(better, value, sk_best)
        threshold = np.where(better, level_threshold, threshold)
        edges[better, 0] = f[k[better]] - half_width
        edges[better, 1] = f[k[better]] + half_width
        window[better] = n_w
        found |= better
    out = []
    for i in range(rows):
        if not found[i]:
            out.append(
                PRSMHealthError(
                    f"no kurtogram band above {lows[i]:g} Hz fits below 0.45 × {rate:g} Hz "
                    f"in {n} samples"
                )
            )
            continue
        out.append(
            {
                "band": (float(edges[i, 0]), float(edges[i, 1])),
                "sk": float(sk_best[i]),
                "impulsive": bool(sk_best[i] > threshold[i]),
                "threshold": float(threshold[i]),
                "window": int(window[i]),
            }
        )
    return out


def envelope_amplitude_spectrum(
    x: np.ndarray, rate: float, band: tuple[float, float]
) -> tuple[np.ndarray, np.ndarray]:
    """Amplitude spectrum of the envelope of ``x`` in ``band`` [Hz] (see the module docstring)."""
    x = _check(x, rate)
    freq, amp = envelope_amplitude_spectra(x[None], rate, [band])
    return freq, amp[0]


def envelope_amplitude_spectra(
    x: np.ndarray, rate: float, bands: list[tuple[float, float]]
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`envelope_amplitude_spectrum` of each row of ``x`` (rows, n) in its band."""
    for lo, hi in bands:
        if not (0 < lo < hi < rate / 2):
            raise PRSMHealthError(
                f"band = {(lo, hi)!r} must satisfy 0 < low < high < rate/2 = {rate / 2:g} Hz"
            )
    freq = np.fft.rfftfreq(x.shape[-1], 1.0 / rate)
    amp = np.empty((len(x), len(freq)))
    # a few rows per call: their envelopes and spectra stay in the cache, a whole batch's do
    # not, and row by row the calls cost more than the arithmetic
    for i in range(0, len(x), ENVELOPE_ROWS):
        rows = slice(i, i + ENVELOPE_ROWS)
        amp[rows] = amplitude_spectrum(band_envelope(x[rows], rate, bands[rows]), rate)[1]
    return freq, amp


def line_and_ratio(
    freq: np.ndarray, amp: np.ndarray, target: float, limit: float
) -> tuple[float, float]:
    """(amplitude, line-to-floor ratio) at ``target`` [Hz]; NaN outside (0, ``limit``)."""
    line, ratio = lines_and_ratios(freq, amp[None], np.array([[target]], float), np.array([limit]))
    return float(line[0, 0]), float(ratio[0, 0])


def lines_and_ratios(
    freq: np.ndarray, amp: np.ndarray, targets: np.ndarray, limits: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(amplitudes, line-to-floor ratios) of shape (rows, targets) at ``targets`` [Hz] (rows,
    targets) of the spectra ``amp`` (rows, bins); NaN outside (0, ``limits`` (rows,)).

    The line is the largest amplitude within ±max(2 bins, 1 %) of the target, the floor the
    median of the amplitudes from 0.5× to 1.5× the target without the line's bins (every row
    and target in one compiled loop: :func:`prsm_health.signals.kernels.line_floors`)."""
    df = freq[1] - freq[0]
    valid = np.isfinite(targets) & (targets > 0) & (targets < limits[:, None])
    target = np.where(valid, targets, 1.0)
    half = np.maximum(2 * df, 0.01 * target)
    # index ranges on the sorted frequencies: [a, b) near the line, [c, d) the surroundings
    a = np.searchsorted(freq, target - half, side="left")
    b = np.searchsorted(freq, target + half, side="right")
    c = np.searchsorted(freq, 0.5 * target, side="left")
    d = np.searchsorted(freq, 1.5 * target, side="right")
    a, b, c, d = (np.where(valid, k, 0) for k in (a, b, c, d))  # empty ranges where not valid
    lines = np.full(targets.shape, np.nan)
    floor = np.full(targets.shape, np.nan)
    line_floors(np.ascontiguousarray(amp, float), a, b, c, d, lines, floor)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(floor > 0, lines / floor, np.nan)
    return lines, ratio


def defect_lines(
    x: np.ndarray,
    rate: float,
    frequencies: dict[str, float],
    band: tuple[float, float] | None = None,
    harmonics: int = HARMONICS,
) -> dict:
    """Envelope lines at each defect frequency.

    Parameters
    ----------
    x : ndarray
    rate : float [Hz]
    frequencies : dict name → frequency [Hz]
        E.g. :func:`prsm_health.physics.kinematics.defect_frequencies`.
    band : (low, high) [Hz] or None
        None: the kurtogram's band above 3× the highest defect frequency (its third harmonic).
    harmonics : int

    Returns
    -------
    dict
        ``band``, ``sk``, ``impulsive`` (None when the band was given) and ``lines``: name →
        {``amplitude``, ``ratio`` (at the fundamental), ``ratio_sum`` (sum of the ratios of
        the first ``harmonics`` harmonics that fit)}.

    Raises
    ------
    PRSMHealthError
        No kurtogram band fits (``band`` None).
    """
    x = _check(x, rate)
    result = defect_lines_batch(
        x[None], rate, [frequencies], None if band is None else [band], harmonics
    )[0]
    if isinstance(result, PRSMHealthError):
        raise result
    return result


def defect_lines_batch(
    x: np.ndarray,
    rate: float,
    frequencies: list[dict[str, float]],
    bands: list[tuple[float, float]] | None = None,
    harmonics: int = HARMONICS,
) -> list:
    """:func:`defect_lines` of each row of ``x`` (rows, n) with its defect frequencies (and
    band): the kurtograms, envelopes and line ratios of all rows computed together. A row
    where no kurtogram band fits gets the :class:`PRSMHealthError` instead of a result."""
    results: list = [None] * len(x)
    if bands is None:
        lows = []
        for row_frequencies in frequencies:
            finite = [f for f in row_frequencies.values() if math.isfinite(f) and f > 0]
            lows.append(max(3.0 * max(finite, default=0.0), 0.02 * rate))
        found = _best_bands(spectral_kurtosis(x, rate), rate, np.array(lows, float), x.shape[-1])
        bands = []
        for i, best in enumerate(found):
            if isinstance(best, PRSMHealthError):
                results[i] = best
                bands.append(None)
                continue
            results[i] = {"band": best["band"], "sk": best["sk"], "impulsive": best["impulsive"]}
            bands.append(best["band"])
    else:
        results = [{"band": tuple(band), "sk": None, "impulsive": None} for band in bands]
    rows = [i for i, band in enumerate(bands) if band is not None]
    if not rows:
        return results
    freq, amp = envelope_amplitude_spectra(x[rows], rate, [bands[i] for i in rows])
    # every harmonic of every defect of a row: targets (rows, defects × harmonics)
    names = [list(frequencies[i]) for i in rows]
    width = max(len(n) for n in names)
    f0 = np.full((len(rows), width), np.nan)
    for r, i in enumerate(rows):
        f0[r, : len(names[r])] = list(frequencies[i].values())
    targets = f0[:, :, None] * np.arange(1, harmonics + 1)
    limits = np.array(
        [0.5 * (bands[i][1] - bands[i][0]) for i in rows]
    )  # modulation a band of width B carries
    line, ratio = lines_and_ratios(freq, amp, targets.reshape(len(rows), -1), limits)
    line = line.reshape(targets.shape)
    ratio = ratio.reshape(targets.shape)
    fits = np.isfinite(ratio)
    # the sum of the harmonics' ratios that fit, harmonic by harmonic as np.sum adds them
    ratio_sum = np.where(fits.any(axis=-1), np.where(fits, ratio, 0.0).sum(axis=-1), np.nan)
    for r, i in enumerate(rows):
        results[i]["lines"] = {
            name: {
                "amplitude": float(line[r, k, 0]),
                "ratio": float(ratio[r, k, 0]),
                "ratio_sum": float(ratio_sum[r, k]),
            }
            for k, name in enumerate(names[r])
        }
    return results


#: Most points of each spectrum :func:`window_spectra` returns (a plot a screen wide shows
#: fewer).
SPECTRUM_POINTS = 1024


def window_spectra(
    x: np.ndarray,
    rate: float,
    design: PRSMDesign | None = None,
    screw_speed: float | None = None,
    max_points: int = SPECTRUM_POINTS,
) -> dict:
    """What a person looks at in one window of nut acceleration: its amplitude spectrum, its
    envelope spectrum in the band the indicators use, and the defect frequencies to read them
    at — bounded in size, for a dashboard or a report.

    * **Amplitude spectrum**: :func:`prsm_health.signals.spectra.amplitude_spectrum` (Hann, coherent
      gain corrected) without the DC bin, reduced to at most ``max_points`` points on
      log-spaced frequency bins, each bin keeping its largest amplitude at that amplitude's
      frequency (a peak keeps its height and place; below the FFT resolution a bin holds one
      FFT bin, so nothing is averaged away).
    * **Envelope spectrum**: :func:`envelope_amplitude_spectrum` in the band :func:`defect_lines`
      chooses (the kurtogram above 3× the highest defect frequency: the band of the
      ``*_sk_band_centre`` indicator), up to the modulation that band carries (half its width:
      above, lines are meaningless), reduced the same way on linear bins.
    * **Defect frequencies** at ``screw_speed``: :func:`prsm_health.physics.kinematics.defect_frequencies`
      and the gear mesh frequency (:func:`~prsm_health.physics.kinematics.characteristic_frequencies`),
      with :func:`defect_lines`' amplitude and line-to-floor ratio at each.

    Parameters
    ----------
    x : ndarray
        One window of a vibration channel (the nut axial acceleration) [m/s²].
    rate : float [Hz]
    design : PRSMDesign or None
        None (a rig that is not a PRSM): no defect frequencies, the band above 2 % of the rate.
    screw_speed : float or None [rad/s]
        The window's mean screw speed; None or 0: no defect frequencies.
    max_points : int
        Most points per spectrum (≥ 16).

    Returns
    -------
    dict
        ``sample_rate`` [Hz], ``samples``, ``screw_speed`` [rad/s] or None;
        ``spectrum``: ``frequency`` [Hz], ``amplitude`` [unit of x]; ``envelope``:
        ``frequency``, ``amplitude``, ``band`` (low, high) [Hz], ``sk``, ``impulsive``,
        ``modulation_limit`` [Hz] — or None with ``envelope_note`` saying why (no band fits a
        short window at a low rate); ``frequencies``: name → [Hz] (the defect locations of
        :func:`~prsm_health.physics.kinematics.defect_frequencies`, then ``gear_mesh`` for a standard
        PRSM); ``lines``: defect name → ``amplitude``, ``ratio``, ``ratio_sum``. Plain
        floats and lists (JSON-ready; a NaN ratio stays NaN).
    """
    x = _check(x, rate)
    if not (isinstance(max_points, int) and max_points >= 16):
        raise PRSMHealthError(f"max_points = {max_points!r} must be an integer >= 16")
    speed = None
    if screw_speed is not None:
        if not math.isfinite(screw_speed):
            raise PRSMHealthError(f"screw_speed = {screw_speed!r} must be finite [rad/s]")
        speed = float(screw_speed)
    defects: dict[str, float] = {}
    mesh = None
    if design is not None and speed:
        defects = defect_frequencies(design, speed)
        mesh = characteristic_frequencies(design, speed).gear_mesh
    freq, amp = amplitude_spectrum(x, rate)
    spectrum = _peak_bins(freq[1:], amp[1:], max_points, log=True)
    envelope, note, lines = None, None, {}
    try:
        found = defect_lines(x, rate, defects)
    except PRSMHealthError as exc:  # no kurtogram band fits (short window, low rate)
        note = str(exc)
    else:
        band = found["band"]
        limit = 0.5 * (band[1] - band[0])
        f_env, a_env = envelope_amplitude_spectrum(x, rate, band)
        keep = (f_env > 0) & (f_env <= limit)
        envelope = {
            **_peak_bins(f_env[keep], a_env[keep], max_points, log=False),
            "band": [float(band[0]), float(band[1])],
            "sk": float(found["sk"]),
            "impulsive": bool(found["impulsive"]),
            "modulation_limit": float(limit),
        }
        lines = {
            name: {key: float(value) for key, value in line.items()}
            for name, line in found["lines"].items()
        }
    frequencies = {name: float(f) for name, f in defects.items()}
    if mesh is not None:
        frequencies["gear_mesh"] = float(mesh)
    out = {
        "sample_rate": float(rate),
        "samples": int(len(x)),
        "screw_speed": speed,
        "spectrum": spectrum,
        "envelope": envelope,
        "frequencies": frequencies,
        "lines": lines,
    }
    if note is not None:
        out["envelope_note"] = note
    return out


def _peak_bins(freq: np.ndarray, amp: np.ndarray, max_points: int, *, log: bool) -> dict:
    """At most ``max_points`` (frequency, amplitude) pairs: the spectrum cut into that many
    equal bins of frequency (of log frequency with ``log``), each represented by its largest
    amplitude at that amplitude's frequency; empty bins dropped."""
    if len(freq) > max_points:
        if log:
            edges = np.geomspace(freq[0], freq[-1], max_points + 1)
        else:
            edges = np.linspace(freq[0], freq[-1], max_points + 1)
        group = np.clip(np.searchsorted(edges, freq, side="right") - 1, 0, max_points - 1)
        # frequencies ascend, so each bin's points are one run: its maximum by reduceat, and
        # the first point of the run that reaches it
        starts = np.flatnonzero(np.r_[True, group[1:] != group[:-1]])
        peak = np.repeat(np.maximum.reduceat(amp, starts), np.diff(np.r_[starts, len(amp)]))
        hits = np.flatnonzero(amp == peak)
        keep = hits[np.r_[True, group[hits[1:]] != group[hits[:-1]]]]
        freq, amp = freq[keep], amp[keep]
    return {"frequency": freq.tolist(), "amplitude": amp.tolist()}
