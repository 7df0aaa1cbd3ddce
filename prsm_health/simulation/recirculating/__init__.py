"""The recirculating PRSM (paper 03) as a dynamic model (:mod:`.model`); its kernels in
:mod:`._kernels`."""

from .model import (
    NutSpall,
    RecirculatingRun,
    right_hand_side,
    simulate_recirculating,
)

__all__ = [
    "NutSpall",
    "RecirculatingRun",
    "right_hand_side",
    "simulate_recirculating",
]
