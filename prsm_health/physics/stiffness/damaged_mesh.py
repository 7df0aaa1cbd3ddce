"""The mesh of a roller gear in its ring with one damaged tooth (a crack or a pit), over the
engagement of that tooth: the total mesh stiffness while its pair is in contact, over the
healthy total. The damaged sections come from :mod:`.tooth_damage`, the mesh from
:mod:`.gear_mesh`.

References
----------
- X. Tian, "Dynamic simulation for system response of gearbox including localized gear
  faults", MSc thesis, University of Alberta, 2004, §3.
- X. Liang, M.J. Zuo, M.R. Hoseini, "Vibration signal modeling of a planetary gear set for
  tooth crack detection", Eng. Fail. Anal. 48 (2015) 185–200.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from prsm_health.core.errors import require

from .gear_mesh import design_mesh_stiffness


@dataclass(frozen=True)
class DamagedMesh:
    """Mesh stiffness over the engagement of one damaged tooth.

    Attributes
    ----------
    ratio : ndarray [-]
        Total mesh stiffness with the damaged tooth over the healthy total, ``cycles``·n_points
        samples, uniform in mesh phase; phase 0 is the damaged tooth's pair entering contact
        at the start of the active path (the phase convention of
        :class:`~prsm_health.physics.stiffness.gear_mesh.MeshStiffness`); 1 outside its contact.
    cycles : int
        Mesh cycles covered (the damaged pair is in contact for ``contact_ratio`` of them).
    healthy_single, damaged_single : ndarray [N/m]
        Single-pair stiffness along the path of contact, healthy and damaged.
    path_position : ndarray [m]
        Roll distance along the line of action of each single-pair sample.
    """

    ratio: np.ndarray
    cycles: int
    healthy_single: np.ndarray
    damaged_single: np.ndarray
    path_position: np.ndarray

    @property
    def largest_loss(self) -> float:
        """Largest relative loss of single-pair stiffness along the path [-]."""
        return float(np.max(1.0 - self.damaged_single / self.healthy_single))


def damaged_mesh(design, damage, member: str, *, threaded_tooth: bool = True, n_points: int = 400):
    """The mesh of a design's roller gear in its ring with one damaged tooth.

    Parameters
    ----------
    design : PRSMDesign
    damage : object with ``section`` and ``contact_share`` (e.g.
        :class:`prsm_health.actuator.faults.ToothCrack`, :class:`prsm_health.actuator.faults.ToothPit`)
    member : {"ring_gear", "roller_gear"}
        The gear that carries the damaged tooth.
    threaded_tooth, n_points
        As :func:`~prsm_health.physics.stiffness.gear_mesh.design_mesh_stiffness`.

    Returns
    -------
    DamagedMesh
    """
    require(
        member in ("ring_gear", "roller_gear"),
        "faults.location",
        member,
        "must be ring_gear or roller_gear for gear tooth damage",
    )
    healthy = design_mesh_stiffness(design, threaded_tooth=threaded_tooth, n_points=n_points)
    key = "ring_damage" if member == "ring_gear" else "roller_damage"
    damaged = design_mesh_stiffness(
        design, threaded_tooth=threaded_tooth, n_points=n_points, **{key: damage}
    )
    n_samples = healthy.single_pair.size
    cycles = -(-n_samples // n_points)
    index = np.arange(cycles * n_points)
    change = np.zeros(index.size)
    change[:n_samples] = damaged.single_pair - healthy.single_pair
    total = healthy.stiffness[index % n_points]
    return DamagedMesh(
        ratio=(total + change) / total,
        cycles=int(cycles),
        healthy_single=healthy.single_pair,
        damaged_single=damaged.single_pair,
        path_position=healthy.path_position,
    )
