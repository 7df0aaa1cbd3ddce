"""The recirculating PRSM (paper 03) as a dynamic model (:mod:`.model`); its kernels in
:mod:`._kernels`."""

from .model import RecirculatingRun, right_hand_side, simulate_recirculating

__all__ = ["RecirculatingRun", "right_hand_side", "simulate_recirculating"]
