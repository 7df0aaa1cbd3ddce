"""prsm_health — physics-based signals and health diagnostics for planetary roller screws.

Public API (SI units throughout):

- designs: :func:`preset`, :class:`PRSMDesign`
- kinematics: :func:`speed_ratios`, :func:`characteristic_frequencies`
- static stiffness: :mod:`prsm_health.stiffness` (gear mesh, thread/axial, electric cylinder)
- validation against the papers: :func:`prsm_health.validation.collect`
"""

from .design import PRESETS, GearGeometry, MassProperties, Material, PRSMDesign, preset
from .errors import ParameterError, PRSMHealthError
from .kinematics import characteristic_frequencies, speed_ratios

__version__ = "0.1.0"

__all__ = [
    "PRESETS",
    "GearGeometry",
    "MassProperties",
    "Material",
    "PRSMDesign",
    "ParameterError",
    "PRSMHealthError",
    "__version__",
    "characteristic_frequencies",
    "preset",
    "speed_ratios",
]
