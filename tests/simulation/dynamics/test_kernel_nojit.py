"""The numba kernel and its pure-Python execution (NUMBA_DISABLE_JIT=1) agree on a small case."""

import json
import os
import subprocess
import sys

import numpy as np

SCRIPT = """
import json, numpy as np
from prsm_health import *
r = simulate("paper01", HealthState(), OperatingProfile(duration=0.002, speed=50.0, load=200.0),
             "ideal", 3, options=SimulationOptions(settle_time=0.0))
print(json.dumps({k: v.tolist() for k, v in r.channels.items()}))
"""


def _run(disable_jit: bool) -> dict:
    env = dict(os.environ, NUMBA_DISABLE_JIT="1" if disable_jit else "0")
    out = subprocess.run(
        [sys.executable, "-c", SCRIPT],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_jit_and_python_agree():
    jit, python = _run(False), _run(True)
    for name, values in jit.items():
        a, b = np.asarray(values), np.asarray(python[name])
        scale = max(np.max(np.abs(a)), 1e-12)
        # Same IEEE arithmetic in a different compiler; libm and numba's own math routines may
        # differ in the last bit, which a 2 ms run keeps near round-off (1e-9 of the scale).
        assert np.max(np.abs(a - b)) <= 1e-9 * scale, name
