"""Paper 01 rows: kinematics and frequencies (§3.1–3.3).

Reference: ../shared/papers/01-dynamics-time-varying-mesh-stiffness.txt.
"""

from __future__ import annotations

import math

from ..design import preset
from ..kinematics import characteristic_frequencies, speed_ratios
from . import Row, inconsistent, not_computable, reproduced

_DYNAMICS_PENDING = (
    "needs the nonlinear dynamic simulator (issue [2/6]), not built yet; "
    "../shared/notes/dynamics-findings.md finds it inconsistent with the paper's own amplitudes"
)


def rows() -> list[Row]:
    design = preset("paper01")
    ratio = speed_ratios(design).carrier
    freqs = characteristic_frequencies(design, 100.0)
    out = [
        reproduced(
            "01",
            "§3.2",
            "screw speed 100 rad/s in rpm",
            "rpm",
            955.0,
            100.0 * 60.0 / (2 * math.pi),
            5e-4,
            "unit conversion; tolerance = the paper's rounding to 3 digits",
        ),
        reproduced(
            "01",
            "§3.1",
            "carrier/screw speed ratio (rigid body)",
            "-",
            0.37,
            ratio,
            0.0136,
            "r_s/(2(r_s + r_c)) = 0.375; tolerance = half a unit of the paper's last printed "
            "digit (0.005/0.37). The paper's own 5.8 Hz and 377 Hz imply 0.364 (rows below)",
        ),
        inconsistent(
            "01",
            "§3.2",
            "carrier frequency f_p at 100 rad/s",
            "Hz",
            5.8,
            freqs.carrier,
            "100·0.375/2π = 5.97 Hz; the paper's 5.8 Hz implies a 0.364 speed ratio (3 % slip), "
            "contradicting its own 0.37 and the rigid-body 0.375 it claims to match",
        ),
        inconsistent(
            "01",
            "§3.2",
            "gear mesh frequency z2·f_p at 100 rad/s",
            "Hz",
            377.0,
            freqs.gear_mesh,
            "65 × 5.97 Hz = 388 Hz; 377 Hz follows from the inconsistent 5.8 Hz",
        ),
        not_computable(
            "01", "§3.1", "settling time of the speed ratio", "ms", 0.05, None, _DYNAMICS_PENDING
        ),
    ]
    for clearance, freq in ((10, 590.0), (20, 538.0), (30, 507.0)):
        out.append(
            not_computable(
                "01",
                "§3.3 table",
                f"dominant nut axial frequency, b = {clearance} µm",
                "Hz",
                freq,
                None,
                _DYNAMICS_PENDING,
            )
        )
    out.append(
        not_computable(
            "01",
            "§3.3",
            "FEA dominant axial frequency, b = 30 µm",
            "Hz",
            488.0,
            None,
            "FEA model not described in the paper",
        )
    )
    return out
