"""Run.windows: the one place recordings are cut into windows (features, diagnosis, service),
and the boundary arithmetic the streaming MCAP replay shares with it."""

import numpy as np
import pytest

from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import MIN_SAMPLES, Run, complete_windows, window_span

RATE = 1000.0


def _run(n: int) -> Run:
    t = np.arange(n) / RATE
    return Run(t, {"nut_axial_accel": np.arange(n, dtype=float)}, RATE, {"design": "paper01"})


def test_window_arithmetic():
    assert window_span(0, 400) == (0, 400)
    assert window_span(3, 400) == (1200, 1600)
    assert window_span(2, 400, 100, origin=7) == (207, 607)
    assert [complete_windows(total, 400) for total in (0, 399, 400, 799, 800)] == [0, 0, 1, 1, 2]
    assert complete_windows(1000, 400, 100) == 7  # starts 0, 100, …, 600


def test_complete_windows_only():
    parts, notes = _run(1100).windows(0.4)
    assert [len(p) for p in parts] == [400, 400] and notes == []
    assert parts[1].channels["nut_axial_accel"][0] == 400.0  # views of the run, in order
    assert parts[1].labels == {"design": "paper01"}
    hopped, _ = _run(1100).windows(0.4, hop=0.1)
    assert [p.channels["nut_axial_accel"][0] for p in hopped] == [
        0,
        100,
        200,
        300,
        400,
        500,
        600,
        700,
    ]
    assert _run(300).windows(0.4) == ([], [])  # shorter than a window: none


@pytest.mark.parametrize(
    "n, lengths, note",
    [
        # half a window, but 200 samples < MIN_SAMPLES: too short for the indicators, dropped
        (1000, [400, 400], "last 0.2 s not diagnosed: shorter than half a window (0.2 s)"),
        (1100, [400, 400, 300], "last window is 0.3 s, shorter than 0.4 s"),
        (900, [400, 400], "last 0.1 s not diagnosed: shorter than half a window (0.2 s)"),
        (800, [400, 400], None),
        (300, [300], "recording (0.3 s) is shorter than the window (0.4 s)"),
    ],
)
def test_tail_policy(n, lengths, note):
    parts, notes = _run(n).windows(0.4, min_tail=0.5)
    assert [len(p) for p in parts] == lengths
    if note is None:
        assert notes == []
    else:
        assert len(notes) == 1 and notes[0].startswith(note), notes
    # the windows tile the run from its start, without overlap
    starts = [float(p.time[0]) for p in parts]
    assert starts == sorted(starts) and starts[0] == 0.0


def test_bad_lengths():
    with pytest.raises(PRSMHealthError, match=f"need at least {MIN_SAMPLES}"):
        _run(1000).windows(0.1)
    with pytest.raises(PRSMHealthError, match="hop"):
        _run(1000).windows(0.4, hop=1e-6)
    with pytest.raises(PRSMHealthError, match="gives 0 samples"):
        _run(1000).windows(float("nan"))


def test_replay_cuts_where_run_windows_cuts(tmp_path):
    # the streaming MCAP replay and Run.windows share window_span: same spans, same samples
    from prsm_health.io.mcap import iter_windows, write_mcap

    run = _run(1300)
    write_mcap(run, tmp_path / "r.mcap")
    stream = iter_windows(tmp_path / "r.mcap", 0.4)
    try:
        replayed = list(stream)
    finally:
        stream.close()
    parts, _ = run.windows(0.4)
    assert len(replayed) == len(parts) == 3
    for w, part in zip(replayed, parts):
        assert np.array_equal(w.channels["nut_axial_accel"], part.channels["nut_axial_accel"])


def test_a_tail_of_a_few_samples_is_no_news_a_longer_one_is_said_rounded():
    rate = 20_000.0

    def run_of(n):
        t = np.arange(n) / rate
        return Run(time=t, channels={"nut_axial_accel": np.sin(t)}, sample_rate=rate)

    _, notes = run_of(10_001).windows(0.5, min_tail=0.5)
    assert notes == []
    _, notes = run_of(12_400).windows(0.5, min_tail=0.5)
    assert notes == ["last 0.12 s not diagnosed: shorter than half a window (0.25 s)"]
