"""The live view (prsm_health.apps.live, ``replay --live``): a Foxglove WebSocket client on 127.0.0.1
checks what the server advertises and publishes against the MCAP contract and the recording.

The client (aiohttp) speaks the Foxglove WebSocket protocol: JSON ``serverInfo`` / ``advertise``
from the server, a JSON ``subscribe`` from the client, then binary ``messageData`` frames
(opcode 1, u32 subscription id, u64 log time [ns], payload). foxglove-sdk 0.30 accepts the
protocol under its current subprotocol name ``foxglove.sdk.v1`` only (the same protocol as
``foxglove.websocket.v1``, renamed); the client offers both.
"""

import asyncio
import contextlib
import json
import math
import re
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
import typing
from pathlib import Path

import aiohttp
import foxglove.layouts as fl
import numpy as np
import pytest
from mcap.reader import make_reader

from prsm_health import HealthState, OperatingProfile, simulate
from prsm_health.actuator.faults import FAULT_CLASSES
from prsm_health.apps.cli import main
from prsm_health.apps.live import (
    MESSAGE_BUDGET,
    LivePlayer,
    _complete,
    _log_times,
    _run_windows,
    window_diagnoser,
)
from prsm_health.core.channels import TOPIC_DIAGNOSIS, TOPIC_DRIVE, TOPIC_FIELDS, TOPIC_TRUTH
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run
from prsm_health.diagnostics.diagnosis import CANNOT_TELL, diagnose_window, load_bundle, replay
from prsm_health.diagnostics.not_observable import OBSERVABLE, diagnosis_message
from prsm_health.io.mcap import iter_windows, read_mcap, write_mcap
from prsm_health.io.mcap.replay import window_origin_ns, window_reached_ns
from prsm_health.io.mcap.schema import diagnosis_schema, topic_schema

SUBPROTOCOLS = ("foxglove.sdk.v1", "foxglove.websocket.v1")
OP_MESSAGE_DATA = 1
DURATION = 0.3  # s of recording
WINDOW = 0.1  # s: three complete windows, three diagnoses
DECIMATE = 10  # 600 messages per topic: few enough that the client keeps up with a burst
RATE = 0.5  # the 0.3 s recording plays in 0.6 s: a burst (~0.1 s) is far from pacing


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A short simulated flight-EMA recording (measured topics + truth) as an MCAP file."""
    run = simulate(
        "paper01",
        HealthState.uniform(20e-6),
        OperatingProfile(duration=DURATION, speed=100.0),
        "flight-ema",
        3,
    )
    path = tmp_path_factory.mktemp("live") / "run.mcap"
    write_mcap(run, path)
    return path


@pytest.fixture(scope="module")
def bundle():
    return load_bundle()


def _diagnoser(bundle):
    def diagnose(w):  # what live and replay publish: the contract's JSON and what plots draw
        run = Run(w.time, w.channels, w.sample_rate, w.labels)
        return diagnosis_message(diagnose_window(run, bundle).to_json())

    return diagnose


def _file_schemas(path):
    """topic → (schema name, schema encoding, schema text, message encoding) of an MCAP file."""
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    return {
        c.topic: (
            summary.schemas[c.schema_id].name,
            summary.schemas[c.schema_id].encoding,
            summary.schemas[c.schema_id].data.decode(),
            c.message_encoding,
        )
        for c in summary.channels.values()
    }


async def _collect(url, topics, done: threading.Event, timeout=20.0):
    """Connect, wait for ``topics`` to be advertised, subscribe to them, and record every
    message until the player is ``done`` and 0.3 s pass without one."""
    out = {"server_info": None, "channels": {}, "messages": []}
    async with aiohttp.ClientSession() as session:
        async with session.ws_connect(url, protocols=SUBPROTOCOLS, max_msg_size=0) as ws:
            out["protocol"] = ws.protocol
            subscriptions = {}
            deadline = time.monotonic() + timeout
            while time.monotonic() < deadline:
                try:
                    msg = await asyncio.wait_for(ws.receive(), 0.3)
                except asyncio.TimeoutError:
                    if done.is_set():
                        break
                    continue
                if msg.type == aiohttp.WSMsgType.TEXT:
                    data = json.loads(msg.data)
                    if data["op"] == "serverInfo":
                        out["server_info"] = data
                    elif data["op"] == "advertise":
                        for c in data["channels"]:
                            out["channels"][c["topic"]] = c
                        if set(topics) <= set(out["channels"]) and not subscriptions:
                            subscriptions = {
                                k: out["channels"][t]["topic"] for k, t in enumerate(topics)
                            }
                            await ws.send_str(
                                json.dumps(
                                    {
                                        "op": "subscribe",
                                        "subscriptions": [
                                            {"id": k, "channelId": out["channels"][t]["id"]}
                                            for k, t in subscriptions.items()
                                        ],
                                    }
                                )
                            )
                elif msg.type == aiohttp.WSMsgType.BINARY:
                    assert msg.data[0] == OP_MESSAGE_DATA
                    sub, log_time = struct.unpack_from("<IQ", msg.data, 1)
                    out["messages"].append(
                        (time.monotonic(), subscriptions[sub], log_time, msg.data[13:])
                    )
                else:
                    break
    return out


def _play(player: LivePlayer, result: dict, done: threading.Event):
    try:
        if player.wait_for_client(timeout=15):
            result["stats"] = player.play()
    except BaseException as exc:  # reported by the test
        result["error"] = exc
    finally:
        done.set()


def _session(player, topics):
    """Play ``player`` in a thread while a client collects what it publishes."""
    result, done = {}, threading.Event()
    thread = threading.Thread(target=_play, args=(player, result, done))
    thread.start()
    try:
        seen = asyncio.run(_collect(player.url, topics, done))
    finally:
        thread.join(30)
    assert "error" not in result, result.get("error")
    return seen, result["stats"]


def _by_topic(messages, topic):
    return [(k, m) for k, m in enumerate(messages) if m[1] == topic]


def test_live_replay_publishes_the_recording_and_its_diagnoses(recording, bundle):
    """Paced replay of an MCAP file (half real time), every 10th sample: contract topics and
    schemas, the recording's values and log times, the pacing, and one diagnosis per window
    equal to the one ``replay --out`` writes, published after the window's last sample."""
    run = read_mcap(recording)
    n = len(run)
    with LivePlayer(
        recording,
        window=WINDOW,
        diagnose=_diagnoser(bundle),
        port=0,
        rate=RATE,
        decimate=DECIMATE,
    ) as player:
        assert player.host == "127.0.0.1" and player.url == f"ws://127.0.0.1:{player.port}"
        signal_topics = list(TOPIC_FIELDS)  # nut_accel, drive, truth: the file has all three
        seen, stats = _session(player, [*signal_topics, TOPIC_DIAGNOSIS])

    # ---- handshake and advertised channels: the MCAP contract, byte for byte
    assert seen["protocol"] in SUBPROTOCOLS
    assert seen["server_info"]["op"] == "serverInfo"
    diagnosed = recording.parent / "diagnosed.mcap"
    expected = [
        diagnosis_message(step.diagnosis.to_json())
        for step in replay(recording, bundle, window=WINDOW, out=diagnosed)
    ]
    contract = _file_schemas(diagnosed)  # the recording's schemas + replay's diagnosis schema
    assert set(seen["channels"]) == set(contract) == {*signal_topics, TOPIC_DIAGNOSIS}
    for topic, channel in seen["channels"].items():
        name, encoding, schema, message_encoding = contract[topic]
        assert channel["schemaName"] == name
        assert channel["schemaEncoding"] == encoding == "jsonschema"
        assert channel["encoding"] == message_encoding == "json"
        assert json.loads(channel["schema"]) == json.loads(schema)

    # ---- every published sample arrived, with the recording's values and time base
    messages = seen["messages"]
    kept = np.arange(0, n, DECIMATE)
    assert stats.samples == n and stats.published == len(kept) and stats.diagnoses == 3
    for topic in signal_topics:
        got = _by_topic(messages, topic)
        assert len(got) == len(kept), topic
        source = run.truth if topic == TOPIC_TRUTH else run.channels
        fields = [(f, name) for f, name in TOPIC_FIELDS[topic] if name in source]
        for (_, (_, _, log_time, payload)), i in zip(got, kept):
            obj = json.loads(payload)
            assert list(obj) == [f for f, _ in fields]
            assert [obj[f] for f, _ in fields] == [float(source[name][i]) for _, name in fields]
            assert log_time == round(run.time[i] * 1e9)

    # ---- pacing, not a burst. Wide bounds (this is not a speed test): paced, the messages of a
    # topic arrive at sample rate × RATE / DECIMATE = 1000/s over 0.6 s, none ahead of its
    # due time by more than a pacing tick (10 ms) plus scheduling jitter; a burst would bring
    # all 600 in about 0.1 s (6000/s, up to 0.5 s ahead).
    drive = [m for _, m in _by_topic(messages, TOPIC_DRIVE)]
    arrival = np.array([m[0] for m in drive])
    log_s = np.array([m[2] for m in drive]) / 1e9
    rate = (len(drive) - 1) / (arrival[-1] - arrival[0])  # messages/s of one topic
    assert 0.5 < rate / (run.sample_rate * RATE / DECIMATE) < 2.0, rate
    ahead = (log_s - log_s[0]) / RATE - (arrival - arrival[0])  # [s of wall time]
    assert ahead.max() < 0.15, ahead.max()
    assert stats.wall_time >= 0.5 * DURATION / RATE

    # ---- diagnoses: after their window's last sample, at the window's end, as replay --out
    got = _by_topic(messages, TOPIC_DIAGNOSIS)
    assert [m[2] for _, m in got] == [round((k + 1) * WINDOW * 1e9) for k in range(3)]
    for (position, (_, _, end_ns, payload)), want in zip(got, expected):
        last_sample = max(
            k for k, m in enumerate(messages) if m[1] == TOPIC_DRIVE and m[2] < end_ns
        )
        assert position > last_sample
        diagnosis = json.loads(payload)
        assert diagnosis == json.loads(json.dumps(want))
        assert set(diagnosis["clearance"]) == {"estimate", "lower", "upper"}
        assert isinstance(diagnosis["fault_class"], str)
        assert math.isclose(sum(diagnosis["class_probabilities"].values()), 1.0, abs_tol=1e-6)


def test_live_run_as_fast_as_possible_with_automatic_decimation():
    """A Run in memory (what ``simulate --live`` plays): only the topics it has, no diagnosis
    topic without a model, every 2nd sample by default at 20 kHz, values and log times exact."""
    fs, n = 20_000.0, 2_000
    rng = np.random.default_rng(1)
    time_s = np.arange(n) / fs
    channels = {"nut_axial_accel": rng.standard_normal(n), "drive_torque": rng.standard_normal(n)}
    channels["drive_torque"][5] = np.nan  # non-finite samples are published as null
    run = Run(time_s, channels, fs)
    with LivePlayer(run, port=0, rate=None) as player:
        assert player.decimate == math.ceil(2 * fs / MESSAGE_BUDGET) == 2
        assert not player.diagnosing
        seen, stats = _session(player, ["/prsm/nut_accel", "/prsm/drive"])
    assert set(seen["channels"]) == {"/prsm/nut_accel", "/prsm/drive"}
    assert json.loads(seen["channels"]["/prsm/drive"]["schema"])["required"] == ["drive_torque"]
    got = [m for m in seen["messages"] if m[1] == "/prsm/drive"]
    assert stats.published == len(got) == n // 2
    values = [json.loads(m[3])["drive_torque"] for m in got]
    assert values[:2] == [channels["drive_torque"][0], channels["drive_torque"][2]]
    assert values[2] == channels["drive_torque"][4] and values[3] == channels["drive_torque"][6]
    assert [m[2] for m in got] == [round(t * 1e9) for t in time_s[::2]]


def test_live_run_with_a_bundle_publishes_what_replay_writes(recording, bundle):
    """``bundle=`` (what ``simulate --live`` and ``replay --live`` pass): a Run in memory is
    cut and diagnosed as ``replay --out`` cuts and diagnoses its MCAP file — the same
    diagnoses, at the same window ends."""
    expected = [
        diagnosis_message(step.diagnosis.to_json())
        for step in replay(recording, bundle, window=WINDOW)
    ]
    assert len(expected) == 3
    with LivePlayer(
        read_mcap(recording), window=WINDOW, bundle=bundle, port=0, rate=None, decimate=50
    ) as player:
        assert player.diagnosing
        seen, stats = _session(player, [TOPIC_DRIVE, TOPIC_DIAGNOSIS])
    assert stats.diagnoses == 3
    got = [m for m in seen["messages"] if m[1] == TOPIC_DIAGNOSIS]
    assert [m[2] for m in got] == [round((k + 1) * WINDOW * 1e9) for k in range(3)]
    assert [json.loads(m[3]) for m in got] == json.loads(json.dumps(expected))


def test_window_diagnoser_is_the_diagnosis_of_the_window_as_a_run(recording, bundle):
    with contextlib.closing(iter_windows(recording, WINDOW)) as stream:
        w = next(stream)
    assert window_diagnoser(bundle)(w) == _diagnoser(bundle)(w)


def test_diagnose_and_bundle_together_are_refused(recording, bundle):
    with pytest.raises(PRSMHealthError, match="not both"):
        LivePlayer(recording, bundle=bundle, diagnose=_diagnoser(bundle), port=0)


@pytest.mark.parametrize("window", [WINDOW, 0.07])
def test_a_run_is_cut_where_the_mcap_replay_cuts(recording, window):
    """The live view's windows of a Run in memory and the MCAP replay's of its file: the same
    log-time spans (window_span from window_origin_ns), samples and completeness
    (window_reached_ns) — 0.07 s leaves an incomplete last window."""
    run = read_mcap(recording)
    with contextlib.closing(iter_windows(recording, window, partial=True)) as stream:
        replayed = list(stream)
    with contextlib.closing(iter_windows(recording, window)) as stream:
        released = len(list(stream))  # complete windows only
    live = list(_run_windows(run, window))
    assert len(live) == len(replayed) > 1
    for a, b in zip(live, replayed):
        assert (a.index, a.start_ns, a.end_ns) == (b.index, b.start_ns, b.end_ns)
        assert a.start == b.start and a.end == b.end
        assert np.array_equal(a.time, b.time)
        assert a.channels.keys() == b.channels.keys()
        for name in a.channels:
            assert np.array_equal(a.channels[name], b.channels[name], equal_nan=True), name
        assert a.truth.keys() == b.truth.keys() and a.truth.keys()
        for name in a.truth:
            assert np.array_equal(a.truth[name], b.truth[name], equal_nan=True), name
    complete = [_complete(w, _log_times(w)) for w in live]
    assert complete == [True] * released + [False] * (len(live) - released)
    assert released == int(round(DURATION / window, 9))  # 3 of 0.1 s; 4 of 0.07 s


def test_log_time_window_rules():
    assert window_origin_ns(0, 5) == 0 and window_origin_ns(0, -7) == -7
    # 20 kHz: complete once a sample lies within one period (50 µs) + 1 ns of the end
    assert window_reached_ns(1_000_000, 20_000.0) == 1_000_000 - 50_000 - 1
    assert window_reached_ns(1_000_000, None) == window_reached_ns(1_000_000, 0.0) == 999_999


def test_live_errors_are_user_errors(tmp_path, recording):
    with pytest.raises(PRSMHealthError, match="decimate"):
        LivePlayer(recording, port=0, decimate=0)
    with pytest.raises(PRSMHealthError, match="no such file|does not exist|cannot"):
        LivePlayer(tmp_path / "missing.mcap", port=0)
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        with pytest.raises(PRSMHealthError, match="cannot start the Foxglove WebSocket server"):
            LivePlayer(recording, port=busy.getsockname()[1])


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["--port", "70000"], "--port"),
        (["--port", "busy"], "cannot start the Foxglove WebSocket server"),
        (["--live-decimate", "0"], "--live-decimate"),
        (["--out", "x.mcap"], "--live"),
        (["FILE=missing"], "missing.mcap"),
        (["FILE=garbage"], "garbage.mcap"),
    ],
)
def test_replay_live_errors_are_one_line(tmp_path, capsys, recording, argv, needle):
    (tmp_path / "garbage.mcap").write_bytes(b"not an mcap file at all")
    target = str(recording)
    if argv and argv[0].startswith("FILE="):
        target, argv = str(tmp_path / f"{argv[0][5:]}.mcap"), []
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        argv = [str(busy.getsockname()[1]) if a == "busy" else a for a in argv]
        code = main(["replay", target, "--live", "--statistics-only", *argv])
    out, err = capsys.readouterr()
    assert code == 2, (out, err)
    assert err.startswith("error: ") and len(err.strip().splitlines()) == 1, err
    assert needle in err and "Traceback" not in err


def test_simulate_needs_out_or_live(capsys):
    assert main(["simulate", "--duration", "0.01"]) == 2
    assert "--out is required (or --live)" in capsys.readouterr().err


def test_replay_live_command_prints_the_url_and_stops_on_ctrl_c(recording):
    """The command prints one line with the ws:// URL, plays to a client, keeps serving, and
    Ctrl-C (SIGINT) stops it with status 0 and no traceback."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "prsm_health.apps.cli", "replay", str(recording), "--live"]
        + ["--port", "0", "--statistics-only", "--rate", "max"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        first = proc.stdout.readline()
        assert first.startswith("live: open ws://127.0.0.1:") and "Foxglove WebSocket" in first
        url = first.split()[2]
        done = threading.Event()
        waiter = threading.Thread(target=lambda: (proc.stdout.readline(), done.set()))
        waiter.start()
        seen = asyncio.run(_collect(url, ["/prsm/drive"], done))
        # Generous: a cold numba cache compiles the diagnosis' kernels inside the play (tens of
        # seconds on a loaded 2-core machine); Ctrl-C is sent once the play has ended.
        waiter.join(120)
        assert done.is_set(), "the play did not end"
        assert len([m for m in seen["messages"] if m[1] == "/prsm/drive"]) > 0
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert "Traceback" not in err and "stopped" in err


# ---------------------------------------------------------------------------- the layout file
LAYOUT = Path(__file__).resolve().parents[2] / "docs" / "foxglove-layout.json"
# Panel type → (config class, series class, series key) of the SDK's layout types
# (foxglove.layouts, generated from Foxglove's layout schema), to check key names and values.
PANELS = {
    "Plot": ("PlotConfig", "PlotSeries", "paths"),
    "StateTransitions": ("StateTransitionsConfig", "StateTransitionsSeries", "paths"),
    "Indicator": ("IndicatorConfig", "IndicatorRule", "rules"),
    "RawMessages": ("RawMessagesConfig", None, None),
}
# The classic (exported-layout) key for a panel's title; the SDK's layout types put the title
# on the panel instead, so it is not among their config keys.
TITLE = "foxglovePanelTitle"


def _check_keys(obj: dict, cls_name: str) -> None:
    """Every key of ``obj`` is a field of the SDK layout type ``cls_name`` (camelCase), and a
    string value of a field typed as a Literal is one of its values."""
    cls = getattr(fl, cls_name)
    hints = typing.get_type_hints(cls)
    for key, value in obj.items():
        if key == TITLE:
            continue
        name = re.sub(r"(?<!^)(?=[A-Z])", "_", key).lower()
        assert name in hints, f"{cls_name} has no field {key!r}"
        literals = [
            a
            for arg in typing.get_args(hints[name]) or (hints[name],)
            if typing.get_origin(arg) is typing.Literal
            for a in typing.get_args(arg)
        ]
        if literals and isinstance(value, str):
            assert value in literals, f"{cls_name}.{key} = {value!r} not in {literals}"


def _leaves(node):
    if isinstance(node, str):
        return [node]
    assert set(node) == {"direction", "first", "second", "splitPercentage"}, node
    assert node["direction"] in ("row", "column") and 0 < node["splitPercentage"] < 100
    return _leaves(node["first"]) + _leaves(node["second"])


def test_foxglove_layout_file_matches_the_contract(recording, bundle):
    """docs/foxglove-layout.json: a well-formed exported layout whose panels use the SDK's
    layout key names and plot contract topics and fields (the app itself is not available
    here: docs/live.md says what this does not verify)."""
    layout = json.loads(LAYOUT.read_text())
    assert set(layout) == {
        "configById",
        "globalVariables",
        "userNodes",
        "linkedGlobalVariables",
        "playbackConfig",
        "layout",
    }
    panels = _leaves(layout["layout"])
    assert len(panels) == len(set(panels)) and set(panels) == set(layout["configById"])

    # message paths: topic + field (nested for the diagnosis), resolved in the contract schemas
    with contextlib.closing(iter_windows(recording, WINDOW)) as stream:  # no file left open
        example = window_diagnoser(bundle)(next(stream))  # what live and replay publish
    schemas = {t: topic_schema(t, list(pairs)) for t, pairs in TOPIC_FIELDS.items()}
    schemas[TOPIC_DIAGNOSIS] = diagnosis_schema(example)
    paths, kinds = [], set()
    for panel_id, config in layout["configById"].items():
        kind = panel_id.split("!")[0]
        kinds.add(kind)
        config_cls, item_cls, items = PANELS[kind]
        _check_keys(config, config_cls)
        for item in config.get(items, []) if items else []:
            _check_keys(item, item_cls)
            if "value" in item:
                paths.append(item["value"])
        paths += [config[k] for k in ("path", "topicPath") if k in config]
        if kind == "Indicator":
            states = {*FAULT_CLASSES, CANNOT_TELL, OBSERVABLE}
            assert {r["rawValue"] for r in config["rules"]} <= states
    assert kinds == set(PANELS)
    for path in paths:
        topic, _, rest = path.partition(".")
        node = schemas[topic]
        for part in rest.split(".") if rest else []:
            assert part in node["properties"], path
            node = node["properties"][part]
    # the brief's panels: both signal topics, the clearance and its interval, the fault class
    assert {
        "/prsm/nut_accel.axial",
        "/prsm/drive.drive_torque",
        "/prsm/diagnosis.fault_class",
    } <= set(paths)
    # the clearance and its interval as a plot draws them: gaps where not observable (issue
    # 44), the state beside in words
    clearance = {
        f"/prsm/diagnosis.shown.{k}" for k in ("clearance", "clearance_lower", "clearance_upper")
    }
    assert any(
        {s["value"] for s in c.get("paths", [])} == clearance for c in layout["configById"].values()
    )
    assert "/prsm/diagnosis.shown.clearance_state" in paths
