"""A recipe's sweep as written: the swept quantities and groups, the written forms of a value
and a range, group tables flattened to dotted keys, and the test split's draw
(:mod:`prsm_health.datasets.recipe` reads recipes with them)."""

from __future__ import annotations

import numpy as np

SWEEP_MODES = ("grid", "random", "lhs")
#: Swept quantities and their units (a range is [min, max]).
SWEPT = {
    "clearance": "m",
    "clearance_screw": "m",
    "clearance_nut": "m",
    "clearance_gear": "m",
    "speed": "rad/s",
    "load": "N, kN or a share of C_a / C_0a",
    "load_amplitude": "N, kN or a share of C_a / C_0a",
    "friction_scale": "-",
    "wear_spread": "-",
    "preload": "m",
    "lubricant_degradation": "-",
    "lubricant_starvation": "-",
    "temperature": "K",
    "severity": "-",
}
#: Groups whose scalar fields a sweep may also draw — domain randomisation of the operating
#: profile, simulation options (contact damping, restitution, manufacturing scatter), drive train
#: and sensors: ``[sweep.drive_train] coupling_stiffness = [1e3, 2e3]`` or the dotted key
#: ``"drive_train.coupling_stiffness"``; nested fields by more dots
#: (``options.variation.pitch_error``, ``instrumentation.nut_axial_accel.noise_density_ug``).
#: Units are the group's (docs/formats.md); the scenario validates every drawn value.
SWEPT_GROUPS = ("profile", "options", "drive_train", "instrumentation")
#: Swept keys that are forces: any form of :mod:`prsm_health.core.quantities`, resolved to
#: newtons against the recipe's design (:attr:`Recipe.resolved_sweep`).
FORCE_KEYS = ("load", "load_amplitude", "profile.load", "profile.load_amplitude")


def flat_sweep(sweep: dict) -> dict:
    """The sweep with group tables (``[sweep.drive_train]`` …) as dotted keys."""
    out = {}

    def walk(prefix: str, table: dict) -> None:
        for key, value in table.items():
            name = f"{prefix}.{key}"
            if isinstance(value, dict) and "uniform" not in value:
                walk(name, value)
            else:
                out[name] = value

    for key, value in sweep.items():
        if key in SWEPT_GROUPS and isinstance(value, dict):
            walk(key, value)
        else:
            out[key] = value
    return out


def swept_keys(sweep: dict) -> list[str]:
    """The swept quantities of a (flat) sweep: :data:`SWEPT` order, then group fields sorted."""
    grouped = sorted(k for k in sweep if k.split(".")[0] in SWEPT_GROUPS and "." in k)
    return [k for k in SWEPT if k in sweep] + grouped


def set_path(target: dict, path: list[str], value) -> None:
    for key in path[:-1]:
        target = target.setdefault(key, {})
    target[path[-1]] = value


def is_value(key: str, value) -> bool:
    """A number, or for a force (:data:`FORCE_KEYS`) any of its written forms: a string; it is
    parsed (with its own error) by ``Recipe._validate_forces``."""
    if isinstance(value, bool):
        return False
    return isinstance(value, (int, float)) or (key in FORCE_KEYS and isinstance(value, str))


def is_range(value, key: str = "") -> bool:
    """[min, max]; ordered when numbers (a force range is ordered once resolved)."""
    if not (isinstance(value, list) and len(value) == 2 and all(is_value(key, v) for v in value)):
        return False
    numbers = all(isinstance(v, (int, float)) for v in value)
    return not numbers or value[0] <= value[1]


def written_values(value) -> list:
    """The written values of a sweep entry (a list, or ``{uniform = [min, max]}``)."""
    if isinstance(value, dict):
        return list(value.get("uniform", []))
    return list(value) if isinstance(value, list) else [value]


def test_set(n: int, fraction: float, seed: int) -> set[int]:
    k = int(round(n * fraction))
    return set(np.random.default_rng([seed, 0x54455354]).permutation(n)[:k].tolist())
