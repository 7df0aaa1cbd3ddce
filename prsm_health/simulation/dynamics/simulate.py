"""Run orchestration: step choice, step guard, chunked RK4 integration, instrumentation, Run.

:func:`simulate` is the public entry point (re-exported as ``prsm_health.simulate``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from prsm_health.core.channels import TRUTH_NAMES
from prsm_health.core.errors import SimulationError
from prsm_health.core.run import Run

from ..decimation import decimate
from ..run_assembly import assemble_run, measure
from . import _kernels
from . import layout as L
from .model import (
    AUTO_MAX_STEP,
    AUTO_STABLE_FRACTION,
    Model,
    build_model,
    initial_state,
    realised_clearances,
)

#: RK4's stability limit on the imaginary axis is 2√2; keep a margin for the nonlinearity.
STABILITY_MARGIN = 0.9
#: A speed or position loop starts holding the drive torque averaged over this last part of the
#: settling [s]: many periods of the mesh and thread ripples that make the torque fluctuate
#: (kHz); a slower ripple (the carrier's revolution) is left to the loop to follow.
HANDOVER_TIME = 0.005


def _rk4_amplification(z: np.ndarray) -> np.ndarray:
    return np.abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24)


def linearised_eigenvalues(model: Model) -> np.ndarray:
    """Eigenvalues [1/s] of the model linearised on the loaded flanks at the operating load
    (:func:`linearised_modes`)."""
    return linearised_modes(model)[0]


def linearised_modes(model: Model) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """Eigenvalues [1/s], eigenvectors (columns) and the state indices they span, of the model
    linearised on the loaded flanks at the operating load (:func:`linearised_jacobian`)."""
    jac, free = linearised_jacobian(model)
    values, vectors = np.linalg.eig(jac)
    return values, vectors, free


def linearised_jacobian(model: Model) -> tuple[np.ndarray, list[int]]:
    """Jacobian ∂(dy/dt)/∂y [1/s] of the model linearised on the loaded flanks at the operating
    load, over the state indices it spans (returned with it).

    Clearances are closed and every roller carries the operating load on one flank of each
    thread and on the gear, so all contact stiffnesses act (at their tangent values for the
    Hertzian law): the stiffest state a run normally meets. Taken by central differences of the
    kernel's right-hand side; the prescribed screw angle is not a state.
    """
    nq = model.n_coordinates
    rollers = model.rollers.copy()
    # clearances closed, interference (preload) kept
    rollers[:, L.R_B_S] = np.minimum(rollers[:, L.R_B_S], 0.0)
    rollers[:, L.R_B_N] = np.minimum(rollers[:, L.R_B_N], 0.0)
    rollers[:, L.R_B_G] = 0.0
    operating = model.roller_load * model.n_rollers
    # At the run's top speed: at standstill the regularised friction laws (tanh of a sliding
    # speed over ≈ 0.1 rad/s) act as stiff dampers whose RK4 limit would set a far smaller step,
    # though a run only crosses that band for microseconds, where the bounded tanh cannot grow.
    top = float(np.max(np.abs(model.motion[1])))
    loaded = replace(
        model,
        rollers=rollers,
        load_knots=np.array([[0.0, 1.0], [operating, operating]]),
        motion=np.array([[0.0, 1.0], [top, top], [0.0, top]]),
    )
    y0 = initial_state(loaded)
    p = model.params
    held = set(range(2 * nq, 2 * nq + L.N_EXTRA))  # energies and the loop integrator
    if p[L.P_DRIVE_MODE] == L.DRIVE_PRESCRIBED:
        held |= {L.Q_THM, nq + L.Q_THM}
    if p[L.P_COUPLED] != 1.0:  # the screw angle is the motor's
        held |= {L.Q_THS, nq + L.Q_THS}
    if p[L.P_AXIAL_FREE] != 1.0:
        held |= {L.Q_ZS, nq + L.Q_ZS}
    if p[L.P_ON_PAYLOAD] != 1.0:  # the payload coordinate follows the nut
        held |= {L.Q_ZL, nq + L.Q_ZL}
    free = [j for j in range(model.n_state) if j not in held]
    velocity = (np.arange(model.n_state) >= nq) & (np.arange(model.n_state) < 2 * nq)
    scale = np.where(velocity, 1e-7, 1e-10)
    f_plus = np.empty(model.n_state)
    f_minus = np.empty(model.n_state)
    aux = np.zeros(L.n_aux(model.n_rollers))
    jac = np.empty((len(free), len(free)))
    args = (model.params, rollers, model.mesh_table, loaded.motion, loaded.load_knots, model.errors)
    for col, j in enumerate(free):
        y = y0.copy()
        y[j] += scale[j]
        _kernels.rhs(0.0, y, *args, f_plus, aux)
        y[j] -= 2 * scale[j]
        _kernels.rhs(0.0, y, *args, f_minus, aux)
        jac[:, col] = (f_plus[free] - f_minus[free]) / (2 * scale[j])
    return jac, free


def max_stable_step(model: Model) -> tuple[float, float]:
    """Largest stable RK4 step [s] (with :data:`STABILITY_MARGIN`) and the highest natural frequency [Hz]."""
    eig = linearised_eigenvalues(model)
    omega_max = float(np.max(np.abs(eig)))
    # Slow modes (rigid-body motion, the rolling mechanism, friction creep) are resolved by any
    # usable step; their finite-difference noise must not decide the step limit.
    eig = eig[np.abs(eig) > 1e-3 * omega_max]
    lo, hi = 0.0, 4.0 / max(omega_max, 1.0)
    for _ in range(60):  # bisection on the RK4 stability region
        mid = 0.5 * (lo + hi)
        # A mode that physically grows (friction can feed a slow one) may grow in the
        # integration too: the step only must not amplify faster than the exact exp(hλ).
        allowed = np.maximum(1.0, np.exp(mid * eig.real)) * (1.0 + 1e-9)
        if np.all(_rk4_amplification(mid * eig) <= allowed):
            lo = mid
        else:
            hi = mid
    return STABILITY_MARGIN * lo, omega_max / (2 * math.pi)


def settling_model(model: Model) -> Model:
    """The model with the nut axial motion critically damped about its rigid-body speed,
    coupling, thrust bearing and linkage critically damped, and the motor on the prescribed
    motion (a speed or position loop takes over at t = 0, :func:`settled_state`).

    Used before t = 0 only: the rollers find their (uneven) load shares and the drive train its
    static deflections without ringing, so a run starts in its loaded steady state.
    """
    from prsm_health.physics.kinematics import speed_ratios

    params = model.params.copy()
    k_axial = model.n_rollers / (1 / model.thread_stiffness[0] + 1 / model.thread_stiffness[1])
    c_settle = 2.0 * math.sqrt(k_axial * params[L.P_M_N])
    c_guide = params[L.P_C_NA]
    v_rigid = speed_ratios(model.design).nut * float(model.motion[1, 0])
    # settling damper c_s·(v − v_rigid) plus the guide's own c_g·v, as one damper
    params[L.P_C_NA] = c_settle + c_guide
    params[L.P_V_NUT_REF] = c_settle * v_rigid / (c_settle + c_guide)
    m, dt = model.design.masses, model.drive_train
    params[L.P_C_COUP] = 2.0 * math.sqrt(
        params[L.P_K_COUP] * dt.coupling_pair_inertia(m.screw_inertia)
    )
    params[L.P_C_BEAR] = 2.0 * math.sqrt(dt.thrust_bearing_stiffness * m.screw_mass)
    params[L.P_C_LINK] = 2.0 * math.sqrt(dt.linkage_stiffness * dt.payload_mass)
    params[L.P_DRIVE_MODE] = L.DRIVE_PRESCRIBED
    return replace(model, params=params)


def settled_state(model: Model, h: float, settle_time: float) -> np.ndarray:
    """The state at t = 0 after ``settle_time`` [s] of :func:`settling_model` at the step ``h``
    [s] from the initial state: the run's own start, its energy book zeroed at t = 0.

    A speed or position loop takes over from the prescribed motion holding the mean drive
    torque of the settling's last :data:`HANDOVER_TIME` (its integrator set to it): the loop's
    own wind-up against the settling's nut damper, which carries load while the speed lags,
    took ≈ 0.3 s (with paper 01's drive train a run started 5 % slow under 300 N after 30 ms of
    settling, at 18 instead of 50 rad/s under 3000 N)."""
    n_settle = int(round(settle_time / h))
    y = initial_state(model, -n_settle * h)
    if n_settle:
        settling = settling_model(model)
        looped = model.params[L.P_DRIVE_MODE] != L.DRIVE_PRESCRIBED
        n_mean = min(n_settle, max(1, int(round(HANDOVER_TIME / h)))) if looped else 0
        integrate(settling, y, h, n_settle - n_mean, t0=-n_settle * h, record=False)
        nq = model.n_coordinates
        if n_mean:
            record = integrate(settling, y, h, n_mean, t0=-n_mean * h)
            drive = float(np.mean(record[:, L.C_MOTOR_TORQUE]))
            y[2 * nq + L.X_SPEED_INT] = drive / model.params[L.P_KI]
        y[2 * nq + np.array(L.ENERGY_STATES)] = 0.0
    return y


def choose_step(max_step: float, sample_rate: float) -> tuple[float, int]:
    """Integration step h = 1/(m·f_s) ≤ max_step with the smallest integer m."""
    m = max(1, math.ceil(1.0 / (max_step * sample_rate) - 1e-9))
    return 1.0 / (m * sample_rate), m


def integration_step(
    max_step: float | str, h_stable: float, f_max: float, sample_rate: float
) -> tuple[float, int]:
    """The RK4 step h = 1/(m·f_s) and m, for ``options.max_step`` and the model's stable step.

    ``"auto"``: the largest such step below both :data:`AUTO_STABLE_FRACTION` of the stable step
    and :data:`AUTO_MAX_STEP`, so a stiffer or more damped model takes a smaller step instead of
    failing. A given
    ``max_step`` is the user's bound: above the stable step it is refused, naming the limit.
    """
    if max_step == "auto":
        if h_stable < 1e-8:
            raise SimulationError(
                f"stable step {h_stable:.3g} s of this model (highest natural frequency "
                f"{f_max:.0f} Hz) is below 1e-8 s: soften the contacts or the contact damping"
            )
        return choose_step(min(AUTO_MAX_STEP, AUTO_STABLE_FRACTION * h_stable), sample_rate)
    h, factor = choose_step(max_step, sample_rate)
    if h > h_stable:
        raise SimulationError(
            f"integration step {h:.3g} s is above the stable limit {h_stable:.3g} s of this model "
            f"(highest natural frequency {f_max:.0f} Hz, RK4 needs ω·h ≤ 2.8): lower "
            'options.max_step (or "auto"), or soften the contacts (lower load, or '
            "options.traction_stiffness_ratio)"
        )
    return h, factor


def simulate_scenario(scenario, *, progress: bool = False) -> Run:
    """Simulate a :class:`~prsm_health.simulation.scenario.Scenario` of a standard design; see
    :func:`simulate`."""
    design, health, profile = scenario.design, scenario.health, scenario.profile
    instrumentation, options, seed = scenario.instrumentation, scenario.options, scenario.seed
    model = build_model(design, health, profile, options, seed, scenario.drive_train)
    h_stable, f_max = max_stable_step(model)
    h, factor = integration_step(options.max_step, h_stable, f_max, instrumentation.sample_rate)
    n_steps = int(round(profile.duration / h))
    y = settled_state(model, h, options.settle_time)
    record = integrate(model, y, h, n_steps, progress=progress)
    truth_raw = _truth_from_record(record)
    channels = measure(scenario, truth_raw, 1.0 / h)
    # the record's columns filtered together, in place (decimation's kernel)
    truth = _truth_from_record(decimate(record, factor))
    truth["housing_temperature"] = decimate(truth_raw["housing_temperature"], factor)
    nq = model.n_coordinates
    energy = {
        "drive": float(y[2 * nq + L.X_W_DRIVE]),
        "load": float(y[2 * nq + L.X_W_LOAD]),
        "dissipated": float(y[2 * nq + L.X_W_DISS]),
        "friction": float(y[2 * nq + L.X_W_FRIC]),
    }
    return assemble_run(
        scenario,
        channels=channels,
        truth=truth,
        energy=energy,
        labels=realised_clearances(model),
        model_info={
            "integration_step": h,
            "stable_step": h_stable,
            "highest_natural_frequency": f_max,
        },
    )


def _truth_from_record(raw: np.ndarray) -> dict[str, np.ndarray]:
    """Truth signals by name from the kernel's record, whose columns (layout ``C_*``) are the
    truth signals in contract order (prsm_health.core.channels.TRUTH_CHANNELS); the truth
    signals after them are derived from these (``housing_temperature``)."""
    return {name: raw[:, k] for k, name in enumerate(TRUTH_NAMES[: L.N_CHANNELS])}


def integrate(
    model: Model,
    y: np.ndarray,
    h: float,
    n_steps: int,
    *,
    t0: float = 0.0,
    record: bool = True,
    progress: bool = False,
    aux: np.ndarray | None = None,
) -> np.ndarray:
    """Advance the state ``y`` of ``model`` in place by ``n_steps`` RK4 steps of ``h`` [s] from
    ``t0`` [s] — the integration :func:`simulate` runs (the numba kernel, called on 20 ms of
    simulated time at a time).

    Parameters
    ----------
    model : Model
        :func:`~prsm_health.simulation.dynamics.model.build_model`'s parameters.
    y : ndarray
        State (:func:`~prsm_health.simulation.dynamics.model.initial_state`), updated in place.
    h : float [s]
        Step; no stability check here (:func:`max_stable_step` gives the bound).
    n_steps : int
    t0 : float [s]
        Time of the first step.
    record : bool
        Record the truth signals at every step; False: nothing recorded (settling).
    progress : bool
        Show a progress bar (tqdm).
    aux : ndarray or None
        Length ``layout.n_aux(model.n_rollers)``: filled in place with the auxiliary outputs of
        the last right-hand side evaluated (the layout's ``A_*`` entries, then each roller's
        ``AR_*`` block: its tractions, their Coulomb limits, its gear mesh force).

    Returns
    -------
    ndarray
        ``(n_steps, N_CHANNELS)`` record, columns in the layout's ``C_*`` order (the truth
        signals in contract order); one unspecified row when ``record`` is False.

    Raises
    ------
    SimulationError
        The state became non-finite (the step is too large for the contact stiffness).
    """
    raw = np.empty((n_steps if record else 1, L.N_CHANNELS))
    work = [np.empty(model.n_state) for _ in range(5)]
    if aux is None:
        aux = np.zeros(L.n_aux(model.n_rollers))
    elif aux.shape != (L.n_aux(model.n_rollers),) or aux.dtype != np.float64:
        raise ValueError(f"aux must be float64 of length {L.n_aux(model.n_rollers)}")
    chunk = max(1, min(n_steps, int(0.02 / h)))  # 20 ms of simulated time per kernel call
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(
            total=n_steps * h,
            unit="sim s",
            unit_scale=False,
            bar_format="{l_bar}{bar}| {n:.3f}/{total:.3f} s [{elapsed}<{remaining}]",
        )
    done = 0
    while done < n_steps:
        count = min(chunk, n_steps - done)
        status, step = _kernels.integrate(
            y,
            t0 + done * h,
            h,
            count,
            1 if record else count + 1,
            model.params,
            model.rollers,
            model.mesh_table,
            model.motion,
            model.load_knots,
            model.errors,
            raw[done : done + count] if record else raw,
            *work,
            aux,
        )
        if status != 0:
            t_fail = t0 + (done + step) * h
            raise SimulationError(
                f"the state became non-finite at t = {t_fail:.6g} s: the step {h:.3g} s is too "
                "large for the contact stiffness reached there (a load or clearance impact "
                "beyond the linearised bound) — lower options.max_step"
            )
        done += count
        if bar is not None:  # the bar's position from the count: summing steps overshoots
            bar.update(done * h - bar.n)
    if bar is not None:
        bar.close()
    return raw


def right_hand_side(model: Model) -> Callable[[float, np.ndarray], np.ndarray]:
    """The model's state derivative as ``f(t, y) → dy/dt``, for a general ODE solver
    (``scipy.integrate.solve_ivp``): the numba kernel's right-hand side, evaluated on a copy of
    ``y`` whose prescribed motor angle and speed (and the screw's, when rigidly coupled to the
    motor) are first set from the motion at ``t``, the rule the RK4 kernel applies at each
    step. ``y`` is not modified; each call returns a new array."""
    args = (
        model.params,
        model.rollers,
        model.mesh_table,
        model.motion,
        model.load_knots,
        model.errors,
    )
    prescribed = model.params[L.P_DRIVE_MODE] == L.DRIVE_PRESCRIBED
    nq = model.n_coordinates
    aux = np.zeros(L.n_aux(model.n_rollers))

    def f(t: float, y: np.ndarray) -> np.ndarray:
        y = np.array(y, dtype=np.float64)
        if prescribed:
            _kernels._hold_prescribed(y, float(t), model.params, model.motion, nq)
        dy = np.empty_like(y)
        _kernels.rhs(float(t), y, *args, dy, aux)
        return dy

    return f
