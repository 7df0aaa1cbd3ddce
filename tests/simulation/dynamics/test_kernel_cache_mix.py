"""A run's bits do not depend on which kernels a process took from numba's cache.

Dataset workers are fresh processes: one may load ``integrate`` from the cache and compile
``rhs`` itself (the step guard's linearisation calls it), another load both. With fast-math
kernels the first ran other bits on Haswell code (the datasets' resume tests failed in CI), and
these runs amplify a last-bit difference to percent. The test forces that mix with Haswell code
in a private cache: the run must equal, bit for bit, the one that compiled everything.
"""

import os
import shutil
import subprocess
import sys

import pytest

SCRIPT = """
from prsm_health import HealthState, OperatingProfile, simulate
run = simulate("paper01", HealthState(clearance_screw=5e-6),
               OperatingProfile(duration=0.005, speed=80.0, load=100.0), "ideal", 11)
print(run.channels["nut_axial_accel"].tobytes().hex())
"""


def _run(cache, check=True) -> str:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), NUMBA_CPU_NAME="haswell")
    out = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, timeout=600
    )
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout.strip().splitlines()[-1]


def _runs_haswell_code() -> bool:
    from llvmlite import binding

    features = binding.get_host_cpu_features()
    return all(features.get(f, False) for f in ("avx2", "fma", "bmi2", "f16c", "movbe", "lzcnt"))


@pytest.mark.slow
@pytest.mark.skipif(not _runs_haswell_code(), reason="this CPU cannot run Haswell code (x86 AVX2)")
def test_cached_integrate_with_a_fresh_rhs_runs_the_same_bits(tmp_path):
    cache = tmp_path / "numba"
    compiled_all = _run(cache)  # compiles every kernel and fills the cache
    removed = [p for p in cache.rglob("*") if p.is_file() and "_kernels.rhs-" in p.name]
    assert removed, "numba cached no rhs: the mix below would not be tested"
    for path in removed:
        path.unlink()
    assert _run(cache) == compiled_all  # integrate from the cache, rhs compiled here
    shutil.rmtree(cache)
