"""Scenario: the one object a simulated run is built from, and its labels.

A :class:`Scenario` gathers the parameter groups by lifetime — design, health state, operating
profile, instrumentation, simulation options — and the seed. The CLI (``prsm-health simulate``), dataset
recipes (one scenario per run) and the Python API all build it here, from keyword objects or from
a nested dict / TOML table, so defaults and validation live in one place; its :meth:`labels`
are the run labels of the contract (docs/formats.md).

The dict form (and the TOML form, the same tables)::

    design = "paper01"                       # preset name or design TOML file (relative to the
                                             # scenario file), or a [design] table (design files)
    instrumentation = "flight-ema"           # profile name or profile TOML file (relative to the
                                             # scenario file), or an [instrumentation] table
    seed = 3
    [health]   clearance = 20e-6             # shorthand for screw, nut and gear; or each field
    [[health.faults]]  kind = "spall", location = "screw", depth = 20e-6   (prsm_health.actuator.faults)
    [profile]  duration = 0.5, speed = 100.0, load = "20 % C_a", …   (OperatingProfile fields)
    [options]  contact_law = "hertz", ideal = true, …           (SimulationOptions fields)
    [drive_train]  payload_mass = 25.0, …                       (DriveTrain fields)

The ``[instrumentation]`` table holds ``profile = "flight-ema"`` plus overrides (``sample_rate``,
``[instrumentation.nut_axial_accel] noise_density_ug = 40``, ``fitted = false``), or a complete
profile (:func:`prsm_health.simulation.instrumentation.load_instrumentation`). TOML cannot give
``instrumentation`` both as a string and as a table.

Loads (``[profile] load``, ``load_amplitude``) are newtons, a number with a unit (``"4.4 kN"``)
or a share of the design's basic axial load ratings (``"20 % C_a"``, ``"5 % C_0a"``;
:mod:`prsm_health.core.quantities`, :mod:`prsm_health.physics.load_rating`). A scenario resolves
them against its design on construction — its ``profile`` holds newtons — and refuses a peak load
(|load| plus the swing) above the static rating C_0a. Without a load the run is at
:data:`~prsm_health.actuator.states.DEFAULT_LOAD_SHARE` of C_a (20 %, a service load of an
electromechanical actuator); a light-load run gives its load (``load = "2 % C_a"``).
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from prsm_health.actuator.design import DEFAULT_PRESET, PRESETS, PRSMDesign, preset
from prsm_health.actuator.design_files import design_fingerprint, design_toml_tables, load_design
from prsm_health.actuator.drive_train import DriveTrain, duty_check, load_drive_train
from prsm_health.actuator.faults import fault_as_dict
from prsm_health.actuator.states import HealthState, ManufacturingVariation, OperatingProfile
from prsm_health.core.errors import ParameterError, require, require_known_keys
from prsm_health.core.operating_point import OperatingPoint
from prsm_health.core.run import Run
from prsm_health.core.tomlfile import read_toml, toml_value
from prsm_health.physics.load_rating import load_ratings

from .dynamics.model import SimulationOptions
from .dynamics.simulate import simulate_scenario
from .instrumentation import (
    DEFAULT_PROFILE,
    Instrumentation,
    instrumentation_ref,
    list_profiles,
    load_instrumentation,
)
from .recirculating.scenario_run import simulate_recirculating_scenario


def design_ratings(design: PRSMDesign) -> dict[str, float]:
    """``{"C_a": …, "C_0a": …}`` [N]: the basic dynamic and static axial load ratings of
    ``design`` (:func:`~prsm_health.physics.load_rating.load_ratings`, computed once per design
    and process)."""
    ratings = load_ratings(design)
    return {"C_a": float(ratings.dynamic), "C_0a": float(ratings.static)}


_GROUPS = {
    "health": HealthState,
    "profile": OperatingProfile,
    "options": SimulationOptions,
    "drive_train": DriveTrain,
}


@dataclass(frozen=True)
class Scenario:
    """Everything that determines a simulated run.

    Parameters
    ----------
    design : PRSMDesign, preset name, design TOML file or dict form, default "paper01"
    health : HealthState
    profile : OperatingProfile
        Resolved against the design's load ratings on construction: ``scenario.profile`` holds
        its loads in newtons. Default: ``OperatingProfile()``, whose load is
        :data:`~prsm_health.actuator.states.DEFAULT_LOAD_SHARE` (20 %) of C_a.
    instrumentation : Instrumentation, profile name, profile file or dict form, default "flight-ema"
    options : SimulationOptions
    seed : int
        Seeds manufacturing variation, uneven wear and sensor errors (same seed, same run).
    drive_train : DriveTrain
        Motor, coupling, thrust bearing, linkage and payload (default: a flight EMA).
    sensor_seed : int or None
        Seeds the sensors' noise and errors instead of ``seed`` (None: ``seed``). The
        snapshots of one unit over its life (:mod:`prsm_health.physics.life`) share ``seed`` — the
        unit as built — and each draws its own sensor noise.
    """

    design: PRSMDesign = field(default_factory=preset)
    health: HealthState = field(default_factory=HealthState)
    profile: OperatingProfile = field(default_factory=OperatingProfile)
    instrumentation: Instrumentation = field(
        default_factory=lambda: load_instrumentation(DEFAULT_PROFILE)
    )
    options: SimulationOptions = field(default_factory=SimulationOptions)
    seed: int = 0
    drive_train: DriveTrain = field(default_factory=DriveTrain)
    sensor_seed: int | None = None

    def __post_init__(self):
        if not isinstance(self.design, PRSMDesign):
            object.__setattr__(self, "design", load_design(self.design))
        if not isinstance(self.instrumentation, Instrumentation):
            object.__setattr__(self, "instrumentation", load_instrumentation(self.instrumentation))
        require(
            isinstance(self.seed, int) and not isinstance(self.seed, bool) and self.seed >= 0,
            "seed",
            self.seed,
            "must be an integer ≥ 0",
        )
        require(
            self.sensor_seed is None
            or (
                isinstance(self.sensor_seed, int)
                and not isinstance(self.sensor_seed, bool)
                and self.sensor_seed >= 0
            ),
            "sensor_seed",
            self.sensor_seed,
            "must be an integer ≥ 0 (or absent: the seed's)",
        )
        for fault in self.health.faults:
            require(
                self.design.variant in fault.variants,
                "faults.kind",
                fault.kind,
                f"is a fault of the {' or '.join(fault.variants)} PRSM, not of this "
                f"{self.design.variant} design",
            )
        self._resolve_loads()

    def _resolve_loads(self) -> None:
        """The profile's loads in newtons against the design's ratings; a peak above C_0a
        refused; the duty checked against the drive train's motor (torque and speed)."""
        require(
            isinstance(self.profile, OperatingProfile),
            "profile",
            type(self.profile).__name__,
            "must be an OperatingProfile (or, in the dict form, a [profile] table)",
        )
        ratings = design_ratings(self.design)
        profile = self.profile.resolved(ratings)
        peak = profile.peak_load
        if peak > ratings["C_0a"]:
            given = self.profile.load
            text = given.text() if hasattr(given, "text") else f"{given:g} N"
            raise ParameterError(
                "profile.load",
                text,
                f"the peak axial load (|load| + load_amplitude) is {peak:.4g} N, above the "
                f"static load rating C_0a = {ratings['C_0a']:.4g} N of design "
                f"'{self.design.name}' (permanent deformation of the threads: ISO 76); lower "
                "the load or its swing",
            )
        object.__setattr__(self, "profile", profile)
        # The duty against the drive train's motor (torque, speed): a duty beyond the motor's
        # continuous torque is a warning, one it cannot run at all an error (the user's).
        for message in duty_check(
            self.drive_train, self.design, peak, profile.top_speed, continuous_load=profile.rms_load
        ):
            warnings.warn(message, stacklevel=3)

    @property
    def sensors_seed(self) -> int:
        """The seed of the sensors' noise and errors."""
        return self.seed if self.sensor_seed is None else self.sensor_seed

    # ------------------------------------------------------------------ dict / TOML
    @classmethod
    def from_dict(cls, data: dict, *, base: Path | None = None) -> Scenario:
        """Build from the nested dict form (module docstring); errors name the table and key.

        ``design`` is a preset name, a design TOML file (relative paths against ``base``, else
        the working directory), the dict form of :meth:`PRSMDesign.to_dict` or a design;
        ``instrumentation`` likewise a profile name, a profile file or a table (module docstring).
        """
        data = dict(data)
        if "sensors" in data:
            raise ParameterError(
                "scenario.sensors",
                data["sensors"],
                "the [sensors] table was replaced by instrumentation profiles: write "
                f'instrumentation = "{DEFAULT_PROFILE}" (built-ins: '
                f"{', '.join(list_profiles())}) or an [instrumentation] table with profile = … "
                "and overrides (docs/instrumentation.md)",
            )
        require_known_keys(
            "scenario", data, ["design", "instrumentation", "seed", "sensor_seed", *_GROUPS]
        )
        groups = {name: _group(name, kind, data.get(name, {})) for name, kind in _GROUPS.items()}
        design = load_design(data.get("design", DEFAULT_PRESET), base=base)
        instrumentation = load_instrumentation(
            data.get("instrumentation", DEFAULT_PROFILE), base=base
        )
        return cls(
            design=design,
            instrumentation=instrumentation,
            seed=data.get("seed", 0),
            sensor_seed=data.get("sensor_seed"),
            **groups,
        )

    @classmethod
    def from_toml(cls, path: str | Path) -> Scenario:
        """Read a scenario file (the dict form as TOML tables)."""
        path = Path(path)
        return cls.from_dict(read_toml(path, "scenario file"), base=path.parent)

    def to_dict(self) -> dict:
        """The nested dict form, as stored with every run (``Run.scenario``).

        ``design`` and ``instrumentation`` are the built-in names when unmodified, else the
        full dict forms.
        """
        return {
            "design": self.design_ref(),
            "instrumentation": instrumentation_ref(self.instrumentation),
            "health": self.health.as_dict(),
            "profile": self.profile.as_dict(),
            "options": self.options.as_dict(),
            "drive_train": self.drive_train.as_dict(),
            "seed": self.seed,
            **({} if self.sensor_seed is None else {"sensor_seed": self.sensor_seed}),
        }

    def design_ref(self) -> str | dict:
        """The preset name if the design is an unmodified preset, else its full dict form."""
        name = self.design.name
        if name in PRESETS and self.design == preset(name):
            return name
        return self.design.to_dict()

    def to_toml(self) -> str:
        """TOML text that :meth:`from_toml` reads back to an equal scenario."""
        data = self.to_dict()
        design = data.pop("design")
        instrumentation = data.pop("instrumentation")
        lines = [f"seed = {data.pop('seed')}"]
        if "sensor_seed" in data:
            lines.append(f"sensor_seed = {data.pop('sensor_seed')}")
        if isinstance(instrumentation, str):
            lines.insert(0, f"instrumentation = {toml_value(instrumentation)}")
        if isinstance(design, str):
            lines.insert(0, f"design = {toml_value(design)}")
        options = data["options"]
        variation = options.pop("variation")
        faults = data["health"].pop("faults")
        for table, values in data.items():
            lines.append(f"\n[{table}]")
            lines += [f"{k} = {toml_value(v)}" for k, v in values.items() if v is not None]
        lines.append("\n[options.variation]")
        lines += [f"{k} = {toml_value(v)}" for k, v in variation.items()]
        for fault in faults:
            lines.append("\n[[health.faults]]")
            lines += [f"{k} = {toml_value(v)}" for k, v in fault.items()]
        if not isinstance(design, str):
            lines += [""] + design_toml_tables(self.design, "design")
        if not isinstance(instrumentation, str):
            lines += [""] + self.instrumentation.toml_tables("instrumentation")
        return "\n".join(lines) + "\n"

    # ------------------------------------------------------------------ labels
    def operating_point(self) -> OperatingPoint:
        """The design, reduction and nominal conditions a run of this scenario carries
        (:attr:`Run.operating <prsm_health.core.run.Run.operating>`)."""
        p = self.profile
        # a health check has no one operating point: its top speed and its peak load
        check = getattr(p, "check", None)
        return OperatingPoint(
            design=self.design.name,
            # the name is for people; the fingerprint says which design the run is of
            design_fingerprint=design_fingerprint(self.design),
            # the drive torque is the motor's: N between it and the screw (features need it)
            gear_ratio=self.drive_train.gear_ratio,
            screw_speed=p.top_speed if check else p.speed,
            axial_load=p.peak_load if check else p.load,
            load_amplitude=0.0 if check else p.load_amplitude,
            temperature=p.temperature,
        )

    def labels(self) -> dict:
        """Run labels of the contract: nominal health and operating point (SI) — the operating
        point's fields (:meth:`operating_point`) under their own names, so a dataset's table
        holds them beside the health."""
        h, p = self.health, self.profile
        check = getattr(p, "check", None)
        operating = self.operating_point()
        return {
            "design": operating.design,
            "design_fingerprint": operating.design_fingerprint,
            "clearance_screw": h.clearance_screw,
            "clearance_nut": h.clearance_nut,
            "clearance_gear": h.clearance_gear,
            "wear_spread": h.wear_spread,
            "friction_scale": h.friction_scale,
            "lubricant_degradation": h.lubricant_degradation,
            "lubricant_starvation": h.lubricant_starvation,
            "preload": h.preload,
            "preload_effective": h.effective_preload,
            # kinds joined by "+" ("" for none) to group by, and the faults themselves as a
            # JSON text, so a dataset's labels table keeps one scalar per cell
            "fault_kinds": "+".join(sorted({f.kind for f in h.faults})),
            "faults": json.dumps([fault_as_dict(f) for f in h.faults]),
            "screw_speed": operating.screw_speed,
            "axial_load": operating.axial_load,
            "load_amplitude": operating.load_amplitude,
            # the peak load as a share of the design's dynamic rating: how hard the run works
            "load_share": p.peak_load / design_ratings(self.design)["C_a"],
            "motion": "check" if check else p.motion,
            "load_profile": "check" if check else p.load_profile,
            "check": check.name if check else "",
            "gear_ratio": operating.gear_ratio,
            "duration": p.duration,
            "temperature": operating.temperature,
            "seed": self.seed,
            "sensor_seed": self.sensors_seed,
        }

    def simulate(self, *, progress: bool = False) -> Run:
        """Simulate this scenario (:func:`simulate`) → :class:`~prsm_health.core.run.Run`."""
        return _simulate(self, progress)


def _simulate(scenario: Scenario, progress: bool) -> Run:
    """The scenario through the model of its design's variant: the standard PRSM's lumped
    dynamics, or the recirculating PRSM's (paper 03: no gears)."""
    if scenario.design.variant == "recirculating":
        return simulate_recirculating_scenario(scenario, progress=progress)
    return simulate_scenario(scenario, progress=progress)


def simulation_options(values) -> SimulationOptions:
    """The :class:`SimulationOptions` of a scenario's or recipe's ``[options]`` table."""
    return _group("options", SimulationOptions, values)


def _group(name: str, kind: type, values) -> object:
    """One parameter group from its table; unknown keys name the table and list the allowed."""
    if isinstance(values, kind):
        return values
    if kind is HealthState:
        return HealthState.from_dict(values, name)
    if kind is DriveTrain:  # a name, a drive-train file or a table of fields
        return load_drive_train(values)
    if not isinstance(values, dict):
        raise ParameterError(name, values, "must be a table of parameters")
    values = dict(values)
    if kind is SimulationOptions:
        if values.pop("ideal", False):
            values["variation"] = ManufacturingVariation.ideal()
        elif isinstance(values.get("variation"), dict):
            values["variation"] = _group(
                "options.variation", ManufacturingVariation, values["variation"]
            )
    allowed = [f.name for f in fields(kind)]
    if kind is SimulationOptions:
        allowed.append("ideal")
    require_known_keys(name, values, allowed)
    return kind(**values)


def simulate(
    design: PRSMDesign | str | None = None,
    health: HealthState | None = None,
    profile: OperatingProfile | None = None,
    instrumentation: Instrumentation | str | None = None,
    seed: int = 0,
    *,
    options: SimulationOptions | None = None,
    drive_train: DriveTrain | None = None,
    progress: bool = False,
) -> Run:
    """Simulate a PRSM run and return what its instrumentation measures.

    Parameters
    ----------
    design : PRSMDesign or preset name, default "paper01"
    health : HealthState, default HealthState()
    profile : OperatingProfile, default OperatingProfile()
        Its loads may be shares of the design's ratings (``load="20 % C_a"``); the default
        runs at :data:`~prsm_health.actuator.states.DEFAULT_LOAD_SHARE` (20 %) of C_a.
    instrumentation : Instrumentation, profile name or profile TOML file, default "flight-ema"
        The sensors fitted and the sample rate (:mod:`prsm_health.simulation.instrumentation`).
    seed : int
        Seeds manufacturing variation, uneven wear and sensor noise: same seed, same run
        (bit-identical).
    options : SimulationOptions
    drive_train : DriveTrain, default DriveTrain()
        Motor, coupling, thrust bearing, linkage and payload (``DriveTrain.paper01()`` for the
        paper's rigid drive and ideal force on the nut).
    progress : bool
        Show a progress bar (long runs).

    Returns
    -------
    Run
        The fitted measured channels at ``instrumentation.sample_rate``; ``run.truth`` holds
        the truth signals on the same time axis (anti-alias decimated, no sensor errors),
        ``run.energy`` the energy book.

    Raises
    ------
    SimulationError
        When the requested step is beyond the RK4 stability limit of the model, or the state
        becomes non-finite (the error names the time).
    ParameterError
        For any invalid input, a load share without a rating, or a peak load above the
        design's static rating C_0a.
    """
    require(
        isinstance(seed, (int, np.integer)) and seed >= 0, "seed", seed, "must be an integer ≥ 0"
    )
    scenario = Scenario(
        design=design or DEFAULT_PRESET,
        health=health or HealthState(),
        profile=profile or OperatingProfile(),
        instrumentation=instrumentation or DEFAULT_PROFILE,
        options=options or SimulationOptions(),
        seed=int(seed),
        drive_train=drive_train or DriveTrain(),
    )
    return _simulate(scenario, progress)
