"""prsm_health — physics-based signals and health diagnostics for planetary roller screws.

Public API (SI units throughout):

- designs: :func:`preset`, :class:`PRSMDesign`
- kinematics: :func:`speed_ratios`, :func:`characteristic_frequencies`
- static stiffness: :mod:`prsm_health.stiffness` (gear mesh, thread/axial, electric cylinder)
- dynamics: :func:`simulate` (design, health, profile, sensors, seed) → :class:`Run`
- validation against the papers: :func:`prsm_health.validation.collect`
"""

from .design import PRESETS, GearGeometry, MassProperties, Material, PRSMDesign, preset
from .dynamics.model import SimulationOptions
from .dynamics.simulate import SimulationError, simulate
from .errors import ParameterError, PRSMHealthError
from .kinematics import characteristic_frequencies, speed_ratios
from .run import Run
from .sensors import SensorModel
from .states import HealthState, ManufacturingVariation, OperatingProfile

__version__ = "0.1.0"

__all__ = [
    "PRESETS",
    "GearGeometry",
    "HealthState",
    "ManufacturingVariation",
    "OperatingProfile",
    "Run",
    "SensorModel",
    "SimulationError",
    "SimulationOptions",
    "MassProperties",
    "Material",
    "PRSMDesign",
    "ParameterError",
    "PRSMHealthError",
    "__version__",
    "characteristic_frequencies",
    "preset",
    "simulate",
    "speed_ratios",
]
