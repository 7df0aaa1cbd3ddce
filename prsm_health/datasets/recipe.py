"""Dataset recipes: what a dataset holds — design, instrumentation, duration and sample rate,
profile and option settings, a seed, a sweep over clearance, speed, load, friction, wear, faults
(grid, random or Latin-hypercube), repeats, the test split, fault-class thresholds and, for
life recipes, the fleet — and the one run each index stands for (:class:`RunSpec`).

Run i always gets the same parameters and seed (derived from the recipe seed and i), whatever
the worker count or scheduler (docs/formats.md).

Loads — the swept ``load`` and ``load_amplitude`` (lists, ranges, ``{uniform = [min, max]}``) and
the ``[profile]`` table's — may be newtons, a number with a unit or a share of the design's load
rating (``load = ["5 % C_a", "40 % C_a"]``; :mod:`prsm_health.core.quantities`). A recipe has one
design: its sweep is resolved against that design's ratings (a range of shares is a range of
newtons between the resolved ends), the ``[profile]`` loads by each run's scenario.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import zlib
from dataclasses import dataclass, field, fields, replace
from functools import cached_property
from pathlib import Path

import numpy as np

from prsm_health.actuator.design import PRESETS, PRSMDesign
from prsm_health.actuator.design_files import design_fingerprint, design_reference, load_design
from prsm_health.actuator.faults import (
    FaultThresholds,
    fault_as_dict,
    fault_from_dict,
    scaled,
)
from prsm_health.core.errors import (
    ParameterError,
    PRSMHealthError,
    RecipeError,
    nearest_key,
    require_known_keys,
    unknown_key_message,
)
from prsm_health.core.quantities import parse_force
from prsm_health.core.run import Run
from prsm_health.core.tomlfile import read_toml
from prsm_health.simulation.instrumentation import (
    DEFAULT_PROFILE,
    list_profiles,
    load_instrumentation,
)
from prsm_health.simulation.scenario import Scenario, design_ratings

from .sweep import (
    FORCE_KEYS,
    SWEEP_MODES,
    SWEPT,
    SWEPT_GROUPS,
    flat_sweep,
    is_range,
    is_value,
    set_path,
    swept_keys,
    test_set,
    written_values,
)

FORMATS = ("parquet", "mcap", "both")
#: Swept by name: a list of ``fault_cases`` names (drawn uniformly in random and lhs mode).
FAULT_CASE_KEY = "fault_case"
NO_FAULT = "none"
DEFAULT_BATCH = 8
#: Health fields a unit is built with: ``[units.build]`` draws them once per unit.
UNIT_BUILD = (
    "clearance",
    "clearance_screw",
    "clearance_nut",
    "clearance_gear",
    "wear_spread",
    "preload",
)
#: Health fields a life recipe's units set themselves (not sweepable there): their build and
#: their lubricant's ageing.
LIFE_SETS = (*UNIT_BUILD, "lubricant_degradation", "lubricant_starvation")
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
    units: dict = field(default_factory=dict)
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
        # unknown keys first: a typo ('sead') is named as such, not as 'seed' missing
        require_known_keys(
            "recipe",
            data,
            [f.name for f in fields(cls) if f.name != "source"],
            required=("name", "design", "duration", "sample_rate", "seed", "sweep"),
            error=RecipeError,
        )
        data["design"] = _recipe_design(data["design"], base)
        if "instrumentation" in data:
            data["instrumentation"] = _recipe_instrumentation(data["instrumentation"], base)
        if isinstance(data["sweep"], dict):
            data["sweep"] = flat_sweep(data["sweep"])
        faults = data.pop("faults", {})
        if isinstance(faults, dict):
            require_known_keys(
                "faults", faults, [f.name for f in fields(FaultThresholds)], error=RecipeError
            )
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
        self._validate_units(check)
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
        known = ["mode", "repeats", "samples", FAULT_CASE_KEY, *SWEPT]
        unknown = sorted(set(sweep) - set(swept_keys(sweep)) - set(known))
        if unknown:  # named as design files name theirs: the nearest key, the allowed ones
            raise RecipeError(
                f"recipe: {unknown_key_message('sweep', unknown[0], sweep[unknown[0]], known)}, "
                f"and fields of {', '.join(SWEPT_GROUPS)} as group.field"
            )
        self._validate_fault_cases(check)
        repeats = sweep.get("repeats", 1)
        check(
            isinstance(repeats, int) and repeats >= 1,
            "sweep.repeats",
            repeats,
            "must be an integer ≥ 1",
        )
        for key in swept_keys(sweep):
            value = sweep[key]
            unit = SWEPT.get(key, "the group's unit")
            if mode == "grid" and isinstance(value, dict):
                ok = set(value) == {"uniform"} and is_range(value["uniform"], key)
                check(
                    ok,
                    f"sweep.{key}",
                    value,
                    f"a drawn value must be {{uniform = [min, max]}} [{unit}]",
                )
            elif mode == "grid":
                ok = isinstance(value, list) and value and all(is_value(key, v) for v in value)
                check(
                    ok,
                    f"sweep.{key}",
                    value,
                    f"must be a non-empty list of {'forces' if key in FORCE_KEYS else 'numbers'} "
                    f"[{unit}], or {{uniform = [min, max]}}, in grid mode",
                )
            else:
                ok = is_range(value, key)
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
        self._validate_forces(check)
        if self.life:
            self._validate_life(check, mode)
        # Build every run's scenario once (≈ 0.2 ms each), so a bad value anywhere in a sweep
        # fails now, naming the run, not later in a worker.
        for spec in self.runs():
            spec.scenario()

    def _validate_forces(self, check) -> None:
        """Each swept force parses (the error names the key and the accepted forms) and each
        range is ordered once resolved against the design's ratings."""
        for key in swept_keys(self.sweep):
            if key not in FORCE_KEYS:
                continue
            for v in written_values(self.sweep[key]):
                try:
                    newtons = self._newtons(key, v)
                except ParameterError as exc:
                    raise RecipeError(f"recipe: {exc}") from None
                # one value alone above the static rating: named here, not as run k's peak
                check(
                    abs(newtons) <= self.ratings["C_0a"],
                    f"sweep.{key}",
                    v,
                    f"is {newtons:.4g} N, above the static load rating C_0a = "
                    f"{self.ratings['C_0a']:.4g} N of the design",
                )
        try:
            resolved = self.resolved_sweep
        except ParameterError as exc:
            raise RecipeError(f"recipe: {exc}") from None
        for key in FORCE_KEYS:
            value = resolved.get(key)
            if value is None:
                continue
            pair = value.get("uniform") if isinstance(value, dict) else value
            if isinstance(value, dict) or self.sweep.get("mode", "grid") != "grid":
                check(
                    pair[0] <= pair[1],
                    f"sweep.{key}",
                    self.sweep[key],
                    f"a range [min, max] must have min ≤ max (here {pair[0]:g} N > "
                    f"{pair[1]:g} N with the design's ratings)",
                )

    @cached_property
    def ratings(self) -> dict[str, float]:
        """``{"C_a": …, "C_0a": …}`` [N]: the design's basic axial load ratings, which the
        loads given as shares are shares of."""
        return design_ratings(self.prsm_design)

    @cached_property
    def resolved_sweep(self) -> dict:
        """The sweep with every force (:data:`FORCE_KEYS`) in newtons against the design's
        ratings: what the runs draw from."""
        out = dict(self.sweep)
        for key in FORCE_KEYS:
            if key not in out:
                continue
            value = out[key]
            if isinstance(value, dict):
                out[key] = {"uniform": [self._newtons(key, v) for v in value["uniform"]]}
            else:
                out[key] = [self._newtons(key, v) for v in value]
        return out

    def _newtons(self, key: str, value) -> float:
        return parse_force(value, f"sweep.{key}").newtons(self.ratings, f"sweep.{key}")

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
            "a life recipe has units × snapshots × recordings runs; remove samples",
        )

    @cached_property
    def prsm_design(self) -> PRSMDesign:
        """The recipe's design (``design`` holds a preset name or the full dict form)."""
        return load_design(self.design)

    @cached_property
    def design_fingerprint(self) -> str:
        """:func:`~prsm_health.actuator.design_files.design_fingerprint` of the design: every
        run's ``design_fingerprint`` label."""
        return design_fingerprint(self.prsm_design)

    @property
    def life_spec(self):
        """The parsed ``[life]`` table (:class:`~prsm_health.physics.life_spec.LifeSpec`), None without one."""
        if not self.life:
            return None
        from prsm_health.physics.life_spec import LifeSpec

        return LifeSpec.from_dict(self.life)

    def fleet(self) -> list:
        """The units' lives of a life recipe (:func:`prsm_health.physics.life.fleet_lives`), computed
        once per process and recipe."""
        key = self.fingerprint
        if key not in _FLEETS:
            from prsm_health.physics.life import fleet_lives
            from prsm_health.simulation.scenario import simulation_options

            variation = simulation_options(self.options).variation  # the units' build
            _FLEETS[key] = fleet_lives(self.prsm_design, self.life_spec, self.seed, variation)
        return _FLEETS[key]

    def _validate_units(self, check) -> None:
        units = self.units
        check(isinstance(units, dict), "units", units, "must be a table {count = …, seed = …}")
        if not units:
            return
        require_known_keys("units", units, ["count", "seed", "build"], error=RecipeError)
        build = units.get("build", {})
        check(isinstance(build, dict), "units.build", build, "must be a table of [min, max]")
        for key, value in build.items():
            nearest = nearest_key(key, UNIT_BUILD)
            check(
                key in UNIT_BUILD
                or key.split(".")[0] in ("options", "drive_train", "instrumentation"),
                f"units.build.{key}",
                value,
                ("" if nearest is None else f"did you mean {nearest!r}? ")
                + f"must be one of {', '.join(UNIT_BUILD)} or an options./drive_train./"
                "instrumentation. field (what a unit is built and installed with)",
            )
            check(is_range(value), f"units.build.{key}", value, "must be [min, max]")
        for key, minimum in (("count", 1), ("seed", 0)):
            value = units.get(key)
            check(
                isinstance(value, int) and not isinstance(value, bool) and value >= minimum,
                f"units.{key}",
                value,
                f"must be an integer ≥ {minimum}",
            )
        check(
            not self.life,
            "units",
            units,
            "a life recipe's fleet has its own units: leave [units] out",
        )

    def unit_build(self, unit: int) -> dict:
        """The ``[units.build]`` values of unit ``unit``: uniform in each range, each key drawn
        from the units' seed, the unit and the key alone — the same in every recipe with the
        same ``[units]`` seed that lists the key with the same range."""
        out = {}
        for key, (lo, hi) in self.units.get("build", {}).items():
            u = np.random.default_rng([self.units["seed"], unit, zlib.crc32(key.encode())]).random()
            out[key] = float(lo + u * (hi - lo))
        return out

    def unit_build_seed(self, unit: int) -> int:
        """The seed of unit ``unit`` as built (its manufacturing scatter) in a recipe with
        ``[units]``: the same for every recipe with the same ``units.seed``, so two recipes
        (say a baseline and a test) record the same units."""
        return int(np.random.SeedSequence([self.units["seed"], unit]).generate_state(1)[0])

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
        test = test_set(n_total, self.test_fraction, self.seed)
        if self.units:  # whole units held out
            count = self.units["count"]
            test_units = test_set(count, self.test_fraction, self.units["seed"])
            test = {i for i in range(n_total) if i % count in test_units}
        run_id = 0
        sweep = self.resolved_sweep
        drawn = {k: v["uniform"] for k, v in sweep.items() if isinstance(v, dict)}
        for point in points:
            for _ in range(repeats):
                seed = int(np.random.SeedSequence([self.seed, run_id]).generate_state(1)[0])
                run_point = dict(point)
                if drawn:
                    # grid keys given as {uniform = [min, max]}: a fresh value for every run
                    unit = np.random.default_rng([self.seed, run_id, 0x44524157]).random(len(drawn))
                    for u, (k, (lo, hi)) in zip(unit, sorted(drawn.items())):
                        run_point[k] = float(lo + u * (hi - lo))
                if self.units:  # what the unit is built with, the same in each of its runs
                    run_point.update(self.unit_build(run_id % self.units["count"]))
                specs.append(
                    RunSpec(self, run_id, run_point, seed, "test" if run_id in test else "train")
                )
                run_id += 1
        return specs

    def _life_runs(self) -> list[RunSpec]:
        # Unit-major: unit u's recordings are runs u·n … u·n + n − 1 (n = snapshots ×
        # recordings; the j-th recording at the k-th age is run u·n + k·recordings + j). The
        # unit as built (its manufacturing variation and roller wear pattern) is its seed, the
        # same in each of its runs; each run draws its own recording conditions and sensor
        # noise (sensor_seed). The test split holds out whole units.
        spec = self.life_spec
        test_units = test_set(spec.units, self.test_fraction, self.seed)
        keys = swept_keys(self.sweep)
        sweep = self.resolved_sweep
        specs = []
        for unit in self.fleet():
            for k, age in enumerate(unit.snapshot_ages(spec.snapshots)):
                for j in range(spec.recordings):
                    run_id = (unit.unit_id * spec.snapshots + k) * spec.recordings + j
                    draw = np.random.default_rng([self.seed, run_id, 0x534E4150]).random(len(keys))
                    point = {
                        key: float(sweep[key][0] + u * (sweep[key][1] - sweep[key][0]))
                        for u, key in zip(draw, keys)
                    }
                    point.update(unit_id=unit.unit_id, age_hours=float(age))
                    seed = int(np.random.SeedSequence([self.seed, run_id]).generate_state(1)[0])
                    split = "test" if unit.unit_id in test_units else "train"
                    specs.append(RunSpec(self, run_id, point, seed, split))
        return specs

    def _points(self) -> list[dict]:
        sweep = self.resolved_sweep
        keys = swept_keys(sweep)
        mode = sweep.get("mode", "grid")
        cases = sweep.get(FAULT_CASE_KEY)
        if mode == "grid":
            keys = [k for k in keys if not isinstance(sweep[k], dict)]
            if cases:
                keys.append(FAULT_CASE_KEY)
            values = [sweep[k] for k in keys]
            return [dict(zip(keys, combo)) for combo in itertools.product(*values)]
        n = sweep["samples"]
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
                lo, hi = sweep[k]
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
        # no swept or [profile] load: the scenario's default share of the design's rating
        profile = {"duration": r.duration, "speed": p.get("speed", 100.0)}
        profile.update(r.profile)
        for key in ("load", "load_amplitude", "temperature"):
            if key in p:
                profile[key] = p[key]
        if r.units:
            # recordings of a few units: run i records unit i mod count as built (its
            # manufacturing scatter; its [units.build] values are in the run's point); each
            # run's sensors draw their own noise
            build = r.unit_build_seed(self.run_id % r.units["count"])
            return self._build(health, profile, seed=build, sensor_seed=self.seed)
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
                set_path(groups[group], path, value)
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
            "temperature": unit.temperature,
        }
        profile.update(r.profile)
        for key in ("load", "load_amplitude", "temperature"):
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

    def labels(self, *, scenario: Scenario | None = None, run: Run | None = None) -> dict:
        """The run's labels: id, split, fault class, the scenario's labels (nominal values) and,
        given the simulated run, its realised clearances, samples and, for a health check, its
        phases (``check_phases``, JSON of :meth:`CheckPhases.as_record
        <prsm_health.core.check_phases.CheckPhases.as_record>`).

        ``scenario``: this run's :meth:`scenario`, when the caller has built it already (the
        generator, which simulates it); default: built here."""
        scenario = self.scenario() if scenario is None else scenario
        out = {
            "run_id": self.run_id,
            "split": self.split,
            "fault_class": self.recipe.faults.classify(scenario.health),
            "fault_case": self.point.get(FAULT_CASE_KEY, NO_FAULT),
            "severity": self.point.get("severity", 1.0),
            **scenario.labels(),
            # the design's name is for people; this says which design the run is of
            "design_fingerprint": self.recipe.design_fingerprint,
            # domain-randomised fields, under their dotted names
            **{k: v for k, v in self.point.items() if "." in k},
        }
        unit = self.unit()
        if unit is not None:
            out.update(unit.labels(self.point["age_hours"]))
        if self.recipe.units:
            out["unit_id"] = self.run_id % self.recipe.units["count"]
            out["units_seed"] = self.recipe.units["seed"]
        if run is not None:
            out.update({k: v for k, v in run.labels.items() if "_realised_" in k})
            out["n_samples"] = len(run)
            if run.check is not None:  # one JSON cell per run
                out["check_phases"] = json.dumps(run.check.as_record())
        return out


def load_recipe(path: str | Path) -> Recipe:
    """Parse and validate a TOML recipe; errors name the key."""
    path = Path(path)
    return Recipe.from_dict(read_toml(path, "recipe file", RecipeError), base=path.parent)


def _recipe_design(design, base: Path | None) -> str | dict:
    """A preset name as is; a design file or dict as the validated design's dict form."""
    try:
        return design_reference(design, base=base)
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
