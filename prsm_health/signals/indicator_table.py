"""The indicators there are: every indicator's name and unit (:data:`FEATURES`), their groups
(:data:`GROUPS`) and what each group needs of a recording — channels and sample rate
(:data:`GROUP_CHANNELS`) — declared once, for the extractor (:mod:`.features`), the datasets
(which groups they can use) and the diagnosis (which groups it computed, and why not).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from prsm_health.core.channels import CHANNEL_NAMES, VIBRATION

from .channel_statistics import CHANNEL_STATISTICS
from .gear_indicators import GEAR_INDICATORS
from .generic_indicators import GENERIC, NEEDS_ANY
from .reset_comb import REFERENCE_PASSAGE_RATE, RESET_COMB, RESOLVED_HARMONICS

SHORT = {
    "nut_axial_accel": "ax",
    "nut_tangential_accel": "tan",
    "nut_radial_x_accel": "rx",
    "nut_radial_y_accel": "ry",
}
BANDS = ((50.0, 300.0), (300.0, 1000.0), (1000.0, 3000.0), (3000.0, 10000.0))
MESH_CHANNELS = ("nut_tangential_accel", "nut_radial_x_accel")
#: Channels averaged synchronously (TSA) and the periods averaged over: a carrier revolution
#: (the ring gear meshes z_ring times in it) and a roller spin relative to the carrier (its gear
#: meshes z_roller times) — both non-integer numbers of screw turns (docs/gear-indicators.md).
TSA_CHANNELS = ("nut_axial_accel", "nut_tangential_accel")
TSA_PERIODS = ("carrier", "roller")
TSA_INDICATORS = tuple(n for n in GEAR_INDICATORS if n != "periods")
#: Channels whose envelope is read at the defect frequencies (docs/envelope-analysis.md), and the
#: defect locations (prsm_health.physics.kinematics.defect_frequencies).
ENVELOPE_CHANNELS = ("nut_axial_accel", "nut_tangential_accel")
DEFECTS = (
    "screw_flank",
    "nut_flank",
    "roller_flank",
    "ring_gear_tooth",
    "roller_gear_tooth",
    "carrier",
)
ORDER_TRACKING_SPREAD = 0.05
#: Share of the sample rate up to which a spectral line or mode is searched: below the
#: anti-alias filter's roll-off (a logger's decimation passes 0.4–0.45 × its rate).
SEARCH_SHARE = 0.45
#: Where the nut's dominant axial mode is searched [Hz]: paper 01's axial mode of a healthy nut
#: lies inside it at the paper01 preset's loads; the other presets' lie above it at service
#: loads (axial_baseline_frequency: paper02 1.8–3.8, paper03 3.0–6.2, paper04 2.7–5.2 kHz from
#: 100 N to 20 kN), where the search finds the strongest line below 2 kHz instead.
AXIAL_SEARCH = (100.0, 2000.0)
#: Frequency of the nut's bounces across a reversal that the torque rattle counts [Hz]: about
#: 200 Hz in the simulated reversals (measured 2026-12-02 on the import round trip's rig).
RATTLE_BOUNCE = 200.0


def _feature_table() -> dict[str, str]:
    units = {}
    for s in SHORT.values():
        units[f"{s}_rms"] = "m/s²"
        units[f"{s}_peak"] = "m/s²"
        units[f"{s}_crest"] = "-"
        units[f"{s}_kurtosis"] = "-"
        units[f"{s}_skewness"] = "-"
        for lo, hi in BANDS:
            units[f"{s}_band_{int(lo)}_{int(hi)}"] = "(m/s²)²"
    for ch in MESH_CHANNELS:
        s = SHORT[ch]
        for k in (1, 2, 3):
            units[f"{s}_mesh_h{k}"] = "m/s²"
        units[f"{s}_mesh_sidebands"] = "m/s²"
    for ch in ENVELOPE_CHANNELS:
        s = SHORT[ch]
        units[f"{s}_sk_max"] = "-"
        units[f"{s}_sk_band_centre"] = "Hz"
        for defect in DEFECTS:
            units[f"{s}_env_{defect}"] = "m/s²"
            units[f"{s}_env_{defect}_ratio"] = "-"
            units[f"{s}_env_{defect}_ratio_sum"] = "-"
    for ch in TSA_CHANNELS:
        for period in TSA_PERIODS:
            for name in TSA_INDICATORS:
                unit = "m/s²" if name in ("tsa_rms", "sideband_index") else "-"
                units[f"{SHORT[ch]}_tsa_{period}_{name}"] = unit
    units.update(RESET_COMB)  # the recirculating PRSM's resets (signals.reset_comb)
    units.update(
        {
            "mesh_frequency": "Hz",
            "axial_dominant_frequency": "Hz",
            "axial_baseline_frequency": "Hz",
            "axial_frequency_shift": "Hz",
            "axial_frequency_shift_relative": "-",
            "axial_dominant_amplitude": "m/s²",
            "axial_contact_frequency": "Hz",
            "axial_contact_frequency_shift": "Hz",
            "drive_torque_mean": "N·m",
            "drive_torque_ripple": "N·m",
            "efficiency": "-",
            "lost_motion": "m",
            "torque_rattle_rate": "1/s",
            "speed_mean": "rad/s",
            "load_mean": "N",
            "load_range": "N",
            "reversal": "-",
            "housing_temperature_mean": "K",
        }
    )
    units.update(GENERIC)  # any recording's (signals.generic_indicators)
    units.update(CHANNEL_STATISTICS)  # the plain baseline's inputs, not a model's indicators
    return units


#: Indicator name → unit, in the column order of :func:`extract_features`: measured channels only.
FEATURES: dict[str, str] = _feature_table()

#: Truth signals :func:`extract_features` reads when asked (``truth=(name, …)``), and the
#: indicators each adds (after :data:`FEATURES`). ``carrier_speed`` adds none: it locates the
#: mesh lines from the true carrier speed instead of the measured screw speed.
TRUTH_FEATURES: dict[str, dict[str, str]] = {
    "friction_torque": {"friction_torque_mean": "N·m", "friction_torque_ripple": "N·m"},
    "carrier_speed": {},
}

#: Indicator groups for importance and ablation studies.
GROUPS = {
    "mesh": [k for k in FEATURES if "_mesh_" in k] + ["mesh_frequency"],
    "axial_frequency": [k for k in FEATURES if k.startswith("axial_") and k not in GENERIC],
    "classic": [
        k
        for k in FEATURES
        if k.split("_")[0] in SHORT.values()
        and not any(tag in k for tag in ("_mesh_", "_tsa_", "_env_", "_sk_"))
    ],
    "gear": [k for k in FEATURES if "_tsa_" in k],
    "reset_comb": list(RESET_COMB),
    "envelope": [k for k in FEATURES if "_env_" in k or "_sk_" in k],
    "torque": [
        k for k in FEATURES if "torque" in k and k not in GENERIC and k not in CHANNEL_STATISTICS
    ]
    + ["efficiency"],
    "lost_motion": ["lost_motion"],
    "torque_rattle": ["torque_rattle_rate"],
    "operating": ["speed_mean", "load_mean", "load_range", "reversal", "housing_temperature_mean"],
    "generic": list(GENERIC),
    "statistics": list(CHANNEL_STATISTICS),
}
#: Groups that are not condition indicators: the indicator models leave them out (the plain
#: baseline reads ``statistics`` alone).
NOT_INDICATORS = ("statistics",)


@dataclass(frozen=True)
class Needs:
    """What an indicator group reads: the measured channels (all of ``all_of`` and, when
    ``any_of`` is not empty, at least one of it) and the sample rate ``min_rate`` [Hz] below
    which what it measures is out of the recording's band (its indicators are then NaN)."""

    all_of: tuple[str, ...] = ()
    any_of: tuple[str, ...] = ()
    min_rate: float = 0.0

    def missing(self, channels) -> list[str]:
        """What a set of channels lacks for this group (``a or b`` for an any-of set)."""
        out = [c for c in self.all_of if c not in channels]
        if self.any_of and not any(c in channels for c in self.any_of):
            out.append(" or ".join(self.any_of))
        return out

    def too_slow(self, rate: float | None) -> str:
        """Why a sample rate [Hz] is too low for this group ("" when it is not, or unknown)."""
        if rate is None or not rate < self.min_rate:
            return ""
        return f"sample rate {rate:g} Hz below the {self.min_rate:.0f} Hz it needs"


#: The channels and rate each indicator group needs: declared once. A window without them has
#: the group's indicators NaN; a dataset lists the groups it can use
#: (:func:`usable_groups`); a diagnosis names the groups it could not compute and why.
GROUP_CHANNELS: dict[str, Needs] = {
    "mesh": Needs(("screw_speed",), MESH_CHANNELS),
    # the search band's top within the recording's band
    "axial_frequency": Needs(("nut_axial_accel",), min_rate=AXIAL_SEARCH[1] / SEARCH_SHARE),
    "classic": Needs(any_of=VIBRATION),
    "gear": Needs(("screw_angle",), TSA_CHANNELS),
    # the passage period's first RESOLVED_HARMONICS harmonics within the recording's band —
    # the entry and the landing (0.19 of the period apart for paper03) resolved — at a passage
    # rate of 100 Hz (paper03 at paper 03's 40π rad/s: 97 Hz): 4.4 kHz; each window checks
    # its own rate. The pulses' ringing (the nut's axial mode, ≈ 6 kHz for paper03) needs
    # more to be kept whole: the 20 kHz profiles keep it.
    "reset_comb": Needs(
        ("nut_axial_accel", "screw_angle"),
        min_rate=RESOLVED_HARMONICS * REFERENCE_PASSAGE_RATE / SEARCH_SHARE,
    ),
    "envelope": Needs(("screw_speed",), ENVELOPE_CHANNELS),
    "torque": Needs(("drive_torque",)),
    "lost_motion": Needs(("nut_position", "screw_angle")),
    # the bounces it counts within the recording's band
    "torque_rattle": Needs(("drive_torque",), min_rate=RATTLE_BOUNCE / SEARCH_SHARE),
    "operating": Needs(any_of=("screw_speed", "axial_load", "drive_torque", "housing_temperature")),
    "generic": Needs(any_of=NEEDS_ANY),
    "statistics": Needs(any_of=CHANNEL_NAMES),
}


def usable_groups(channels, rate: float | None) -> dict[str, str]:
    """Each indicator group → ``"usable"`` for recordings of these measured channels at this
    sample rate [Hz], or why not (the channels it lacks, the rate it needs): what a dataset
    can train on, before any indicator is computed (a usable group may still be NaN in a
    window that does not support it, e.g. lost motion without a reversal)."""
    out = {}
    for group, needs in GROUP_CHANNELS.items():
        if missing := needs.missing(channels):
            out[group] = "missing channel(s) " + ", ".join(missing)
        else:
            out[group] = needs.too_slow(rate) or "usable"
    return out


def indicator_groups(row: dict, channels, rate: float | None = None) -> dict[str, str]:
    """Each indicator group of a window's indicators → ``"computed"`` (at least one finite
    value), or why not: the channels it lacks, the sample rate it needs, or that the window
    does not support it."""
    out = {}
    for group, members in GROUPS.items():
        values = [row.get(name) for name in members]
        needs = GROUP_CHANNELS[group]
        if any(v is not None and math.isfinite(v) for v in values):
            out[group] = "computed"
        elif missing := needs.missing(channels):
            out[group] = "missing channel(s) " + ", ".join(missing)
        elif slow := needs.too_slow(rate):
            out[group] = slow
        else:
            out[group] = "not supported by this window (e.g. no reversal, too slow or too short)"
    return out
