"""Labelled datasets from recipes: sweeps, parallel generation, resumable Parquet (and MCAP) output.

A **recipe** (TOML, see datasets/*.toml and docs/formats.md) names a design, an instrumentation
profile, a run duration and sample rate, profile/option settings, a seed and a **sweep** over
clearance, speed,
load, friction scale and per-roller wear spread — as a grid, or as random or Latin-hypercube
samples over ranges — with repeats, a test split and the fault-class thresholds.

Generation is deterministic: run i always gets the same parameters and seed (derived from the
recipe seed and i), and runs are grouped into fixed batches, so the dataset is identical
whatever the worker count or scheduler. Each batch is written by its worker as one Parquet
shard (one row group per run), atomically (temporary name, then rename); a batch whose shard
exists is done. An interrupted generation (Ctrl-C, kill, crash) therefore resumes on the next
call with no duplicate and no missing run, and never shows a half-written file.

DIR is a local directory or an fsspec URL (``s3://bucket/prefix``, ``gs://…``, ``memory://…``,
``file://…``): every file operation goes through :class:`_Store`. On an object store a file is
staged on the writer's local disk and uploaded in one put, which the store makes visible only
once complete, so workers that share no filesystem write their shards straight to the store.

Layout (contract, docs/formats.md)::

    DIR/manifest.json        recipe, package version, sample rate, units, counts
    DIR/runs.parquet         one row per run: labels and parameters
    DIR/signals/part-NNNNN.parquet   run_id, time, the measured channels, truth_<name>;
                                     row group = run
    DIR/mcap/run-NNNNNN.mcap         with --format mcap|both
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import os
import tempfile
from collections.abc import Callable, Iterable
from contextlib import contextmanager
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from prsm_health.actuator.design import PRESETS
from prsm_health.actuator.design_files import load_design
from prsm_health.actuator.faults import (
    FAULT_CLASSES,
    FaultThresholds,
    fault_as_dict,
    fault_from_dict,
    scaled,
)
from prsm_health.core.channels import CHANNEL_NAMES, TRUTH_PREFIX, UNITS
from prsm_health.core.errors import (
    ParameterError,
    PRSMHealthError,
    RecipeError,
    StorageError,
    require,
)
from prsm_health.core.jsonable import dumps
from prsm_health.core.run import Run
from prsm_health.core.tomlfile import read_toml
from prsm_health.simulation.instrumentation import (
    DEFAULT_PROFILE,
    list_profiles,
    load_instrumentation,
)
from prsm_health.simulation.scenario import Scenario

FORMATS = ("parquet", "mcap", "both")
SWEEP_MODES = ("grid", "random", "lhs")
#: Swept quantities and their units (a range is [min, max]).
SWEPT = {
    "clearance": "m",
    "clearance_screw": "m",
    "clearance_nut": "m",
    "clearance_gear": "m",
    "speed": "rad/s",
    "load": "N",
    "load_amplitude": "N",
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
#: Swept by name: a list of ``fault_cases`` names (drawn uniformly in random and lhs mode).
FAULT_CASE_KEY = "fault_case"
NO_FAULT = "none"
DEFAULT_BATCH = 8
#: Health fields a life recipe's units set themselves (not sweepable there).
LIFE_SETS = (
    "clearance",
    "clearance_screw",
    "clearance_nut",
    "clearance_gear",
    "wear_spread",
    "preload",
    "lubricant_degradation",
    "lubricant_starvation",
)
#: Fleets of life recipes computed in this process, by recipe fingerprint.
_FLEETS: dict[str, list] = {}


@dataclass(frozen=True)
class Recipe:
    """A parsed, validated recipe. Build with :func:`load_recipe` or :meth:`from_dict`."""

    name: str
    design: str | dict
    duration: float
    sample_rate: float
    seed: int
    sweep: dict
    profile: dict = field(default_factory=dict)
    instrumentation: str | dict = DEFAULT_PROFILE
    options: dict = field(default_factory=dict)
    drive_train: dict = field(default_factory=dict)
    faults: FaultThresholds = field(default_factory=FaultThresholds)
    fault_cases: dict = field(default_factory=dict)
    test_fraction: float = 0.2
    batch_size: int = DEFAULT_BATCH
    dtype: str = "float32"
    life: dict = field(default_factory=dict)
    source: dict = field(default_factory=dict, compare=False)

    @classmethod
    def from_dict(cls, data: dict, *, base: Path | None = None) -> Recipe:
        """Parse and validate the dict form of a recipe.

        ``design`` is a preset name, kept as is, or a design TOML file (a relative path against
        ``base``, else the working directory) or the design's dict form: both are stored as the
        full design dict, so ``source`` (what workers rebuild the recipe from, and what the
        manifest and the fingerprint record) holds the design itself, not a path.
        ``instrumentation`` likewise: a built-in profile name is kept, a profile file or an
        ``[instrumentation]`` table (``profile = …`` plus overrides) is stored complete.
        """
        data = dict(data)
        if "sensors" in data:
            raise RecipeError(
                "recipe: the [sensors] table was replaced by instrumentation profiles: write "
                f'instrumentation = "{DEFAULT_PROFILE}" (built-ins: {", ".join(list_profiles())}) '
                "or an [instrumentation] table with profile = … and sensor overrides, e.g. "
                "[instrumentation.nut_axial_accel] noise_density_ug = 40 "
                "(docs/instrumentation.md); sample_rate stays at the top level"
            )
        for key in ("name", "design", "duration", "sample_rate", "seed", "sweep"):
            if key not in data:
                raise RecipeError(f"recipe: missing key {key!r}")
        data["design"] = _recipe_design(data["design"], base)
        if "instrumentation" in data:
            data["instrumentation"] = _recipe_instrumentation(data["instrumentation"], base)
        known = {f.name for f in fields(cls)} - {"source"}
        unknown = sorted(set(data) - known)
        if unknown:
            raise RecipeError(f"recipe: unknown key(s) {', '.join(unknown)}")
        if isinstance(data["sweep"], dict):
            data["sweep"] = _flat_sweep(data["sweep"])
        faults = data.pop("faults", {})
        try:
            thresholds = FaultThresholds(**faults)
        except TypeError as exc:
            raise RecipeError(f"recipe [faults]: {exc}") from None
        recipe = cls(**data, faults=thresholds, source=dict(data, faults=faults))
        recipe._validate()
        return recipe

    def _validate(self) -> None:
        def check(ok, key, value, allowed):
            if not ok:
                raise RecipeError(f"recipe: {key} = {value!r} is invalid: {allowed}")

        check(
            isinstance(self.name, str) and self.name,
            "name",
            self.name,
            "must be a non-empty string",
        )
        check(
            self.design in PRESETS if isinstance(self.design, str) else True,
            "design",
            self.design,
            f"must be one of {', '.join(sorted(PRESETS))} or a design TOML file",
        )
        check(
            isinstance(self.duration, (int, float)) and 0 < self.duration <= 60,
            "duration",
            self.duration,
            "must lie in (0, 60] s",
        )
        check(
            isinstance(self.sample_rate, (int, float)) and 100 <= self.sample_rate <= 1e6,
            "sample_rate",
            self.sample_rate,
            "must lie in [100, 1e6] Hz",
        )
        check(
            isinstance(self.seed, int) and self.seed >= 0,
            "seed",
            self.seed,
            "must be an integer ≥ 0",
        )
        check(
            0 <= self.test_fraction < 1, "test_fraction", self.test_fraction, "must lie in [0, 1)"
        )
        check(
            isinstance(self.batch_size, int) and self.batch_size >= 1,
            "batch_size",
            self.batch_size,
            "must be an integer ≥ 1",
        )
        check(
            self.dtype in ("float32", "float64"), "dtype", self.dtype, "must be float32 or float64"
        )
        sweep = self.sweep
        check(isinstance(sweep, dict), "sweep", sweep, "must be a table")
        mode = sweep.get("mode", "grid")
        check(mode in SWEEP_MODES, "sweep.mode", mode, f"must be one of {', '.join(SWEEP_MODES)}")
        unknown = sorted(
            set(sweep) - set(_swept_keys(sweep)) - {"mode", "repeats", "samples", FAULT_CASE_KEY}
        )
        check(
            not unknown,
            "sweep",
            unknown,
            f"unknown key(s); allowed: mode, repeats, samples, {FAULT_CASE_KEY}, "
            f"{', '.join(SWEPT)}, and fields of {', '.join(SWEPT_GROUPS)} as group.field",
        )
        self._validate_fault_cases(check)
        repeats = sweep.get("repeats", 1)
        check(
            isinstance(repeats, int) and repeats >= 1,
            "sweep.repeats",
            repeats,
            "must be an integer ≥ 1",
        )
        for key in _swept_keys(sweep):
            value = sweep[key]
            unit = SWEPT.get(key, "the group's unit")
            if mode == "grid" and isinstance(value, dict):
                ok = set(value) == {"uniform"} and _is_range(value["uniform"])
                check(
                    ok,
                    f"sweep.{key}",
                    value,
                    f"a drawn value must be {{uniform = [min, max]}} [{unit}]",
                )
            elif mode == "grid":
                ok = (
                    isinstance(value, list)
                    and value
                    and all(isinstance(v, (int, float)) for v in value)
                )
                check(
                    ok,
                    f"sweep.{key}",
                    value,
                    f"must be a non-empty list of numbers [{unit}], or {{uniform = [min, max]}}, in grid mode",
                )
            else:
                ok = (
                    isinstance(value, list)
                    and len(value) == 2
                    and all(isinstance(v, (int, float)) for v in value)
                    and value[0] <= value[1]
                )
                check(
                    ok,
                    f"sweep.{key}",
                    value,
                    f"must be a range [min, max] [{unit}] in {mode} mode",
                )
        if mode != "grid" and not self.life:
            samples = sweep.get("samples")
            check(
                isinstance(samples, int) and samples >= 1,
                "sweep.samples",
                samples,
                f"must be an integer ≥ 1 in {mode} mode",
            )
        if self.life:
            self._validate_life(check, mode)
        # Build every run's scenario once (≈ 0.2 ms each), so a bad value anywhere in a sweep
        # fails now, naming the run, not later in a worker.
        for spec in self.runs():
            spec.scenario()

    def _validate_life(self, check, mode: str) -> None:
        try:
            self.fleet()  # parses [life] and simulates every unit's life (≈ 5 ms a unit)
        except ParameterError as exc:
            raise RecipeError(f"recipe [life]: {exc}") from None
        check(
            mode == "random",
            "sweep.mode",
            mode,
            "must be random in a life recipe (each snapshot draws its recording conditions)",
        )
        set_by_life = sorted(
            k for k in self.sweep if k in LIFE_SETS or k in (FAULT_CASE_KEY, "severity")
        )
        check(
            not set_by_life,
            "sweep",
            set_by_life,
            "the life simulation sets clearances, wear spread, lubricant state and faults "
            "in a life recipe: sweep recording conditions only (speed, load, …)",
        )
        check(
            "samples" not in self.sweep,
            "sweep.samples",
            self.sweep.get("samples"),
            "a life recipe has units × snapshots runs; remove samples",
        )

    @property
    def life_spec(self):
        """The parsed ``[life]`` table (:class:`~prsm_health.physics.life.LifeSpec`), None without one."""
        if not self.life:
            return None
        from prsm_health.physics.life import LifeSpec

        return LifeSpec.from_dict(self.life)

    def fleet(self) -> list:
        """The units' lives of a life recipe (:func:`prsm_health.physics.life.fleet_lives`), computed
        once per process and recipe."""
        key = self.fingerprint
        if key not in _FLEETS:
            from prsm_health.physics.life import fleet_lives

            _FLEETS[key] = fleet_lives(load_design(self.design), self.life_spec, self.seed)
        return _FLEETS[key]

    def _validate_fault_cases(self, check) -> None:
        cases = self.fault_cases
        check(isinstance(cases, dict), "fault_cases", cases, "must be a table of named cases")
        for name, faults in cases.items():
            check(
                isinstance(faults, list),
                f"fault_cases.{name}",
                faults,
                'must be a list of fault tables, e.g. [{ kind = "spall", location = "nut" }]',
            )
            for fault in faults:
                try:
                    fault_from_dict(fault)
                except ParameterError as exc:
                    raise RecipeError(f"recipe: fault_cases.{name}: {exc}") from None
        names = self.sweep.get(FAULT_CASE_KEY)
        if names is None:
            return
        known = [NO_FAULT, *cases]
        check(
            isinstance(names, list) and names and all(n in known for n in names),
            f"sweep.{FAULT_CASE_KEY}",
            names,
            f"must be a non-empty list of case names among: {', '.join(known)}",
        )

    @property
    def fingerprint(self) -> str:
        """Stable hash of the recipe content (guards a dataset directory against another recipe)."""
        return hashlib.sha256(
            json.dumps(self.source, sort_keys=True, default=str).encode()
        ).hexdigest()[:16]

    # ------------------------------------------------------------------ runs
    def runs(self) -> list[RunSpec]:
        """Every run of the recipe, in run-id order (deterministic)."""
        if self.life:
            return self._life_runs()
        points = self._points()
        repeats = self.sweep.get("repeats", 1)
        specs = []
        n_total = len(points) * repeats
        test = _test_set(n_total, self.test_fraction, self.seed)
        run_id = 0
        drawn = {k: v["uniform"] for k, v in self.sweep.items() if isinstance(v, dict)}
        for point in points:
            for _ in range(repeats):
                seed = int(np.random.SeedSequence([self.seed, run_id]).generate_state(1)[0])
                run_point = dict(point)
                if drawn:
                    # grid keys given as {uniform = [min, max]}: a fresh value for every run
                    unit = np.random.default_rng([self.seed, run_id, 0x44524157]).random(len(drawn))
                    for u, (k, (lo, hi)) in zip(unit, sorted(drawn.items())):
                        run_point[k] = float(lo + u * (hi - lo))
                specs.append(
                    RunSpec(self, run_id, run_point, seed, "test" if run_id in test else "train")
                )
                run_id += 1
        return specs

    def _life_runs(self) -> list[RunSpec]:
        # Unit-major: unit u's snapshots are runs u·n … u·n + n − 1. The unit as built (its
        # manufacturing variation and roller wear pattern) is its seed, the same in every
        # snapshot; each snapshot's sensors draw their own noise (sensor_seed). The test split
        # holds out whole units.
        spec = self.life_spec
        test_units = _test_set(spec.units, self.test_fraction, self.seed)
        keys = _swept_keys(self.sweep)
        specs = []
        for unit in self.fleet():
            for k, age in enumerate(unit.snapshot_ages(spec.snapshots)):
                run_id = unit.unit_id * spec.snapshots + k
                unit_draw = np.random.default_rng([self.seed, run_id, 0x534E4150]).random(len(keys))
                point = {
                    key: float(self.sweep[key][0] + u * (self.sweep[key][1] - self.sweep[key][0]))
                    for u, key in zip(unit_draw, keys)
                }
                point.update(unit_id=unit.unit_id, age_hours=float(age))
                seed = int(np.random.SeedSequence([self.seed, run_id]).generate_state(1)[0])
                split = "test" if unit.unit_id in test_units else "train"
                specs.append(RunSpec(self, run_id, point, seed, split))
        return specs

    def _points(self) -> list[dict]:
        keys = _swept_keys(self.sweep)
        mode = self.sweep.get("mode", "grid")
        cases = self.sweep.get(FAULT_CASE_KEY)
        if mode == "grid":
            keys = [k for k in keys if not isinstance(self.sweep[k], dict)]
            if cases:
                keys.append(FAULT_CASE_KEY)
            values = [self.sweep[k] for k in keys]
            return [dict(zip(keys, combo)) for combo in itertools.product(*values)]
        n = self.sweep["samples"]
        if mode == "random":
            unit = np.random.default_rng([self.seed, 0x5357]).random((n, len(keys)))
        else:
            from scipy.stats import qmc

            unit = qmc.LatinHypercube(
                d=max(len(keys), 1), seed=np.random.default_rng([self.seed, 0x4C48])
            ).random(n)
        out = []
        for row in unit:
            point = {}
            for j, k in enumerate(keys):
                lo, hi = self.sweep[k]
                point[k] = float(lo + row[j] * (hi - lo))
            if cases:  # a categorical draw from its own stream, so the numeric draws stay put
                pick = np.random.default_rng([self.seed, len(out), 0x46434153]).integers(len(cases))
                point[FAULT_CASE_KEY] = cases[int(pick)]
            out.append(point)
        return out

    def batches(self) -> list[list[int]]:
        """Run ids grouped into the fixed batches that workers write as one shard each."""
        ids = list(range(len(self.runs())))
        return [ids[i : i + self.batch_size] for i in range(0, len(ids), self.batch_size)]


def _flat_sweep(sweep: dict) -> dict:
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


def _swept_keys(sweep: dict) -> list[str]:
    """The swept quantities of a (flat) sweep: :data:`SWEPT` order, then group fields sorted."""
    grouped = sorted(k for k in sweep if k.split(".")[0] in SWEPT_GROUPS and "." in k)
    return [k for k in SWEPT if k in sweep] + grouped


def _set_path(target: dict, path: list[str], value) -> None:
    for key in path[:-1]:
        target = target.setdefault(key, {})
    target[path[-1]] = value


def _is_range(value) -> bool:
    return (
        isinstance(value, list)
        and len(value) == 2
        and all(isinstance(v, (int, float)) for v in value)
        and value[0] <= value[1]
    )


def _test_set(n: int, fraction: float, seed: int) -> set[int]:
    k = int(round(n * fraction))
    return set(np.random.default_rng([seed, 0x54455354]).permutation(n)[:k].tolist())


@dataclass(frozen=True)
class RunSpec:
    """One run of a recipe: its id, swept values, seed and split."""

    recipe: Recipe
    run_id: int
    point: dict
    seed: int
    split: str

    def scenario(self) -> Scenario:
        """The :class:`~prsm_health.simulation.scenario.Scenario` of this run (validates)."""
        r, p = self.recipe, self.point
        unit = self.unit()
        if unit is not None:
            return self._life_scenario(unit)
        health = {"clearance": p.get("clearance", 10e-6)}
        health.update({k: p[k] for k in SWEPT if k.startswith("clearance_") and k in p})
        health_keys = (
            "wear_spread",
            "friction_scale",
            "preload",
            "lubricant_degradation",
            "lubricant_starvation",
        )
        health.update({k: p[k] for k in health_keys if k in p})
        health["faults"] = self.faults()
        profile = {
            "duration": r.duration,
            "speed": p.get("speed", 100.0),
            "load": p.get("load", 100.0),
        }
        profile.update(r.profile)
        for key in ("load_amplitude", "temperature"):
            if key in p:
                profile[key] = p[key]
        return self._build(health, profile, seed=self.seed)

    def _build(self, health, profile: dict, *, seed: int, sensor_seed: int | None = None):
        r, p = self.recipe, self.point
        groups = {
            "profile": profile,
            "instrumentation": copy.deepcopy(_with_sample_rate(r.instrumentation, r.sample_rate)),
            "options": copy.deepcopy(r.options),
            "drive_train": dict(r.drive_train),
        }
        for key, value in p.items():
            group, *path = key.split(".")
            if path:  # a domain-randomised field
                _set_path(groups[group], path, value)
        try:
            return Scenario.from_dict(
                {
                    "design": r.design,
                    "health": health,
                    **groups,
                    "seed": seed,
                    "sensor_seed": sensor_seed,
                }
            )
        except ParameterError as exc:
            raise RecipeError(f"recipe (run {self.run_id}): {exc}") from None

    def unit(self):
        """The :class:`~prsm_health.physics.life.UnitLife` of a life recipe's snapshot, else None."""
        if "unit_id" not in self.point:
            return None
        return self.recipe.fleet()[self.point["unit_id"]]

    def _life_scenario(self, unit) -> Scenario:
        # The unit's health at this age; its temperature unless the sweep draws one.
        r, p = self.recipe, self.point
        health = unit.health_at(p["age_hours"])
        if "friction_scale" in p:
            health = replace(health, friction_scale=p["friction_scale"])
        profile = {
            "duration": r.duration,
            "speed": p.get("speed", 100.0),
            "load": p.get("load", 100.0),
            "temperature": unit.temperature,
        }
        profile.update(r.profile)
        for key in ("load_amplitude", "temperature"):
            if key in p:
                profile[key] = p[key]
        return self._build(health, profile, seed=unit.seed, sensor_seed=self.seed)

    def faults(self) -> list[dict]:
        """The faults of this run's case, their severities scaled by its ``severity``."""
        name = self.point.get(FAULT_CASE_KEY, NO_FAULT)
        factor = self.point.get("severity", 1.0)
        try:
            faults = [fault_from_dict(f) for f in self.recipe.fault_cases.get(name, [])]
            return [fault_as_dict(scaled(f, factor)) for f in faults]
        except ParameterError as exc:
            raise RecipeError(
                f"recipe (run {self.run_id}, fault case {name}, severity {factor:g}): {exc}"
            ) from None

    def labels(self, run: Run | None = None) -> dict:
        """The run's labels: id, split, fault class, the scenario's labels (nominal values) and,
        given the simulated run, its realised clearances."""
        scenario = self.scenario()
        out = {
            "run_id": self.run_id,
            "split": self.split,
            "fault_class": self.recipe.faults.classify(scenario.health),
            "fault_case": self.point.get(FAULT_CASE_KEY, NO_FAULT),
            "severity": self.point.get("severity", 1.0),
            **scenario.labels(),
            # domain-randomised fields, under their dotted names
            **{k: v for k, v in self.point.items() if "." in k},
        }
        unit = self.unit()
        if unit is not None:
            out.update(unit.labels(self.point["age_hours"]))
        if run is not None:
            out.update({k: v for k, v in run.labels.items() if "_realised_" in k})
            out["n_samples"] = len(run)
        return out


def load_recipe(path: str | Path) -> Recipe:
    """Parse and validate a TOML recipe; errors name the key."""
    path = Path(path)
    return Recipe.from_dict(read_toml(path, "recipe file", RecipeError), base=path.parent)


def _recipe_design(design, base: Path | None) -> str | dict:
    """A preset name as is; a design file or dict as the validated design's dict form."""
    if isinstance(design, str) and design in PRESETS:
        return design
    try:
        return load_design(design, base=base).to_dict()
    except ParameterError as exc:
        raise RecipeError(f"recipe: {exc}") from None
    except PRSMHealthError as exc:
        raise RecipeError(f"recipe: design: {exc}") from None


def _recipe_instrumentation(instrumentation, base: Path | None) -> str | dict:
    """A built-in profile name as is; a profile file or table as the profile's complete dict
    (without its sample rate: the recipe's top-level ``sample_rate`` sets it, so a table may not
    set it too)."""
    if isinstance(instrumentation, str) and instrumentation in list_profiles():
        return instrumentation
    if isinstance(instrumentation, dict) and "sample_rate" in instrumentation:
        raise RecipeError(
            "recipe: instrumentation.sample_rate: the recipe's top-level sample_rate sets the "
            "sample rate; remove it from the [instrumentation] table"
        )
    try:
        complete = load_instrumentation(instrumentation, base=base).to_dict()
    except ParameterError as exc:
        raise RecipeError(f"recipe: {exc}") from None
    except PRSMHealthError as exc:
        raise RecipeError(f"recipe: instrumentation: {exc}") from None
    del complete["sample_rate"]
    return complete


def _with_sample_rate(instrumentation: str | dict, sample_rate: float) -> dict:
    """The dict form of the recipe's profile at the recipe's sample rate."""
    if isinstance(instrumentation, str):
        return {"profile": instrumentation, "sample_rate": sample_rate}
    return {**instrumentation, "sample_rate": sample_rate}


# ---------------------------------------------------------------------- storage
class _Store:
    """A dataset directory — a local path or an fsspec URL — and the few file operations that
    generation and :class:`Dataset` need, all through fsspec.

    Paths given to the methods are relative to the dataset directory, with ``/``. Writes are
    staged (:meth:`staged`), so a file appears under its name only once complete. Failures of
    the store itself (unknown protocol, backend not installed, unreachable endpoint, missing
    bucket, denied access) raise :class:`~prsm_health.core.errors.StorageError` naming the location.

    Parameters
    ----------
    location : str or path-like
        A plain local path (used as is, like :class:`pathlib.Path`), or a URL such as
        ``s3://bucket/prefix``. Storage options (endpoint, credentials) come from the
        environment, as the fsspec backend reads them (docs/formats.md, "Object stores").
    """

    def __init__(self, location: str | os.PathLike):
        import fsspec
        from fsspec.implementations.local import LocalFileSystem

        text = os.fspath(location)
        #: What a worker rebuilds the store from: the location exactly as given.
        self.url = text
        if "://" not in text and "::" not in text:
            # A plain path keeps its plain-path meaning (relative to the working directory,
            # no ~ expansion), as before object stores were supported.
            self.fs, self.root = LocalFileSystem(), os.path.abspath(text)
            self.location: Path | str = Path(text)
        else:
            try:
                self.fs, root = fsspec.core.url_to_fs(text)
            except (ValueError, ImportError) as exc:  # unknown protocol, backend not installed
                raise StorageError(f"{text}: unusable dataset location ({exc})") from None
            self.root = root.rstrip("/")
            local = isinstance(self.fs, LocalFileSystem)
            self.location = Path(self.root) if local else text.rstrip("/")
            if not self.root.strip("/"):
                raise StorageError(
                    f"{text}: the URL names no location (write e.g. s3://bucket/datasets/name)"
                )
        self.local = isinstance(self.fs, LocalFileSystem)
        #: memory:// lives in one process: worker processes would each write their own copy.
        self.in_process = "memory" in _protocols(self.fs)
        # fsspec shares one filesystem object per process and URL: its listings may predate
        # what another process wrote since
        self.refresh()

    def __str__(self) -> str:
        return str(self.location)

    def path(self, rel: str = "") -> str:
        """The full path of ``rel`` inside the store's filesystem (what ``self.fs`` takes)."""
        return f"{self.root}/{rel}" if rel else self.root

    def name(self, rel: str) -> str:
        """``rel`` as a user would write it (messages)."""
        if isinstance(self.location, Path):
            return str(self.location / rel)
        return f"{self.location}/{rel}" if rel else self.location

    @contextmanager
    def _io(self, action: str, rel: str):
        try:
            yield
        except PRSMHealthError:
            raise
        except Exception as exc:  # any backend's error type: botocore, aiohttp, gcsfs, OSError
            detail = " ".join(str(exc).split()) or type(exc).__name__
            raise StorageError(
                f"{self.name(rel)}: cannot {action} ({type(exc).__name__}: {detail})"
            ) from exc

    def refresh(self) -> None:
        """Forget cached listings: other processes (workers) write to the store, and an fsspec
        filesystem would otherwise answer from a listing made before they did. All of them:
        s3fs's ``invalidate_cache(path)`` forgets a path and its parents, not its children."""
        with self._io("list", ""):
            self.fs.invalidate_cache()

    def makedirs(self, *rels: str) -> None:
        """Create directories — local ones only: object stores have none, and s3fs would
        create a missing *bucket* instead of reporting it."""
        if self.local:
            for rel in rels:
                with self._io("create directory", rel):
                    self.fs.makedirs(self.path(rel), exist_ok=True)

    def exists(self, rel: str) -> bool:
        with self._io("check", rel):
            return self.fs.exists(self.path(rel))

    def list(self, rel: str) -> list[str]:
        """Names (not paths) in directory ``rel``; empty if it does not exist."""
        self.refresh()
        with self._io("list", rel):
            try:
                paths = self.fs.ls(self.path(rel), detail=False)
            except FileNotFoundError:
                return []
        return [p.rstrip("/").rsplit("/", 1)[-1] for p in paths]

    def read_text(self, rel: str) -> str:
        with self._io("read", rel):
            return self.fs.cat_file(self.path(rel)).decode()

    def open(self, rel: str):
        """A binary file object to read ``rel``."""
        with self._io("read", rel):
            return self.fs.open(self.path(rel), "rb")

    def write_text(self, rel: str, text: str) -> None:
        with self.staged(rel) as tmp:
            Path(tmp).write_text(text)

    def remove(self, rel: str) -> None:
        with self._io("remove", rel):
            self.fs.rm_file(self.path(rel))

    @contextmanager
    def staged(self, rel: str):
        """Yield a local file path to write; when the block ends without error, the file
        becomes ``rel`` at once, else it is dropped.

        Local: a temporary name next to the destination (``NAME.partial-<pid>``), renamed.
        Object store: a local temporary file, uploaded in one put — an object appears only
        when its upload completes, so a killed writer leaves nothing under the name (an
        interrupted multipart upload leaves invisible parts, which the bucket's lifecycle
        rule for incomplete uploads removes).
        """
        if self.local:
            tmp = f"{self.path(rel)}.partial-{os.getpid()}"
            try:
                yield tmp
                # os.replace, not fs.mv: fsspec's local mv is shutil.move, which on Windows
                # copies onto an existing target instead of replacing it atomically
                with self._io("write", rel):
                    os.replace(tmp, self.path(rel))
            finally:
                if os.path.exists(tmp):
                    os.unlink(tmp)
            return
        with tempfile.TemporaryDirectory(prefix="prsm-health-") as folder:
            tmp = os.path.join(folder, rel.rsplit("/", 1)[-1])
            yield tmp
            with self._io("write", rel):
                self.fs.put_file(tmp, self.path(rel))

    def discard_partials(self, *rels: str) -> None:
        """Remove what killed writers left in directories ``rels`` (local stores: staged
        files under ``.partial-`` names; object stores stage on the writer's disk)."""
        if self.local:
            for rel in rels:
                for name in self.list(rel):
                    if ".partial-" in name:
                        self.remove(f"{rel}/{name}")


def _protocols(fs) -> tuple[str, ...]:
    protocol = fs.protocol
    return (protocol,) if isinstance(protocol, str) else tuple(protocol)


# ---------------------------------------------------------------------- generation
def _shard_name(batch: int) -> str:
    return f"signals/part-{batch:05d}.parquet"


def _mcap_name(run_id: int) -> str:
    return f"mcap/run-{run_id:06d}.mcap"


def run_batch(recipe_source: dict, batch: int, out_dir: str, formats: str) -> list[dict]:
    """Simulate one batch and write its shard (and MCAP files); returns the batch's labels.

    Runs in a worker process (local pool or Dask worker): takes only plain data, writes its own
    files straight to ``out_dir`` (a local path or a store URL: a Dask worker needs no
    filesystem shared with the client), returns only the small label dicts.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    recipe = Recipe.from_dict(recipe_source)
    store = _Store(out_dir)
    specs = recipe.runs()
    dtype = np.float32 if recipe.dtype == "float32" else np.float64
    tables, labels = [], []
    for run_id in recipe.batches()[batch]:
        spec = specs[run_id]
        run = spec.scenario().simulate()
        label = spec.labels(run)
        run.labels = dict(run.labels, **label)
        if formats in ("mcap", "both"):
            from prsm_health.io.mcap import write_mcap

            with store.staged(_mcap_name(run_id)) as tmp:
                write_mcap(run, tmp)
        columns = {"run_id": pa.array(np.full(len(run), run_id, np.int32))}
        for name, values in run.columns().items():
            # time stays float64: float32 would round the sample times
            columns[name] = pa.array(values if name == "time" else values.astype(dtype))
        tables.append(pa.table(columns))
        labels.append(label)
    # One shard per batch, one row group per run; the labels ride in the footer so a shard and
    # its labels appear together, atomically (staged, see _Store.staged). The runs of a
    # recipe share their instrumentation, hence their columns.
    metadata = _schema_metadata(recipe, tables[0].column_names[1:])
    metadata[b"prsm_health.labels"] = json.dumps(labels).encode()
    with store.staged(_shard_name(batch)) as tmp:
        with pq.ParquetWriter(
            tmp, tables[0].schema.with_metadata(metadata), compression="zstd"
        ) as writer:
            for table in tables:
                writer.write_table(table, row_group_size=table.num_rows)
    return labels


def _schema_metadata(recipe: Recipe, columns: list[str]) -> dict:
    return {
        b"prsm_health.units": json.dumps({k: UNITS[k] for k in columns}).encode(),
        b"prsm_health.sample_rate": repr(float(recipe.sample_rate)).encode(),
        b"prsm_health.recipe": recipe.name.encode(),
    }


def _shard_schema(store: _Store, rel: str):
    import pyarrow.parquet as pq

    with store._io("read", rel):
        return pq.read_schema(store.path(rel), filesystem=store.fs)


def _shard_labels(store: _Store, rel: str) -> list[dict]:
    meta = _shard_schema(store, rel).metadata or {}
    return json.loads(meta[b"prsm_health.labels"])


@dataclass
class GenerationReport:
    """What one call of :func:`generate` did."""

    out: Path | str
    """The dataset directory: a Path, or the URL of an object-store dataset."""
    total_runs: int
    generated_runs: int
    resumed_runs: int
    seconds: float

    @property
    def runs_per_minute(self) -> float:
        return 60.0 * self.generated_runs / self.seconds if self.seconds > 0 else float("nan")


def generate(
    recipe: Recipe | str | Path,
    out: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | object | None = None,
    formats: str = "parquet",
    progress: bool = True,
    on_batch: Callable[[int], None] | None = None,
) -> GenerationReport:
    """Generate (or resume) a dataset.

    Parameters
    ----------
    recipe : Recipe or path to a TOML recipe
    out : path or str
        Dataset directory: a local path, or an fsspec URL (``s3://bucket/prefix``, ``gs://…``,
        ``memory://…``, ``file://…``; credentials and endpoint from the environment,
        docs/formats.md). Created if missing. A directory holding another recipe's dataset is
        refused.
    workers : int or None
        Local worker processes (default: CPU count; 1 for ``memory://``, which lives in this
        process). 1 runs in this process.
    scheduler : str, distributed.Client or None
        Dask scheduler address (or a Client); default from ``DASK_SCHEDULER_ADDRESS``. When set,
        batches run on the cluster and the workers write the files to ``out``: a shared
        filesystem for a local path, none needed for an object-store URL.
    formats : {"parquet", "mcap", "both"}
    progress : bool
        Progress bar with runs done, rate and ETA.
    on_batch : callable or None
        Called with each finished batch index (tests use it to interrupt).
    """
    import time

    recipe = recipe if isinstance(recipe, Recipe) else load_recipe(recipe)
    require(formats in FORMATS, "format", formats, f"must be one of {', '.join(FORMATS)}")
    store = _Store(out)
    _prepare(store, recipe, formats)
    batches = recipe.batches()
    total = sum(len(b) for b in batches)
    done = {f"signals/{name}" for name in store.list("signals")}
    pending = [i for i in range(len(batches)) if _shard_name(i) not in done]
    resumed = total - sum(len(batches[i]) for i in pending)
    scheduler = (
        scheduler if scheduler is not None else os.environ.get("DASK_SCHEDULER_ADDRESS") or None
    )
    start = time.perf_counter()
    bar = None
    if progress and pending:
        from tqdm import tqdm

        bar = tqdm(total=total, initial=resumed, unit="run", desc=recipe.name, smoothing=0.1)
    done_runs = 0

    def finished(batch: int) -> None:
        nonlocal done_runs
        done_runs += len(batches[batch])
        if bar is not None:
            bar.update(len(batches[batch]))
        if on_batch is not None:
            on_batch(batch)

    try:
        if scheduler:
            _run_dask(scheduler, recipe, store, formats, pending, finished)
        else:
            _run_local(workers, recipe, store, formats, pending, finished)
    finally:
        if bar is not None:
            bar.close()
    _finalise(store, recipe, formats)
    return GenerationReport(store.location, total, done_runs, resumed, time.perf_counter() - start)


def _prepare(store: _Store, recipe: Recipe, formats: str) -> None:
    mcap = formats in ("mcap", "both")
    store.makedirs("", "signals", *(["mcap"] if mcap else []))
    stamp = ".recipe.json"
    if store.exists(stamp):
        previous = json.loads(store.read_text(stamp))
        if previous.get("fingerprint") != recipe.fingerprint:
            raise PRSMHealthError(
                f"{store} holds a dataset of recipe {previous.get('name')!r} with other content "
                f"({_recipe_changes(previous.get('source'), recipe.source)}); runs made with "
                "different settings cannot be mixed: use a new --out directory or undo the edit"
            )
    else:
        # the first write: an unreachable store or a missing bucket fails here, before any run
        store.write_text(
            stamp,
            dumps(
                {"name": recipe.name, "fingerprint": recipe.fingerprint, "source": recipe.source}
            ),
        )
    # a killed worker's unfinished shard or MCAP file
    store.discard_partials("signals", *(["mcap"] if mcap else []))


def _recipe_changes(before: dict | None, after: dict) -> str:
    """Which recipe keys differ, as 'key: old → new' (dotted keys for tables)."""
    if before is None:
        return "the directory predates change tracking"

    def flat(d, prefix=""):
        out = {}
        for k, v in d.items():
            out.update(flat(v, f"{prefix}{k}.") if isinstance(v, dict) else {prefix + k: v})
        return out

    a, b = flat(before), flat(after)
    changed = [
        f"{k}: {a.get(k, '(unset)')!r} → {b.get(k, '(unset)')!r}"
        for k in sorted(set(a) | set(b))
        if a.get(k) != b.get(k)
    ]
    return "changed " + "; ".join(changed[:5]) + (" …" if len(changed) > 5 else "")


def _run_local(workers, recipe, store, formats, pending, finished) -> None:
    workers = workers or (1 if store.in_process else os.cpu_count() or 1)
    require(isinstance(workers, int) and workers >= 1, "workers", workers, "must be an integer ≥ 1")
    require(
        workers == 1 or not store.in_process,
        "workers",
        workers,
        f"must be 1 for {store.url}: a memory:// store lives in this process, worker processes "
        "would each write to their own",
    )
    if workers == 1:
        for batch in pending:
            run_batch(recipe.source, batch, store.url, formats)
            finished(batch)
        return
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    # Workers ignore SIGINT: on Ctrl-C the parent stops them at once (shards are written
    # atomically, so a killed batch leaves no file and is redone on resume); otherwise each
    # worker would finish its batch and start queued ones before the pool noticed.
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_ignore_sigint)
    try:
        futures = {pool.submit(run_batch, recipe.source, b, store.url, formats): b for b in pending}
        remaining = set(futures)
        while remaining:
            done, remaining = wait(remaining, return_when=FIRST_COMPLETED)
            for fut in done:
                fut.result()
                finished(futures[fut])
    except BaseException:
        processes = list((pool._processes or {}).values())  # no public API to stop a worker
        pool.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            process.terminate()
        for process in processes:
            process.join(timeout=2.0)
        raise
    pool.shutdown()


def _ignore_sigint() -> None:
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _run_dask(scheduler, recipe, store, formats, pending, finished) -> None:
    from distributed import Client, as_completed

    client = scheduler if isinstance(scheduler, Client) else Client(scheduler)
    try:
        futures = client.map(
            run_batch,
            [recipe.source] * len(pending),
            pending,
            # workers open the store themselves: an object-store URL needs no shared filesystem
            [store.url] * len(pending),
            [formats] * len(pending),
            pure=False,
        )
        index = {f.key: b for f, b in zip(futures, pending)}
        for fut in as_completed(futures):
            fut.result()
            finished(index[fut.key])
    finally:
        if client is not scheduler:
            client.close()


def dataset_counts(frame) -> dict:
    """The manifest's ``counts`` of a labels table: runs, train, test, runs per fault class."""
    classes = frame["fault_class"].value_counts().sort_index() if "fault_class" in frame else {}
    return {
        "runs": len(frame),
        "train": int((frame["split"] == "train").sum()),
        "test": int((frame["split"] == "test").sum()),
        "fault_class": {k: int(v) for k, v in dict(classes).items()},
    }


def _finalise(store: _Store, recipe: Recipe, formats: str) -> None:
    """Assemble runs.parquet and manifest.json from the shards (idempotent)."""
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq

    from prsm_health import __version__

    store.refresh()  # the workers' shards, not a listing cached before they wrote them
    rows = []
    for batch in range(len(recipe.batches())):
        shard = _shard_name(batch)
        for group, label in enumerate(_shard_labels(store, shard)):
            rows.append(dict(label, shard=shard, row_group=group))
    frame = pd.DataFrame(rows).sort_values("run_id").reset_index(drop=True)
    stored = _shard_schema(store, _shard_name(0)).names
    table = pa.Table.from_pandas(frame, preserve_index=False)
    with store.staged("runs.parquet") as tmp:
        pq.write_table(table, tmp)
    manifest = {
        "name": recipe.name,
        "recipe": recipe.source,
        "package": {"name": "prsm_health", "version": __version__},
        "sample_rate": recipe.sample_rate,
        "duration": recipe.duration,
        "channels": {k: UNITS[k] for k in stored if k == "time" or k in CHANNEL_NAMES},
        "truth": {k: UNITS[k] for k in stored if k in UNITS and k.startswith(TRUTH_PREFIX)},
        "dtype": recipe.dtype,
        "formats": formats,
        "fault_taxonomy": {
            "classes": list(FAULT_CLASSES),
            "thresholds": recipe.faults.as_dict(),
            "rule": FaultThresholds.__doc__.split("\n\n")[1].strip().replace("\n    ", " "),
        },
        "counts": dataset_counts(frame),
    }
    store.write_text("manifest.json", dumps(manifest, indent=2))


class Dataset:
    """A generated dataset directory: labels table and per-run signals.

    Parameters
    ----------
    path : path or str
        A local directory or an fsspec URL (``s3://bucket/prefix`` …), as for :func:`generate`.
    """

    def __init__(self, path: str | Path):
        import pandas as pd

        self._store = _Store(path)
        #: A Path for a local dataset, the URL (str) for an object-store one.
        self.path = self._store.location
        if not self._store.exists("manifest.json"):
            raise PRSMHealthError(f"{self.path}: not a dataset directory (no manifest.json)")
        try:
            self.manifest = json.loads(self._store.read_text("manifest.json"))
            # a file object, not filesystem=: pandas < 2.1 has no such argument
            with self._store.open("runs.parquet") as file:
                self.runs = pd.read_parquet(file)
        except StorageError:
            raise
        except Exception as exc:  # damaged files
            raise PRSMHealthError(f"{self.path}: unreadable dataset ({exc})") from None

    @property
    def sample_rate(self) -> float:
        return float(self.manifest["sample_rate"])

    @property
    def channels(self) -> tuple[str, ...]:
        """The measured channels the dataset's runs have, in contract order."""
        return tuple(c for c in CHANNEL_NAMES if c in self.manifest["channels"])

    def __len__(self) -> int:
        return len(self.runs)

    def run(self, run_id: int, *, truth: bool = True) -> Run:
        """The signals of one run as a :class:`~prsm_health.core.run.Run` (one row group read):
        the measured channels, and the truth signals in ``Run.truth`` unless ``truth`` is
        False (then their columns are not read)."""
        import pyarrow.parquet as pq

        from prsm_health.io.columns import contract_channels, truth_columns

        rows = self.runs[self.runs["run_id"] == run_id]
        if rows.empty:
            raise PRSMHealthError(f"run_id {run_id} is not in {self.path}")
        row = rows.iloc[0]
        store = self._store
        with (
            store._io("read", row["shard"]),
            # a local shard read by pyarrow itself: through fsspec it took 1.5× as long
            pq.ParquetFile(
                store.path(row["shard"]), filesystem=None if store.local else store.fs
            ) as shard,
        ):
            names = shard.schema_arrow.names
            if not truth:
                names = [c for c in names if not c.startswith(TRUTH_PREFIX)]
            table = shard.read_row_group(int(row["row_group"]), columns=names)
        channels = contract_channels(
            store.name(row["shard"]), names, lambda c: table.column(c).to_numpy()
        )
        signals = truth_columns(names, lambda c: table.column(c).to_numpy())
        labels = {
            k: (v.item() if hasattr(v, "item") else v)
            for k, v in row.items()
            if k not in ("shard", "row_group")
        }
        return Run(
            table.column("time").to_numpy(),
            channels,
            self.sample_rate,
            labels,
            {"recipe": self.manifest["recipe"]},
            truth=signals,
        )

    def iter_runs(self, run_ids: Iterable[int] | None = None):
        for run_id in run_ids if run_ids is not None else self.runs["run_id"]:
            yield self.run(int(run_id))


def dataset_throughput(report: GenerationReport) -> str:
    """One line for logs and docs: runs, time, runs/min."""
    return (
        f"{report.generated_runs} runs in {report.seconds:.1f} s "
        f"({report.runs_per_minute:.0f} runs/min; {report.resumed_runs} already done)"
    )


__all__ = [
    "Dataset",
    "FaultThresholds",
    "GenerationReport",
    "Recipe",
    "RecipeError",
    "RunSpec",
    "generate",
    "load_recipe",
    "run_batch",
]
