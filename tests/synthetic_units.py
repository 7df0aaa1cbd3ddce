"""Synthetic units for the prognosis tests (the CLI's and the service's): degradation
histories S(t) = PHI0 + exp(ln θ + βt) + noise that fail at THRESHOLD, and a prognostics model
fitted on ten of them (no simulation). At tests/, on the path of every test through
tests/conftest.py."""

import math

import numpy as np
import pandas as pd

from prsm_health.prognostics import RULModel

Z90 = 1.6448536269514722
THRESHOLD, PHI0 = 30e-6, 8e-6


def unit(rng, n_points=20):
    """Ages [h], clearance estimates and measurement sd [m] of one unit, and its life [h]."""
    ln_theta = math.log(2e-6) + 0.15 * rng.standard_normal()
    beta = 2.4e-4 * (1 + 0.15 * rng.standard_normal())
    life = (math.log(THRESHOLD - PHI0) - ln_theta) / beta
    ages = np.linspace(0.0, life, n_points, endpoint=False)
    sd = rng.uniform(0.2e-6, 0.5e-6, n_points)
    estimate = PHI0 + np.exp(ln_theta + beta * ages) + sd * rng.standard_normal(n_points)
    return ages, estimate, sd, life


def fitted_model(units: int = 10, seed: int = 0) -> RULModel:
    """A degradation and similarity model fitted on ``units`` synthetic units of 20 points."""
    rng = np.random.default_rng(seed)
    parts, lives = [], {}
    for uid in range(units):
        ages, estimate, sd, life = unit(rng, 20)
        parts.append(
            pd.DataFrame(
                {
                    "unit_id": uid,
                    "age_hours": ages,
                    "clearance": estimate,
                    "clearance_lower": estimate - Z90 * sd,
                    "clearance_upper": estimate + Z90 * sd,
                }
            )
        )
        lives[uid] = life
    return RULModel(n_samples=2000).fit(pd.concat(parts, ignore_index=True), lives)
