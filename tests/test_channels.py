"""The channel contract is declared once and every consumer agrees with it."""

import pytest

from prsm_health import channels
from prsm_health.dynamics import layout
from prsm_health.errors import PRSMHealthError


def test_record_order_matches_the_kernel_layout():
    index = {c.name: k for k, c in enumerate(channels.CHANNELS)}
    for name in channels.CHANNEL_NAMES:
        assert getattr(layout, "C_" + name.upper()) == index[name]
    assert layout.N_CHANNELS == len(channels.CHANNELS)


def test_every_channel_is_measured_or_truth_and_on_one_topic():
    assert set(channels.MEASURED_NAMES) | set(channels.TRUTH_NAMES) == set(channels.CHANNEL_NAMES)
    assert not set(channels.MEASURED_NAMES) & set(channels.TRUTH_NAMES)
    fields = [f for pairs in channels.TOPIC_FIELDS.values() for f, _ in pairs]
    assert len(fields) == len(channels.CHANNELS)
    assert {"friction_torque", "carrier_speed"} <= set(channels.TRUTH_NAMES)


def test_unknown_channel_lists_the_contract():
    with pytest.raises(PRSMHealthError, match="nut_axial_accel"):
        channels.channel("nut_axial_acc")


def test_import_is_lazy():
    import subprocess
    import sys

    code = "import prsm_health, sys; print('numba' in sys.modules, 'pandas' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]
