"""Life simulation: how a unit's clearances, lubricant and flanks evolve over operating hours.

Quasi-static (no dynamics): the wear and fatigue rates of :mod:`prsm_health.physics.wear` under a unit's
duty cycle, integrated over its age. What changes with age:

* **lubricant degradation** d(t) = t/T_lube (capped at 1): its additives are used up over the
  lubricant's life T_lube, which halves for every 15 K above 70 °C (the relubrication-interval
  rule of rolling-bearing makers, e.g. SKF's catalogue; Arrhenius-like ageing of the base oil
  and thickener);
* **clearances** b_screw(t), b_nut(t): b₀ + ∫ ḃ(d(t′)) dt′, the Archard rate of each engagement
  averaged over the duty cycle's load spectrum and the share of hours in motion; the rate
  grows as the additives deplete (:meth:`~prsm_health.physics.wear.WearParameters.coefficient`), so
  wear accelerates through life;
* **a spall** starts when the fatigue damage of the flanks reaches the unit's drawn Weibull
  survival (ISO 281, surfaces combined) and then grows in length exponentially.

Since the rates do not depend on the clearance itself, the integral is exact on the
degradation grid: b(t) = b₀ + T_lube·∫₀^{t/T_lube} ḃ(d) dd while the lubricant ages, then
linear. A unit **fails** at the first of: its **installed clearance** reaching
``failure_clearance`` (the lost-motion limit), or its spall reaching ``failure_spall_length``.
The installed clearance is what a health check's zero-load lost motion reads (÷ 4): the mean
thread half-clearance (b_screw + b_nut)/2 plus the play the assembly adds by taking up the
rollers' pitch errors (:func:`~prsm_health.actuator.assembly.assembly_play`, a constant of the
unit's build, ≈ 1 µm at grade-5 tolerances). Uneven wear between rollers moves wear between
them and keeps the mean (:class:`~prsm_health.actuator.assembly.RollerDraws`). Before
2026-12 the criterion and the ``clearance_mean_true`` label were the mean thread
half-clearance alone, which no check can read; that is now ``clearance_thread_true``. The gear backlash is not worn in this model (the ring gear
only synchronises the rollers; its load is the rolling-resistance torque, orders below the
thread loads): it stays at its built value.

A **fleet** is N units with manufacturing, material and usage scatter (:class:`FleetScatter`),
each drawn from the recipe seed and its unit id, so the same recipe gives the same fleet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from prsm_health.actuator.assembly import assembly_play
from prsm_health.actuator.design import PRSMDesign
from prsm_health.actuator.faults import Spall
from prsm_health.actuator.states import HealthState, ManufacturingVariation
from prsm_health.core.errors import require

from .life_spec import DutyCycle, LifeSpec
from .load_rating import load_ratings
from .lubrication import DEFAULT_LUBRICANT, asperity_share, stribeck_curve
from .wear import (
    SURFACES,
    WEIBULL_SLOPE,
    PartGeometry,
    WearParameters,
    clearance_growth_rate,
    contact_states,
    l10_cycles,
    stress_cycle_rates,
)

#: Lubricant life is quoted at 70 °C and halves per 15 K above (doubles per 15 K below).
LUBRICANT_REFERENCE_TEMPERATURE = 343.15
LUBRICANT_HALVING = 15.0
FAILURE_MODES = ("wear", "spall")
#: Lubricant degradations the wear rates are tabulated on (0 new … 1 depleted).
DEGRADATION_GRID = np.linspace(0.0, 1.0, 101)
#: Steps of the age grid a unit's wear is accumulated on (up to 4× its expected life).
_AGE_STEPS = 2000


@dataclass(frozen=True)
class UnitLife:
    """One unit's life, from its build to its failure (SI; ages in operating hours)."""

    unit_id: int
    seed: int  # the unit as built: manufacturing variation and roller wear pattern
    initial_clearance: float
    wear_spread: float  # uneven roller load sharing (FleetScatter.wear_spread)
    load_scale: float
    wear_scale: float  # the unit's wear coefficient ÷ the duty's (lognormal scatter)
    temperature: float  # [K]
    lubricant_life: float  # [h] at the unit's temperature
    ages: np.ndarray  # [h], the grid the wear is accumulated on
    worn_screw: np.ndarray  # [m] wear of b_screw at those ages
    worn_nut: np.ndarray
    duty_hours: np.ndarray  # [h] at those ages: operating hours × the usage intensity
    spall: Spall | None  # where and how the spall is, its length at initiation
    spall_age: float  # [h], inf without one
    spall_doubling: float  # [h]
    failure_age: float  # [h]
    failure_mode: str
    failure_clearance: float
    failure_spall_length: float
    change_age: float | None = None  # [h], the duty's change (DutyCycle.change_age)
    change_load: float = 1.0
    assembly_play: float = 0.0  # [m], the half-clearance its assembly adds (constant)

    def duty_change(self, age) -> np.ndarray:
        """The loads' factor at ``age`` from the duty's change (1 before it)."""
        age = np.asarray(age, dtype=float)
        if self.change_age is None:
            return np.ones_like(age)
        return np.where(age >= self.change_age, self.change_load, 1.0)

    def degradation(self, age) -> np.ndarray:
        return np.minimum(np.asarray(age, dtype=float) / self.lubricant_life, 1.0)

    def clearances(self, age) -> tuple[np.ndarray, np.ndarray]:
        """(b_screw, b_nut) [m] at ``age`` [h] (linear between the grid's ages)."""
        age = np.asarray(age, dtype=float)
        return (
            self.initial_clearance + np.interp(age, self.ages, self.worn_screw),
            self.initial_clearance + np.interp(age, self.ages, self.worn_nut),
        )

    def thread_clearance(self, age) -> np.ndarray:
        """Mean thread half-clearance (b_screw + b_nut)/2 [m] at ``age``."""
        screw, nut = self.clearances(age)
        return 0.5 * (screw + nut)

    def clearance(self, age) -> np.ndarray:
        """The installed clearance [m]: the mean thread half-clearance plus the assembly's
        play — what a check's zero-load lost motion reads, and the failure criterion's."""
        return self.thread_clearance(age) + self.assembly_play

    def spall_length(self, age) -> np.ndarray:
        """Spall length [m] at ``age`` (0 before it starts)."""
        age = np.asarray(age, dtype=float)
        if self.spall is None:
            return np.zeros_like(age)
        grown = self.spall.length * 2.0 ** ((age - self.spall_age) / self.spall_doubling)
        return np.where(age >= self.spall_age, np.minimum(grown, 10e-3), 0.0)

    def rul(self, age) -> np.ndarray:
        """Remaining useful life [h] at ``age``."""
        return self.failure_age - np.asarray(age, dtype=float)

    def snapshot_ages(self, n: int) -> np.ndarray:
        """Ages of n snapshots spread over the life: k/n of the failure age, k = 0 … n − 1."""
        return self.failure_age * np.arange(n) / n

    def health_at(self, age: float) -> HealthState:
        """The :class:`~prsm_health.actuator.states.HealthState` the dynamics simulate at ``age``."""
        screw, nut = (float(v) for v in self.clearances(age))
        mean = 0.5 * (screw + nut)
        worn = mean - self.initial_clearance
        faults = ()
        length = float(self.spall_length(age))
        if length > 0.0:
            faults = (_with_length(self.spall, length),)
        return HealthState(
            clearance_screw=screw,
            clearance_nut=nut,
            clearance_gear=self.initial_clearance,
            # roller i's clearance b(1 + s·u_i) with s chosen so its worn part is spread by
            # wear_spread: b₀ + w(1 + s_w·u_i) = b(1 + (s_w·w/b)·u_i)
            wear_spread=self.wear_spread * worn / mean if mean > 0 else 0.0,
            lubricant_degradation=float(self.degradation(age)),
            faults=faults,
        )

    def labels(self, age: float) -> dict:
        """Life labels of a snapshot at ``age`` (the run-label contract's life fields)."""
        return {
            "unit_id": self.unit_id,
            "age_hours": float(age),
            "rul_hours": float(self.rul(age)),
            "failure_age_hours": self.failure_age,
            "failure_mode": self.failure_mode,
            "clearance_mean_true": float(self.clearance(age)),
            "clearance_thread_true": float(self.thread_clearance(age)),
            "spall_length_true": float(self.spall_length(age)),
            "duty_hours": float(np.interp(age, self.ages, self.duty_hours)),
            "duty_load": self.load_scale * float(self.duty_change(age)),
        }


def _cumulative(rate: np.ndarray) -> np.ndarray:
    # ∫₀^d rate dd′ on the degradation grid (trapezoid)
    steps = 0.5 * (rate[1:] + rate[:-1]) * np.diff(DEGRADATION_GRID)
    return np.concatenate([[0.0], np.cumsum(steps)])


def _with_length(spall: Spall, length: float) -> Spall:
    return replace(spall, length=length)


@dataclass(frozen=True)
class WearRates:
    """A unit's ageing rates under a duty cycle, per operating hour (SI otherwise).

    ``clearance[side]``: growth rate of the half-clearance b of the screw or nut engagement
    [m/h] at each lubricant degradation of :data:`DEGRADATION_GRID`; ``damage[surface]``:
    ISO 281 L10 lives consumed per operating hour (screw, roller, nut).
    """

    clearance: dict
    damage: dict


def wear_rates(
    design: PRSMDesign,
    duty: DutyCycle,
    *,
    lubricant_name: str = DEFAULT_LUBRICANT,
    temperature: float | None = None,
    wear: WearParameters | None = None,
    wear_scale: float = 1.0,
    load_scale: float = 1.0,
    geometry: PartGeometry | None = None,
) -> WearRates:
    """Clearance growth and fatigue damage rates of a unit under ``duty`` (resolved: loads in
    newtons), its loads times ``load_scale`` and its wear coefficient times ``wear_scale``, at
    ``temperature`` [K] (default the duty's): the Archard rate of each engagement
    (:func:`~prsm_health.physics.wear.clearance_growth_rate`, on the asperity share of the
    lubricant's film) and the stress cycles over the L10 life of each surface, summed over the
    load spectrum weighted by its time shares and the motion fraction."""
    geometry = geometry or PartGeometry.of(design)
    wear = wear or WearParameters()
    temperature = duty.temperature if temperature is None else temperature
    zeros = np.zeros_like(DEGRADATION_GRID)
    rates = {"screw": zeros.copy(), "nut": zeros.copy()}
    damage = dict.fromkeys(SURFACES, 0.0)
    k = wear.coefficient(DEGRADATION_GRID) * wear_scale
    for load, share in zip(duty.loads, duty.shares):
        load = load * load_scale
        weight = share * duty.motion_fraction * 3600.0  # seconds in this state per hour
        contacts = contact_states(design, geometry, load, duty.speed)
        for side, contact in contacts.items():
            film = stribeck_curve(
                design,
                lubricant_name,
                [contact.entrainment_speed],
                axial_load=load,
                temperature=temperature,
                degradation=DEGRADATION_GRID,
            )
            shares = asperity_share(film.film_ratio)
            rates[side] += weight * np.array(
                [
                    clearance_growth_rate(
                        geometry,
                        contact,
                        side,
                        stroke=duty.stroke,
                        asperity_share=float(f),
                        coefficient=float(kk),
                    )
                    for f, kk in zip(shares, k)
                ]
            )
        per_second = stress_cycle_rates(geometry, contacts, duty.stroke)
        pressure = {
            "screw": contacts["screw"].max_pressure,
            "roller": max(contacts["screw"].max_pressure, contacts["nut"].max_pressure),
            "nut": contacts["nut"].max_pressure,
        }
        for surface in SURFACES:
            damage[surface] += (
                weight * per_second[surface] / float(l10_cycles(wear, pressure[surface]))
            )
    return WearRates(clearance=rates, damage=damage)


def lubricant_life_at(life_at_reference: float, temperature: float) -> float:
    """Hours until the additives are used up at ``temperature`` [K], from the life at 70 °C:
    halved per 15 K above, doubled per 15 K below (module docstring)."""
    return life_at_reference * 2.0 ** (
        (LUBRICANT_REFERENCE_TEMPERATURE - temperature) / LUBRICANT_HALVING
    )


def unit_life(
    design: PRSMDesign,
    spec: LifeSpec,
    unit_id: int,
    fleet_seed: int,
    geometry=None,
    ratings: dict | None = None,
    variation: ManufacturingVariation | None = None,
) -> UnitLife:
    """Simulate one unit's life (deterministic in ``fleet_seed`` and ``unit_id``); the duty's
    loads given as shares are shares of ``ratings`` (default: the design's,
    :func:`~prsm_health.physics.load_rating.load_ratings`); the unit is built with
    ``variation``'s tolerances (default :class:`ManufacturingVariation`'s), which set its
    assembly's play."""
    geometry = geometry or PartGeometry.of(design)
    rng = np.random.default_rng([fleet_seed, unit_id, 0x4C494645])  # "LIFE"
    sc, wear = spec.scatter, spec.wear
    duty = spec.duty.resolved(ratings or load_ratings(design))
    draws = rng.random(5)
    b0 = sc.initial_clearance[0] + draws[0] * (sc.initial_clearance[1] - sc.initial_clearance[0])
    load_scale = sc.load_scale[0] + draws[1] * (sc.load_scale[1] - sc.load_scale[0])
    temperature = (
        duty.temperature + sc.temperature[0] + draws[2] * (sc.temperature[1] - sc.temperature[0])
    )
    spread = sc.wear_spread[0] + draws[3] * (sc.wear_spread[1] - sc.wear_spread[0])
    survival = float(draws[4])
    k_scale = math.exp(sc.wear_coefficient * rng.standard_normal())
    life_scale = math.exp(sc.lubricant_life * rng.standard_normal())
    t_lube = lubricant_life_at(duty.lubricant_life * life_scale, temperature)
    temperature = min(max(temperature, 223.15), 473.15)

    def unit_rates(loads: float) -> WearRates:  # this unit's, its duty's loads × loads
        return wear_rates(
            design,
            duty,
            lubricant_name=spec.lubricant,
            temperature=temperature,
            wear=wear,
            wear_scale=k_scale,
            load_scale=loads,
            geometry=geometry,
        )

    duty_rates = unit_rates(load_scale)
    rates, damage = duty_rates.clearance, duty_rates.damage
    # the rates from the duty's change on
    after = None if duty.change_age is None else unit_rates(load_scale * duty.change_load)

    seed = int(np.random.SeedSequence([fleet_seed, unit_id, 0x554E4954]).generate_state(1)[0])
    play = assembly_play(seed, design.n_rollers, variation or ManufacturingVariation())
    # Deterministic wear first (exact on the degradation grid), to size the age grid; then the
    # unit's wandering usage intensity along it.
    expected = _expected_failure(rates, b0 + play, t_lube, spec)
    span = min(spec.max_age, 4.0 * expected)
    while True:  # a unit whose usage ran low may need a longer grid (same draws otherwise)
        ages = np.linspace(0.0, span, _AGE_STEPS + 1)
        usage = _usage_increments(rng, np.diff(ages), sc.usage, sc.usage_time)
        mid = 0.5 * (ages[1:] + ages[:-1])
        d_mid = np.minimum(mid / t_lube, 1.0)
        worn = {}
        for side, r in rates.items():
            rate = np.interp(d_mid, DEGRADATION_GRID, r)
            if after is not None:
                changed = np.interp(d_mid, DEGRADATION_GRID, after.clearance[side])
                rate = np.where(mid >= duty.change_age, changed, rate)
            worn[side] = np.concatenate([[0.0], np.cumsum(rate * usage)])
        life = UnitLife(
            unit_id=unit_id,
            seed=seed,
            initial_clearance=float(b0),
            wear_spread=float(spread),
            load_scale=float(load_scale),
            wear_scale=float(k_scale),
            temperature=float(temperature),
            lubricant_life=t_lube,
            ages=ages,
            worn_screw=worn["screw"],
            worn_nut=worn["nut"],
            duty_hours=np.concatenate([[0.0], np.cumsum(usage)]),
            spall=None,
            spall_age=math.inf,
            spall_doubling=math.inf,
            failure_age=math.inf,
            failure_mode="wear",
            failure_clearance=spec.failure_clearance,
            failure_spall_length=spec.failure_spall_length,
            change_age=duty.change_age,
            change_load=duty.change_load,
            assembly_play=play,
        )
        wear_failure = _crossing(life, spec.failure_clearance)
        if math.isfinite(wear_failure) or span >= spec.max_age:
            break
        span = min(spec.max_age, 4.0 * span)

    # Spall: ISO 281 survival of the surfaces together, S = exp(ln 0.9·Σ (D_i)^e), D_i the
    # L10 lives consumed; initiation where S reaches the unit's drawn survival.
    hazard = {s: damage[s] ** WEIBULL_SLOPE for s in SURFACES}
    total = sum(hazard.values())
    spall, spall_age, doubling, spall_failure = None, math.inf, math.inf, math.inf
    if total > 0:
        spall_age = (math.log(survival) / math.log(0.9)) ** (1 / WEIBULL_SLOPE) / total ** (
            1 / WEIBULL_SLOPE
        )
    if after is not None and spall_age > duty.change_age:
        # damage D_i = d_i·t_c + d'_i·(t − t_c) after the change: Σ D_i^e is monotone in t
        spall_age = _changed_spall_age(damage, after.damage, duty.change_age, survival)
        damage = after.damage  # the duty the spall starts and grows under
        hazard = {s: damage[s] ** WEIBULL_SLOPE for s in SURFACES}
        total = sum(hazard.values())
    if spall_age < min(wear_failure, spec.max_age):
        pick = rng.random() * total
        surface = next(s for s in SURFACES if (pick := pick - hazard[s]) <= 0 or s == SURFACES[-1])
        doubling = wear.spall_doubling / damage[surface]  # hours to double
        spall = _spall_on(surface, design, duty, wear, rng)
        spall_failure = spall_age + doubling * math.log2(
            max(spec.failure_spall_length / spall.length, 1.0)
        )
    failure = min(wear_failure, spall_failure)
    require(
        failure <= spec.max_age,
        "life.max_age",
        spec.max_age,
        f"unit {unit_id} has not failed by then (clearance "
        f"{float(life.clearance(spec.max_age)) * 1e6:.1f} µm of "
        f"{spec.failure_clearance * 1e6:g} µm): raise the duty's loads or the wear "
        "coefficient, or max_age",
    )
    return replace(
        life,
        spall=spall,
        spall_age=spall_age if spall is not None else math.inf,
        spall_doubling=doubling,
        failure_age=failure,
        failure_mode="spall" if spall_failure < wear_failure else "wear",
    )


def _changed_spall_age(before: dict, after: dict, change_age: float, survival: float) -> float:
    """Age [h] at which the surfaces' ISO 281 survival exp(ln 0.9·Σ D_i^e) reaches
    ``survival`` when each surface's damage rate changes from ``before`` to ``after`` at
    ``change_age`` (bisection: the hazard only grows)."""
    target = math.log(survival) / math.log(0.9)

    def hazard(t):
        return sum(
            (before[s] * change_age + after[s] * (t - change_age)) ** WEIBULL_SLOPE
            for s in SURFACES
        )

    low, high = change_age, 2.0 * change_age + 1.0
    while hazard(high) < target:
        if high > 1e12:
            return math.inf
        high *= 2.0
    for _ in range(100):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if hazard(mid) < target else (low, mid)
    return high


def _expected_failure(rates: dict, b0: float, t_lube: float, spec: LifeSpec) -> float:
    """Age [h] at which the duty cycle's mean wear alone brings the installed clearance (``b0``
    at age 0) to the failure threshold (max_age if it never does)."""
    mean_rate = 0.5 * (rates["screw"] + rates["nut"])  # [m/h] on the degradation grid
    aged = _cumulative(mean_rate) * t_lube  # wear by the time the lubricant is at d
    needed = spec.failure_clearance - b0
    if needed <= aged[-1]:
        return float(np.interp(needed, aged, DEGRADATION_GRID)) * t_lube
    if mean_rate[-1] <= 0:
        return spec.max_age
    return min(t_lube + (needed - aged[-1]) / mean_rate[-1], spec.max_age)


def _usage_increments(rng, steps: np.ndarray, sigma: float, correlation: float) -> np.ndarray:
    """Usage [h] in each step: the step times the intensity exp(σX − σ²/2) (mean 1), X a
    unit-variance Ornstein–Uhlenbeck process with correlation time ``correlation`` [h]
    (exact discretisation)."""
    if sigma == 0.0:
        return steps
    keep = np.exp(-steps / correlation)
    shocks = rng.standard_normal(len(steps) + 1)
    x = np.empty(len(steps))
    state = shocks[0]
    for i, (a, z) in enumerate(zip(keep, shocks[1:])):
        state = a * state + math.sqrt(1.0 - a * a) * z
        x[i] = state
    return steps * np.exp(sigma * x - 0.5 * sigma * sigma)


def _crossing(life: UnitLife, threshold: float) -> float:
    """First age at which the installed clearance reaches ``threshold`` (inf if not on the
    grid)."""
    clearance = life.clearance(life.ages)
    above = np.flatnonzero(clearance >= threshold)
    if above.size == 0:
        return math.inf
    i = int(above[0])
    if i == 0:
        return 0.0
    c0, c1 = clearance[i - 1], clearance[i]
    return float(
        life.ages[i - 1] + (threshold - c0) / (c1 - c0) * (life.ages[i] - life.ages[i - 1])
    )


def _spall_on(surface: str, design: PRSMDesign, duty: DutyCycle, wear, rng) -> Spall:
    # Where a spall starts: a random spot of the loaded track of that surface.
    flank = "loaded" if np.dot(duty.loads, duty.shares) >= 0 else "unloaded"
    angle = float(rng.uniform(0.0, 2 * math.pi))
    if surface == "screw":
        half = 0.45 * min(
            duty.stroke + design.engaged_threads * design.pitch, design.screw_free_length
        )
        return Spall(
            location="screw",
            depth=wear.spall_depth,
            length=wear.spall_initial_length,
            angle=angle,
            position=float(rng.uniform(-half, half)),
            flank=flank,
        )
    if surface == "nut":
        half = 0.5 * design.engaged_threads * design.pitch
        return Spall(
            location="nut",
            depth=wear.spall_depth,
            length=wear.spall_initial_length,
            angle=angle,
            position=float(rng.uniform(-half, half)),
            flank=flank,
        )
    return Spall(
        location="roller",
        depth=wear.spall_depth,
        length=wear.spall_initial_length,
        angle=angle,
        roller=int(rng.integers(design.n_rollers)),
        flank="both",
    )


def fleet_lives(
    design: PRSMDesign,
    spec: LifeSpec,
    fleet_seed: int,
    variation: ManufacturingVariation | None = None,
) -> list[UnitLife]:
    """Every unit of the fleet (deterministic in ``fleet_seed``), built with ``variation``'s
    tolerances (default :class:`ManufacturingVariation`'s)."""
    geometry = PartGeometry.of(design)
    ratings = load_ratings(design)
    ratings = {"C_a": float(ratings.dynamic), "C_0a": float(ratings.static)}
    return [
        unit_life(design, spec, u, fleet_seed, geometry, ratings, variation)
        for u in range(spec.units)
    ]
