"""Gear tooth damage (issue 12, item 2): crack and pit in the potential-energy mesh stiffness,
one damaged tooth in the mesh cycle, and the kernel reading it."""

import math

import numpy as np
import pytest

from prsm_health import HealthState, OperatingProfile, preset, simulate
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.actuator.faults import ToothCrack, ToothPit
from prsm_health.core.errors import ParameterError
from prsm_health.physics.stiffness.damaged_mesh import damaged_mesh
from prsm_health.physics.stiffness.gear_mesh import mesh_stiffness

DESIGN = preset("paper01")
#: An ordinary external steel pair (z 40/40, m 2 mm, 20°, 20 mm wide).
PAIR = dict(z1=40, z2=40, module=2e-3, pressure_angle=math.radians(20), face_width=20e-3)


@pytest.mark.parametrize("member", ["ring_gear", "roller_gear"])
def test_zero_damage_is_the_healthy_mesh(member):
    for fault in (ToothCrack(location=member, depth=0.0), ToothPit(location=member, depth=0.0)):
        mesh = damaged_mesh(DESIGN, fault, member)
        assert np.max(np.abs(mesh.ratio - 1.0)) < 1e-12


def test_crack_softens_the_pair_more_as_it_grows():
    healthy = mesh_stiffness(**PAIR).single_pair
    losses = []
    for depth in (0.5e-3, 1.0e-3, 1.5e-3, 2.0e-3):
        cracked = mesh_stiffness(**PAIR, pinion_damage=ToothCrack(depth=depth)).single_pair
        assert np.all(cracked <= healthy * (1 + 1e-12))
        losses.append(float(np.max(1 - cracked / healthy)))
    assert losses[0] > 0 and all(a < b for a, b in zip(losses, losses[1:])), losses


@pytest.mark.parametrize("member", ["ring_gear", "roller_gear"])
def test_one_damaged_tooth_in_the_cycle(member):
    mesh = damaged_mesh(DESIGN, ToothCrack(location=member), member)
    n = mesh.ratio.size // mesh.cycles
    in_contact = np.zeros(mesh.ratio.size, bool)
    in_contact[: mesh.healthy_single.size] = True
    assert np.all(mesh.ratio[~in_contact] == 1.0)
    assert mesh.ratio[in_contact].min() < 0.99  # the default 0.4 mm crack: a 2–8 % loss
    assert mesh.ratio.size == mesh.cycles * n
    assert np.all(mesh.ratio <= 1.0 + 1e-12)


def test_pit_only_acts_on_its_band():
    pit = ToothPit(location="ring_gear", offset=0.0, length=0.1e-3)
    mesh = damaged_mesh(DESIGN, pit, "ring_gear")
    loss = 1 - mesh.damaged_single / mesh.healthy_single
    # the band is 0.1 mm of radius around the pitch circle: a minority of the path
    assert 0 < np.mean(loss > 1e-3) < 0.5
    assert loss.max() > 0.05  # 40 % of the contact line gone where it lies


def test_bad_tooth_damage_names_the_field():
    with pytest.raises(ParameterError, match="faults.location"):
        ToothCrack(location="screw")
    with pytest.raises(ParameterError, match="faults.depth"):
        damaged_mesh(DESIGN, ToothCrack(depth=2e-3), "ring_gear")  # beyond the centreline
    with pytest.raises(ParameterError, match="faults.width"):
        ToothPit(width=1.0)
    with pytest.raises(ParameterError, match="faults.tooth"):
        simulate(health=HealthState(faults=(ToothCrack(tooth=65),)), profile=OperatingProfile(0.01))


@pytest.mark.slow
def test_kernel_reads_the_damaged_tooth_with_energy_balance():
    # Same seed, with and without a severe ring-tooth pit: the signals differ (the table is
    # read), and the energy book closes within 1 %. On the direct drive: the default
    # gearhead's own mesh line dominates the nut's tangential vibration (its signature is
    # the reduction's, not the PRSM's: docs/faults.md).
    profile = OperatingProfile(duration=0.2, load=300.0)
    pit = ToothPit(location="ring_gear", width=0.9, depth=0.2e-3, length=0.5e-3)
    direct = DriveTrain.direct()
    healthy = simulate("paper01", HealthState(), profile, "ideal", 4, drive_train=direct)
    damaged = simulate(
        "paper01", HealthState(faults=(pit,)), profile, "ideal", 4, drive_train=direct
    )
    difference = np.std(damaged["nut_tangential_accel"] - healthy["nut_tangential_accel"])
    assert difference > 0.1 * np.std(healthy["nut_tangential_accel"])
    e = damaged.energy
    assert e["drive"] == pytest.approx(-e["load"] + e["dissipated"], rel=1e-2)
