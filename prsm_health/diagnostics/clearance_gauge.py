"""The thread clearance *measured* from a health check's reversals by the actuator's own physics,
with an error budget: the health check read as a measuring instrument.

A slow reversal under ±F crosses the threads' play, 4·b (b the mean half-clearance: the screw
and nut engagements each have a dead band of 2b, in series), plus every elastic deflection and
play between the angle and the position sensor
(:mod:`prsm_health.physics.lost_motion_chain`). The check's reversals give the lost motion L_i
at loads F_i (:class:`~prsm_health.signals.check_indicators.ReversalStep`, fitted over the
settled samples, where the nut rests on its flanks). The gauge reads

    L_i = L_0 + k·E(F_i),        L_0 = 4·b + C,

E(F) the chain's elastic lost motion at F (thread contacts with their load sharing, gear and
coupling torsion, thrust bearing), k a unit's factor on it (its real stiffnesses against the
nominal ones), C the constant part (gearhead backlash, thrust-bearing play, the sensors' lag).

- **Two loads** (the built-in check's ±25 % and ±10 % C_a): k = (L_1 − L_2)/(E_1 − E_2),
  L_0 = L_1 − k·E_1 — the unit's stiffnesses drop out (measured, one factor at a time:
  bearing 1.0–2.0e8 N/m, coupling 1–3e3 N·m/rad, friction ×1.5 and a degraded lubricant move
  the reading by ≤ 0.4 µm of b, against up to 3 µm from one reversal through the nominal
  chain). The torsion term takes the measured drive torque (:meth:`Gauge.chain`), so the
  friction the load does not carry is in the chain as it is in the unit.
- **One load**: k = 1, the nominal chain; the stiffness term of the budget says how far that
  can be off.

b = (L_0 − C)/4. C is the actuator's: from its drive train and sensors (**nominal**: the
datasheets' backlash, a thrust bearing's play, the sensors' filter delays), or — better —
fixed at **commissioning** (:class:`Commissioning`): where a unit's as-built clearance b_c is
known (measured at assembly), its first checks fix its own stiffness factor k_c and C, and a
later check reads its heavier reversal through that chain, b = (L_1 − k_c·E_1 − C)/4 (the
extrapolation's lighter reversal weighs the rollers with the tighter gaps more, so reading
through the unit's own k_c keeps less of the uneven-gap error: 0.47 against 0.65 µm on the
study's fresh units). Without it the budget carries the unknown plays.

**Temperature.** The housing temperature changes the oil's viscosity, so the friction torque
and the torsion it winds up; that term is elastic (∝ the load) and the two-load extrapolation
removes it, the measured torque carrying the rest (10 °C against 70 °C: ≤ 0.05 µm of b). With
one reversal it is part of the stiffness term. No thermal-expansion correction is made: the
simulator's thread geometry does not expand (docs/diagnostics.md), and on hardware it is a
constant of the unit over a check that commissioning at the service temperature absorbs.

**Budget and interval.** Each term's standard deviation in b (:attr:`GaugeReading.budget`):
the reversals' repeatability through the extrapolation's weights, the stiffness shape (the
chain's form against a unit's), uneven gaps between rollers (the load-weighted gap the reversal
reads is below the plain mean when gaps differ: one-sided, grows with b), the constant offsets
when not commissioned, and the slope. Their root sum square, times a conformal factor
(:data:`CONFORMAL_SCALE`, :data:`COMMISSIONED_SCALE`: the split-conformal 90 % quantile of
|error|/sd on simulated units whose build is drawn from the documented ranges,
``tools/studies/clearance_gauge.py``), is the 90 % interval's half-width.

References
----------
- ISO 230-2:2014 §3.2 — the reversal value (the lost motion between the two directions).
- Paper 01 (docs/references.md) §1.1–1.3 — the backlash function f(δ, b), 2b per engagement.
- Paper 04 — the axial stiffness of the engaged threads (the chain's contact term).
- A. N. Angelopoulos, S. Bates, "A gentle introduction to conformal prediction and
  distribution-free uncertainty quantification", arXiv:2107.07511 (2021), §2 — the split
  conformal quantile ⌈(n+1)(1−α)⌉/n of normalised scores.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.core.errors import ParameterError, require, require_range
from prsm_health.physics.kinematics import speed_ratios
from prsm_health.physics.lost_motion_chain import (
    CLEARANCE_SLOPE,
    DELAYED_CHANNELS,
    compliance_chain,
)

#: Two reversals are extrapolated to zero load when the heavier's load is at least this many
#: times the lighter's: closer, the extrapolation's weights blow the noise up (at 1.5 the
#: lighter reversal's noise enters ×3).
EXTRAPOLATION_RATIO = 1.5
#: The stiffness factor k two reversals may give [-]: beyond it the reversals disagree with
#: any plausible actuator (the documented ranges give 0.9–1.4), and the reading falls back to
#: the heavier reversal with the nominal chain.
STIFFNESS_FACTOR_RANGE = (0.5, 2.0)
#: Standard deviation of k across the documented builds (bearing stiffness 1.0–2.0e8 N/m,
#: coupling 1–3e3 N·m/rad, lubricant, friction: k 0.93–1.34, ``tools/studies/clearance_gauge.py
#: --factors``): the stiffness term of a one-reversal reading.
STIFFNESS_FACTOR_SD = 0.12
#: Standard deviation [m of lost motion] of one reversal's settled step between repeat checks
#: of one unit from its sensors (the flight-ema LVDT and resolver): measured 0.22–0.27 µm at
#: 2 µm RMS of LVDT noise, 0.33–0.42 µm at 10 µm (the built-in check's two reversals, six
#: sensor seeds: ``tools/studies/clearance_gauge.py --repeatability``); the interval's
#: conformal factors were calibrated with this value.
REVERSAL_REPEATABILITY = 0.3e-6
#: Standard deviation [m of b] of the two-load extrapolation's stiffness-shape error across the
#: documented builds (the chain's form against a unit's): the one-factor runs spread over
#: −0.29…+0.17 µm around the default unit for bearing 1–2e8 N/m and coupling 1–3e3 N·m/rad
#: (``tools/studies/clearance_gauge.py --factors``).
SHAPE_SD = 0.15e-6
#: Standard deviation of the uneven-gap term per metre of b [-]: the reading falls below the
#: mean gap by ≈ 7 % of b at a wear spread of 0.3 (b = 20 µm, the one-factor runs); a wear
#: spread drawn from [0, 0.3] (the error growing about as its square) gives about this share as
#: its standard deviation.
UNEVEN_GAP_SHARE = 0.025
#: The same through the unit's own chain (commissioned: the heaviest reversal with k_c), per
#: metre of clearance gained since commissioning [-]: the heavier reversal reads nearer the
#: mean gap — measured on the study's calibration units, the error per metre gained fell by
#: 0.86·s² (s the wear spread: −7.7 % at 0.3), so 0.03 is about its spread over s in [0, 0.3].
COMMISSIONED_GAP_SHARE = 0.03
#: Relative standard deviation of the slope 4 [-]: the settled steps read 4.03–4.09 per metre
#: of b (the one-factor runs; +2.2 % of the clearance gained on the study's evenly worn
#: calibration units).
SLOPE_SD = 0.03
#: Conformal factors on the budget's standard deviation for a 90 % interval, not commissioned
#: and commissioned (where a model's check part has none of its own recipe): measured by
#: ``tools/studies/clearance_gauge.py`` on 30 flight-ema calibration units (90 service checks)
#: drawn from the documented ranges; on 30 fresh units they covered 0.87 and 0.92
#: (models/MODEL_CARD.md): the budget's spread is about the errors' (a normal's 90 % factor is
#: 1.645).
CONFORMAL_SCALE = 1.65
COMMISSIONED_SCALE = 1.60


#: The reversals' frequency [Hz] the sensors' delays are taken at: the built-in check's
#: 0.25 s period (well below the filters' corners the delay barely depends on it).
NOMINAL_REVERSAL_FREQUENCY = 4.0
#: The sensors' filters are evaluated at this multiple of the sample rate (they stand for
#: analog filters; their delay is the same at any rate well above the corner).
DELAY_RATE_FACTOR = 10
#: The thrust bearing's half-play a unit may have [m]: 0 (preloaded pair) to 5 µm (an
#: unpreloaded angular-contact pair after running-in; engineering estimate, the range the
#: reading's factor table is measured over).
BEARING_HALF_PLAY = (0.0, 5e-6)
#: The gearhead's backlash a unit may have, as multiples of the datasheet's [-]: a new
#: gearhead within its catalogue value (Yaskawa SGMMV: ≤ 3 arcmin) up to twice it (worn).
BACKLASH_SHARE = (0.0, 2.0)
#: The sensors' lag a unit may have, as multiples of the datasheets' [-]: the filter corners'
#: tolerance (±20 %).
SENSOR_LAG_SHARE = (0.8, 1.2)


def offset_ranges(design: PRSMDesign, drive_train: DriveTrain) -> dict[str, OffsetRange]:
    """The constant terms' ranges [m of lost motion] as deviations from the nominal chain's
    (``Gauge.chain(...).constant``): the thrust bearing's play (:data:`BEARING_HALF_PLAY`)
    and the gearhead's backlash (:data:`BACKLASH_SHARE`). The sensors' lag is speed-dependent
    and enters by :data:`SENSOR_LAG_SHARE` at reading time."""
    lead = speed_ratios(design).nut
    play_nominal = 2.0 * drive_train.thrust_bearing_play
    out = {
        "thrust-bearing play": OffsetRange(
            2.0 * BEARING_HALF_PLAY[0] - play_nominal, 2.0 * BEARING_HALF_PLAY[1] - play_nominal
        )
    }
    if drive_train.geared and drive_train.coupled:
        backlash = 2.0 * drive_train.gear_backlash * lead
        out["gearhead backlash"] = OffsetRange(
            (BACKLASH_SHARE[0] - 1.0) * backlash, (BACKLASH_SHARE[1] - 1.0) * backlash
        )
    return out


#: The gauge's quantities a check diagnosis lists among its indicators (name → the
#: :class:`GaugeReading` attribute): an asset's history keeps them, and its commissioning reads
#: them back (:meth:`Commissioning.from_indicators`).
GAUGE_INDICATORS = {
    "check_zero_load_lost_motion": "zero_load_lost_motion",
    "check_stiffness_factor": "stiffness_factor",
    "check_elastic_lost_motion": "elastic_lost_motion",
}


@dataclass(frozen=True)
class OffsetRange:
    """A constant term of the lost motion the gauge cannot see, as the range a unit's value
    lies in [m of lost motion]: nominal = its middle, budget = a uniform's sd over it."""

    low: float
    high: float

    @property
    def nominal(self) -> float:
        return 0.5 * (self.low + self.high)

    @property
    def sd(self) -> float:
        return (self.high - self.low) / math.sqrt(12.0)


@dataclass(frozen=True)
class Commissioning:
    """A unit's own chain fixed at commissioning, where its as-built clearance b_c is known:
    its stiffness factor k_c (the median of its first checks' two-load k; 1 where they had one
    reversal) and its constant lost motion C = median(L_1 − k_c·E_1) − 4·b_c [m] over those
    checks (L_1, E_1: the heaviest reversal's lost motion and the nominal chain's elastic part
    there). A later check reads b = (L_1 − k_c·E_1 − C)/4.

    Attributes
    ----------
    offset : float [m]
        C.
    clearance : float [m]
        b_c.
    checks : int
    stiffness_factor : float
        k_c.
    """

    offset: float
    clearance: float
    checks: int
    stiffness_factor: float = 1.0

    def __post_init__(self):
        require(math.isfinite(self.offset), "commissioning.offset", self.offset, "finite [m]")
        require_range("commissioning.clearance", self.clearance, -50e-6, 1e-3, unit="m")
        require(self.checks >= 1, "commissioning.checks", self.checks, "must be ≥ 1")
        low, high = STIFFNESS_FACTOR_RANGE
        require_range("commissioning.stiffness_factor", self.stiffness_factor, low, high)

    @classmethod
    def from_readings(cls, readings: Sequence, clearance: float) -> Commissioning:
        """From the unit's first checks — each ``(zero_load_lost_motion, stiffness_factor,
        elastic_lost_motion)`` [m, -, m] of a :class:`GaugeReading` (the factor None with one
        reversal) — and its as-built clearance b_c [m]; readings with a NaN left out (none
        left: refused)."""
        usable = [
            (float(z), 1.0 if k is None else float(k), float(e))
            for z, k, e in readings
            if z is not None
            and e is not None
            and math.isfinite(z)
            and math.isfinite(e)
            and (k is None or math.isfinite(k))
        ]
        if not usable:
            raise ParameterError(
                "commissioning", "no zero-load lost motion", "needs ≥ 1 check with its reversals"
            )
        own = float(np.median([k for _, k, _ in usable]))
        # L_1 − k_c·E_1 = L_0 + (k − k_c)·E_1 of each check
        lost = [z + (k - own) * e for z, k, e in usable]
        offset = float(np.median(lost)) - CLEARANCE_SLOPE * clearance
        return cls(offset, float(clearance), len(usable), own)

    @classmethod
    def from_indicators(cls, rows: Sequence[Mapping], clearance: float) -> Commissioning:
        """:meth:`from_readings` of the first checks' indicators (:data:`GAUGE_INDICATORS`)."""
        names = list(GAUGE_INDICATORS)
        return cls.from_readings([tuple(row.get(n) for n in names) for row in rows], clearance)


@dataclass(frozen=True)
class Gauge:
    """What the gauge knows of the actuator: its design, drive train and sensors.

    Attributes
    ----------
    design : PRSMDesign
    drive_train : DriveTrain
        Nominal figures (datasheets); its backlash and bearing play are the constant offset's
        nominal values.
    sensor_delays : mapping or None
        ``{"nut_position": τ_x, "screw_angle": τ_θ}`` [s], the sensors' group delays (None:
        no sensor term; :func:`~prsm_health.physics.lost_motion_chain.compliance_chain`).
    offsets : mapping of name → OffsetRange
        The constant terms' ranges [m of lost motion] (their middles are the nominal C).
    conformal_scale, commissioned_scale : float
        The interval's factor on the budget's sd, not commissioned and commissioned
        (:data:`CONFORMAL_SCALE`, :data:`COMMISSIONED_SCALE`).
    """

    design: PRSMDesign
    drive_train: DriveTrain = field(default_factory=DriveTrain)
    sensor_delays: Mapping[str, float] | None = None
    offsets: Mapping[str, OffsetRange] = field(default_factory=dict)
    conformal_scale: float = CONFORMAL_SCALE
    commissioned_scale: float = COMMISSIONED_SCALE

    @classmethod
    def nominal(
        cls,
        design: PRSMDesign,
        drive_train: DriveTrain | None = None,
        instrumentation=None,
        *,
        reversal_frequency: float = NOMINAL_REVERSAL_FREQUENCY,
        conformal_scale: float = CONFORMAL_SCALE,
        commissioned_scale: float = COMMISSIONED_SCALE,
    ) -> Gauge:
        """The gauge of an actuator from its datasheets: the drive train's figures (default:
        the flight EMA's), the sensors' filter delays of an instrumentation profile (name,
        file or :class:`~prsm_health.simulation.instrumentation.Instrumentation`; None: no
        sensor term) at the reversals' frequency [Hz], and the documented ranges of the
        constant terms (:func:`offset_ranges`)."""
        drive_train = DriveTrain() if drive_train is None else drive_train
        delays = None
        if instrumentation is not None:
            from prsm_health.simulation.instrumentation import load_instrumentation
            from prsm_health.simulation.sensors import channel_group_delay

            profile = load_instrumentation(instrumentation)
            rate = DELAY_RATE_FACTOR * profile.sample_rate
            delays = {
                c: channel_group_delay(profile, c, reversal_frequency, rate)
                for c in DELAYED_CHANNELS
                if getattr(profile, c, None) is not None
            }
        offsets = offset_ranges(design, drive_train)
        return cls(design, drive_train, delays, offsets, conformal_scale, commissioned_scale)

    def chain(self, reversal):
        """The compliance chain at a reversal: its load, speed and the load shares its step
        was read at, and the torsion from its measured drive torque where it has one
        (through the reduction: N·η_g of the motor's)."""
        dt = self.drive_train
        torque = None
        if math.isfinite(getattr(reversal, "drive_torque", math.nan)):
            torque = reversal.drive_torque * (
                dt.gear_ratio * dt.gear_efficiency if dt.geared else 1.0
            )
        return compliance_chain(
            self.design,
            dt,
            reversal.load,
            load_shares=reversal.load_shares,
            speed_amplitude=reversal.speed,
            sensor_delays=self.sensor_delays,
            screw_torque=torque,
        )

    def read(self, reversals, commissioning: Commissioning | None = None) -> GaugeReading | None:
        """The clearance from a check's reversals
        (:class:`~prsm_health.signals.check_indicators.ReversalStep`, any order); None without
        any. Commissioned with a stiffness factor, the heaviest reversal is read through the
        unit's own chain (module docstring); else the reversals extrapolate to zero load."""
        reversals = sorted(reversals, key=lambda r: -r.load)
        if not reversals:
            return None
        heavy, light = reversals[0], reversals[-1]
        chain_heavy = self.chain(heavy)
        constant, elastic_heavy = chain_heavy.constant, chain_heavy.elastic
        notes = []
        factor, weights, elastic_gap = None, (1.0,), elastic_heavy
        if len(reversals) > 1 and heavy.load >= EXTRAPOLATION_RATIO * light.load:
            elastic_light = self.chain(light).elastic
            elastic_gap = elastic_heavy - elastic_light
            k = (heavy.lost_motion - light.lost_motion) / elastic_gap
            low, high = STIFFNESS_FACTOR_RANGE
            if low <= k <= high:
                factor = k
                r = elastic_heavy / elastic_gap
                weights = (1.0 - r, r)  # L_0 = (1 − r)·L_1 + r·L_2
            else:
                notes.append(
                    f"the reversals at ±{heavy.load:.4g} N and ±{light.load:.4g} N give a "
                    f"stiffness {k:.2f}× the chain's, outside {low:g}–{high:g}: read from "
                    f'"{heavy.phase}" alone with the nominal chain'
                )
        elif len(reversals) > 1:
            notes.append(
                f"the reversals' loads (±{heavy.load:.4g} N, ±{light.load:.4g} N) are too close "
                f"to extrapolate (a ratio ≥ {EXTRAPOLATION_RATIO:g} is needed): read from "
                f'"{heavy.phase}" with the nominal chain'
            )
        used = (heavy,) if factor is None else (heavy, light)
        zero_load = heavy.lost_motion - (1.0 if factor is None else factor) * elastic_heavy
        slope = CLEARANCE_SLOPE
        budget = {}
        if commissioning is None:
            estimate = (
                zero_load - constant - sum(o.nominal for o in self.offsets.values())
            ) / slope
            budget["repeatability"] = (
                REVERSAL_REPEATABILITY * math.sqrt(sum(w * w for w in weights)) / slope
            )
            budget["stiffness"] = (
                SHAPE_SD if factor is not None else STIFFNESS_FACTOR_SD * elastic_heavy / slope
            )
            for name, offset in self.offsets.items():
                budget[name] = offset.sd / slope
            lag = OffsetRange(*(share * chain_heavy.sensor_lag for share in SENSOR_LAG_SHARE))
            budget["sensor lag"] = lag.sd / slope
            reference, gap_share = 0.0, UNEVEN_GAP_SHARE
        else:
            # the heaviest reversal through the unit's own chain: its stiffness factor, fixed at
            # commissioning, does not follow the uneven gaps the way the extrapolation does
            own = commissioning.stiffness_factor
            own_zero_load = heavy.lost_motion - own * elastic_heavy
            estimate = (own_zero_load - commissioning.offset) / slope
            budget["repeatability"] = REVERSAL_REPEATABILITY / slope
            # k_c from the commissioning checks' two reversals: their noise over the lever E_1 − E_2
            k_noise = REVERSAL_REPEATABILITY * math.sqrt(2.0) / abs(elastic_gap)
            budget["commissioning"] = math.hypot(
                k_noise * elastic_heavy / slope, budget["repeatability"]
            ) / math.sqrt(commissioning.checks)
            reference, gap_share = commissioning.clearance, COMMISSIONED_GAP_SHARE
        budget["uneven gaps"] = gap_share * max(estimate - reference, 0.0)
        budget["slope"] = SLOPE_SD * abs(estimate - reference)
        sd = math.sqrt(sum(v * v for v in budget.values()))
        half = (self.conformal_scale if commissioning is None else self.commissioned_scale) * sd
        return GaugeReading(
            estimate=estimate,
            lower=estimate - half,
            upper=estimate + half,
            zero_load_lost_motion=zero_load,
            stiffness_factor=factor,
            elastic_lost_motion=elastic_heavy,
            reversals=tuple((r.phase, r.load, r.lost_motion) for r in used),
            budget=budget,
            commissioned=commissioning is not None,
            notes=tuple(notes),
        )


@dataclass(frozen=True)
class GaugeReading:
    """One check's clearance by physics.

    Attributes
    ----------
    estimate, lower, upper : float [m]
        The mean half-clearance b and its 90 % interval.
    zero_load_lost_motion : float [m]
        L_0, the lost motion extrapolated to zero load (two reversals) or read through the
        nominal chain (one) — whether commissioned or not: what commissioning stores.
    stiffness_factor : float or None
        k of the two-load extrapolation (None: one reversal, the nominal chain).
    elastic_lost_motion : float [m]
        E_1, the nominal chain's elastic lost motion at the heaviest reversal.
    reversals : tuple of (phase, load [N], lost motion [m])
        The reversals read.
    budget : dict of term → sd [m of b]
    commissioned : bool
        Whether the constant offset is the unit's own (:class:`Commissioning`).
    notes : tuple of str
    """

    estimate: float
    lower: float
    upper: float
    zero_load_lost_motion: float
    stiffness_factor: float | None
    elastic_lost_motion: float
    reversals: tuple
    budget: dict
    commissioned: bool
    notes: tuple = ()

    @property
    def sd(self) -> float:
        """The budget's root sum square [m of b]."""
        return math.sqrt(sum(v * v for v in self.budget.values()))

    def indicators(self) -> dict[str, float | None]:
        """The reading as check indicators (:data:`GAUGE_INDICATORS`)."""
        return {name: getattr(self, attribute) for name, attribute in GAUGE_INDICATORS.items()}


def gauge_for(design: PRSMDesign | None, metadata: Mapping, check_part: Mapping | None = None):
    """The gauge of a model bundle's actuator (None without a design): the drive train and
    the instrumentation of the recipe it was trained on (``metadata["trained_on"]["recipe"]``;
    the flight EMA's drive train where it does not say), and the conformal factor its check
    part was calibrated with (else :data:`CONFORMAL_SCALE`)."""
    if design is None:
        return None
    from prsm_health.actuator.drive_train import load_drive_train

    recipe = (metadata.get("trained_on") or {}).get("recipe") or {}
    drive = recipe.get("drive_train")
    drive_train = load_drive_train(drive) if drive else DriveTrain()
    instrumentation = recipe.get("instrumentation") or metadata.get("instrumentation")
    calibration = (check_part or {}).get("gauge") or {}
    scales = {
        "conformal_scale": float(calibration.get("conformal_scale", CONFORMAL_SCALE)),
        "commissioned_scale": float(calibration.get("commissioned_scale", COMMISSIONED_SCALE)),
    }
    try:
        return Gauge.nominal(design, drive_train, instrumentation, **scales)
    except ParameterError:  # an instrumentation this package does not know: no sensor term
        return Gauge.nominal(design, drive_train, None, **scales)
