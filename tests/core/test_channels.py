"""The channel contract is declared once and every consumer agrees with it."""

import numpy as np
import pytest

from prsm_health.core import channels
from prsm_health.core.errors import PRSMHealthError
from prsm_health.simulation.dynamics import layout
from prsm_health.simulation.dynamics.simulate import _truth_from_record


def test_the_kernel_records_every_truth_signal_in_contract_order():
    # The kernel's record columns (layout C_<NAME>) are the truth signals, in the order of
    # TRUTH_CHANNELS; the simulator names them from that order. The truth signals after them
    # (housing_temperature) are derived from the record, not recorded; the recirculating
    # model's own (cam_force, reset_count) come from its own model.
    recorded = channels.TRUTH_NAMES[: layout.N_CHANNELS]
    assert [getattr(layout, "C_" + name.upper()) for name in recorded] == list(
        range(layout.N_CHANNELS)
    )
    assert channels.TRUTH_NAMES[layout.N_CHANNELS :] == (
        "housing_temperature",
        *channels.RECIRCULATING_TRUTH,
    )
    raw = np.arange(5.0 * layout.N_CHANNELS).reshape(5, layout.N_CHANNELS)
    truth = _truth_from_record(raw)
    assert tuple(truth) == recorded
    for k, name in enumerate(recorded):
        assert np.array_equal(truth[name], raw[:, k]), name


def test_measured_and_truth_are_apart():
    assert all(c.kind == channels.MEASURED for c in channels.CHANNELS)
    assert all(c.kind == channels.TRUTH for c in channels.TRUTH_CHANNELS)
    assert channels.CHANNEL_NAMES == tuple(c.name for c in channels.CHANNELS)
    assert len(set(channels.TRUTH_NAMES)) == len(channels.TRUTH_NAMES) == 19
    # No truth-only signal is a channel; the shared names are the true value of what a sensor
    # reads, and are told apart in files by the truth_ prefix.
    assert {"friction_torque", "carrier_speed", "motor_torque", "load_force"}.isdisjoint(
        channels.CHANNEL_NAMES
    )
    assert not any(name.startswith(channels.TRUTH_PREFIX) for name in channels.CHANNEL_NAMES)
    columns = [channels.truth_column(n) for n in channels.TRUTH_NAMES]
    assert set(columns).isdisjoint(channels.CHANNEL_NAMES)
    assert columns[0] == "truth_motor_angle"


def test_every_file_column_has_one_unit():
    units = channels.UNITS
    assert list(units) == [
        "time",
        *channels.CHANNEL_NAMES,
        channels.CHECK_PHASE,
        *(channels.truth_column(n) for n in channels.TRUTH_NAMES),
    ]
    for c in channels.TRUTH_CHANNELS:
        assert units[channels.truth_column(c.name)] == c.unit
        assert c.sensor and c.meaning


def test_every_signal_is_on_one_topic_field():
    pairs = {t: dict(p) for t, p in channels.TOPIC_FIELDS.items()}
    assert set(pairs) == {*channels.MEASURED_TOPICS, channels.TOPIC_TRUTH}
    measured = [n for t in channels.MEASURED_TOPICS for n in pairs[t].values()]
    assert sorted(measured) == sorted(channels.CHANNEL_NAMES)
    assert list(pairs[channels.TOPIC_TRUTH]) == list(channels.TRUTH_NAMES)  # field = name
    assert list(pairs[channels.TOPIC_TRUTH].values()) == list(channels.TRUTH_NAMES)


def test_unknown_channel_lists_the_contract():
    with pytest.raises(PRSMHealthError, match="nut_axial_accel"):
        channels.channel("nut_axial_acc")
    with pytest.raises(PRSMHealthError, match="truth signals are not measured"):
        channels.channel("friction_torque")
    with pytest.raises(PRSMHealthError, match="motor_angle"):
        channels.truth_channel("motor_angel")
    assert channels.truth_channel("load_force").unit == "N"


def test_formats_doc_tables_are_current():
    import subprocess
    import sys
    from pathlib import Path

    tool = Path(__file__).resolve().parents[2] / "tools" / "release" / "make_formats_tables.py"
    out = subprocess.run([sys.executable, str(tool), "--check"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr


def test_import_is_lazy():
    import subprocess
    import sys

    code = "import prsm_health, sys; print('numba' in sys.modules, 'pandas' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]
