"""prsm_health — physics-based signals and health diagnostics for planetary roller screws.

Public API (SI units throughout), imported lazily so ``import prsm_health`` stays fast:

- designs and states: :func:`preset`, :class:`PRSMDesign`, :class:`HealthState`,
  :class:`OperatingProfile`, :class:`SimulationOptions`, :class:`Scenario`
- instrumentation: :class:`Instrumentation`, :func:`load_instrumentation`,
  :func:`list_profiles` (built-in sensor profiles: ideal, lab-rig, flight-ema, minimal)
- kinematics: :func:`speed_ratios`, :func:`characteristic_frequencies`, :func:`defect_frequencies`
- simulation: :func:`simulate` (design, health, profile, instrumentation, seed) → :class:`Run`
- data: :class:`Dataset`, :func:`read_mcap`, :func:`write_mcap`, :func:`read_recording`
- diagnostics: :func:`extract_features`, :func:`load_model` (a diagnosis model bundle),
  :func:`diagnose` → :class:`Diagnosis`
- ageing and prognostics: :class:`LifeSpec`, :func:`fleet_lives` (wear, lubricant ageing and
  fatigue over operating hours), :func:`diagnose_runs`, :func:`fleet_histories`,
  :class:`RULModel`, :func:`load_prognostics_model`, :func:`read_history`,
  :func:`prognose` → :class:`Prognosis`
- static stiffness: :mod:`prsm_health.physics.stiffness`; validation: :func:`prsm_health.validation.collect`
"""

from __future__ import annotations

from importlib import import_module

#: The layers, lowest first: each is a folder of this package, and a module imports only from
#: its own layer and those below it (docs/architecture.md; tests/test_architecture.py checks it).
LAYERS = (
    "core",
    "actuator",
    "physics",
    "simulation",
    "signals",
    "io",
    "datasets",
    "diagnostics",
    "monitoring",
    "training",
    "prognostics",
    "release",
    "validation",
    "apps",
)

#: Public name → module that defines it (relative to the package).
_EXPORTS = {
    "__version__": ".core.version",
    "PRESETS": ".actuator.design",
    "GearGeometry": ".actuator.design",
    "MassProperties": ".actuator.design",
    "Material": ".actuator.design",
    "PRSMDesign": ".actuator.design",
    "preset": ".actuator.design",
    "HealthState": ".actuator.states",
    "ManufacturingVariation": ".actuator.states",
    "Spall": ".actuator.faults",
    "PreloadLoss": ".actuator.faults",
    "OperatingProfile": ".actuator.states",
    "Instrumentation": ".simulation.instrumentation",
    "list_profiles": ".simulation.instrumentation",
    "load_instrumentation": ".simulation.instrumentation",
    "SimulationOptions": ".simulation.dynamics.model",
    "Scenario": ".simulation.scenario",
    "simulate": ".simulation.scenario",
    "Run": ".core.run",
    "characteristic_frequencies": ".physics.kinematics",
    "defect_frequencies": ".physics.kinematics",
    "speed_ratios": ".physics.kinematics",
    "ParameterError": ".core.errors",
    "PRSMHealthError": ".core.errors",
    "SimulationError": ".core.errors",
    "Dataset": ".datasets",
    "read_mcap": ".io.mcap",
    "write_mcap": ".io.mcap",
    "read_recording": ".io",
    "extract_features": ".signals.features",
    "Diagnosis": ".diagnostics.diagnosis",
    "diagnose": ".diagnostics.diagnosis",
    "diagnose_runs": ".diagnostics.diagnosis",
    "LifeSpec": ".physics.life",
    "fleet_lives": ".physics.life",
    "Prognosis": ".prognostics",
    "RULModel": ".prognostics",
    "fleet_histories": ".prognostics",
    "load_prognostics_model": ".prognostics",
    "prognose": ".prognostics",
    "read_history": ".prognostics",
}
#: Public names that differ from the defining module's name for them.
_ALIASES = {
    "load_model": (".diagnostics.diagnosis", "load_bundle"),
}

__all__ = sorted([*_EXPORTS, *_ALIASES])


def __getattr__(name: str):
    if name in _EXPORTS:
        module, attr = _EXPORTS[name], name
    elif name in _ALIASES:
        module, attr = _ALIASES[name]
    else:
        raise AttributeError(f"module 'prsm_health' has no attribute {name!r}")
    value = getattr(import_module(module, __name__), attr)
    globals()[name] = value  # next access skips this hook
    return value


def __dir__():
    return __all__
