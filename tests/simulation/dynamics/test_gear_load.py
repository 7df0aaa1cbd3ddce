"""The gears' real load: rollers roll on screw and nut, so a pitch mismatch ε between the gear ratio
and the nut–roller rolling ratio loads the gear (Jones & Velinsky 2012) until the nut traction
slips. Short runs (0.05 s after the 0.03 s settling) of paper01 at 2 kN, 100 rad/s.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from prsm_health import (
    HealthState,
    ManufacturingVariation,
    OperatingProfile,
    SimulationOptions,
    preset,
    simulate,
)
from prsm_health.actuator.drive_train import DriveTrain
from prsm_health.simulation.dynamics import _kernels
from prsm_health.simulation.dynamics import layout as L
from prsm_health.simulation.dynamics.model import build_model
from prsm_health.simulation.dynamics.simulate import (
    integration_step,
    max_stable_step,
    settled_state,
)

DESIGN = preset("paper01")
LOAD = 2000.0
MU = 0.1  # constant Coulomb coefficient, so the Coulomb limit is known
OPTIONS = SimulationOptions(
    variation=ManufacturingVariation.ideal(), lubrication="constant", friction_coefficient=MU
)


def _forces(mismatch: float, duration: float = 0.05) -> dict[str, np.ndarray]:
    # As simulate(), reading each roller's gear force and tractions every 50 µs.
    profile = OperatingProfile(duration=duration, speed=100.0, load=LOAD)
    model = build_model(DESIGN, HealthState(), profile, OPTIONS, 0)
    rollers = model.rollers.copy()
    rollers[:, L.R_ROLL_N] = DESIGN.roller_diameter / 2 / (1.0 + mismatch)
    rollers[:, L.R_MISMATCH] = mismatch
    model = replace(model, rollers=rollers)
    h_stable, f_max = max_stable_step(model)
    h, factor = integration_step("auto", h_stable, f_max, 20_000.0)
    y = settled_state(model, h, OPTIONS.settle_time)
    n = model.n_rollers
    work = [np.empty(model.n_state) for _ in range(5)]
    aux = np.zeros(L.n_aux(n))
    raw = np.empty((1, L.N_CHANNELS))
    rows = []
    for k in range(int(duration * 20_000)):
        status, _ = _kernels.integrate(
            y, k * factor * h, h, factor, factor + 1, model.params, model.rollers,
            model.mesh_table, model.motion, model.load_knots, model.errors, raw, *work, aux,
        )  # fmt: skip
        assert status == 0
        rows.append(aux[L.N_AUX :].reshape(L.N_AUX_PER_ROLLER, n).copy())
    out = np.array(rows)
    return {
        "gear": out[:, L.AR_GEAR],
        "cap_n": out[:, L.AR_CAP_N],
        "traction_n": out[:, L.AR_TRACTION_N],
        "creep": model.rollers[0, L.R_K_TAN_N] / model.rollers[0, L.R_RELAX_N],
    }


#: μN of one roller's nut side and the spin torque of its axial sliding on the screw over the
#: roller gear's base radius: the gear force the roller carries at ε = 0 (see test below).
NORMAL = LOAD / DESIGN.n_rollers / math.sin(DESIGN.contact_angle)
COS_A = math.cos(DESIGN.gear.pressure_angle)
BASELINE = MU * NORMAL * DESIGN.roller_lead / (2 * math.pi) / (DESIGN.roller_diameter / 2 * COS_A)


def test_zero_mismatch_gear_carries_only_the_axial_sliding_torque():
    # With ε = 0 and identical rollers the threads roll at the gear's ratio: the nut traction
    # carries nothing and the gear only the roller spin torque μN·L_r/2π that paper 02's axial
    # sliding of the roller on the screw puts on it through the helix (≈ 1.5 % of the roller's
    # axial load). 30 % margin: the regularised sliding law (tanh) and the unequal axial loads of
    # the two thread sides move it by a few per cent.
    f = _forces(0.0)
    per_roller = LOAD / DESIGN.n_rollers
    gear = np.mean(f["gear"], axis=0)
    assert np.all(np.abs(gear) <= 1.3 * BASELINE)
    assert np.all(np.abs(gear) <= 0.03 * per_roller)
    assert np.all(np.abs(np.mean(f["traction_n"], axis=0)) <= 0.02 * MU * NORMAL)


def test_gear_load_grows_with_mismatch_and_saturates_when_the_nut_slips():
    base = np.mean(_forces(0.0)["gear"])
    added, slipping = {}, {}
    for eps in (1e-4, 3e-4, 3e-3, 1e-2):
        f = _forces(eps)
        added[eps] = np.mean(f["gear"]) - base
        slipping[eps] = float(np.mean(np.abs(f["traction_n"]) >= 0.99 * f["cap_n"]))
        creep = f["creep"]
    # grows with ε …
    assert 0 < added[1e-4] < added[3e-4] < added[3e-3] <= added[1e-2] * 1.02
    # … linearly while the traction sticks: Kalker's creep force k·L·ε over cos α0 (25 %: the
    # gear's share of the roller's spin torque moves with its flank contact)
    assert added[3e-4] == pytest.approx(creep * 3e-4 / COS_A, rel=0.25)
    assert slipping[3e-4] == 0.0
    # … and saturates at the Coulomb limit μN/cos α0 once the roller slips on the nut
    assert slipping[1e-2] > 0.5
    assert added[1e-2] == pytest.approx(MU * NORMAL / COS_A, rel=0.15)
    assert added[1e-2] - added[3e-3] < 0.15 * added[1e-2]


@pytest.mark.parametrize("load", [2000.0, 8000.0])
def test_energy_balance_with_nut_traction_and_mismatch(load):
    # As test_dynamics.test_energy_balance: drive = output + dissipated within 1 % at constant
    # speed and load; a 5 µm rolling-radius scatter (ε ≈ 1.5e-3) makes some rollers creep and
    # others slip on the nut, so both traction branches and the clamp do work. The automatic
    # step accounts for the nut traction's stiffness (2–8 kN: the step stays stable).
    options = SimulationOptions(
        variation=ManufacturingVariation(rolling_radius_error=5e-6), max_step="auto"
    )
    r = simulate(
        "paper01",
        HealthState(),
        OperatingProfile(duration=0.1, speed=100.0, load=load),
        "ideal",
        3,
        options=options,
        drive_train=DriveTrain.direct(),  # no motor limit: 8 kN is beyond the sized motor's
    )
    e = r.energy
    assert e["drive"] == pytest.approx(-e["load"] + e["dissipated"], rel=1e-2)
    assert e["dissipated"] >= 0 and e["friction"] >= 0
    assert all(np.all(np.isfinite(v)) for v in r.channels.values())
