"""A rig's log of a simulated recording, for the front-door tests: its own column names and
units (degrees, g, millimetres) and no speed column (the drive's speed estimate is not logged;
the reader derives it from the angle), with the column map that reads it back."""

import numpy as np
import pandas as pd

#: The column map's [columns] and [units] tables (a `design = …` line goes before them).
COLUMNS = """
[columns]
time = "t_s"
screw_angle = "motor_deg"
nut_axial_accel = "acc_g"
drive_torque = "torque_Nm"
nut_position = "pos_mm"
housing_temperature = "housing_C"
[units]
t_s = "s"
motor_deg = "deg"
acc_g = "g"
torque_Nm = "N*m"
pos_mm = "mm"
housing_C = "degC"
"""


def write_rig_csv(path, run) -> None:
    """``run`` (flight-ema channels) as the rig logs it."""
    pd.DataFrame(
        {
            "t_s": run.time,
            "motor_deg": np.degrees(run.channels["screw_angle"]),
            "acc_g": run.channels["nut_axial_accel"] / 9.80665,
            "torque_Nm": run.channels["drive_torque"],
            "pos_mm": 1e3 * run.channels["nut_position"],
            "housing_C": run.channels["housing_temperature"] - 273.15,
        }
    ).to_csv(path, index=False)
