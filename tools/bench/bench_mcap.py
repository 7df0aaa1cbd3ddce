"""Benchmark: prsm_health's MCAP writer, reader and replay vs straightforward use of ``mcap``.

The baselines are what a user would write from the mcap documentation:

- write: ``mcap.writer.Writer`` (zstd chunks, summary — its defaults), one
  ``json.dumps(dict)`` and one ``add_message`` per sample and topic;
- read: ``make_reader(f).iter_messages()`` and ``json.loads`` per message into lists, then
  numpy arrays;
- replay: the same iterator in log-time order, cutting fixed windows.

Both sides handle the same messages (the two measured topics, 9 contract channels, one message
per sample and topic), and the script checks that each reads the other's file to the same values. The
signals are synthetic (sines + noise at full double precision, like simulator output), so the
JSON text has realistic lengths without running the simulator.

Usage::

    .venv/bin/python tools/bench/bench_mcap.py [--duration 2.0] [--rate 20000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
from mcap.reader import make_reader
from mcap.writer import Writer

from prsm_health.core.channels import CHANNEL_NAMES, MEASURED_TOPICS
from prsm_health.core.run import Run
from prsm_health.io.mcap import TOPIC_FIELDS, iter_windows, read_mcap, write_mcap

# A recording from hardware: the measured topics only (no /prsm/truth).
TOPICS = {topic: TOPIC_FIELDS[topic] for topic in MEASURED_TOPICS}


def synthetic_run(duration: float, rate: float) -> Run:
    n = int(round(duration * rate))
    t = np.arange(n) / rate
    rng = np.random.default_rng(0)
    channels = {}
    for k, name in enumerate(CHANNEL_NAMES):
        f = 37.0 * (k + 1)
        channels[name] = (k + 1) * np.sin(2 * np.pi * f * t) + 0.1 * rng.standard_normal(n)
    return Run(t, channels, rate, {"design": "paper01", "seed": 0}, {"design": "paper01"})


def baseline_write(run: Run, path: Path) -> None:
    with open(path, "wb") as f:
        writer = Writer(f)
        writer.start()
        topics = []
        for topic, pairs in TOPICS.items():
            schema = {
                "type": "object",
                "properties": {name: {"type": "number"} for name, _ in pairs},
            }
            sid = writer.register_schema(topic, "jsonschema", json.dumps(schema).encode())
            cid = writer.register_channel(topic, "json", sid)
            columns = [(name, run.channels[ch].tolist()) for name, ch in pairs]
            topics.append((cid, columns))
        writer.add_metadata("labels", {k: str(v) for k, v in run.labels.items()})
        writer.add_attachment(0, 0, "scenario.json", "application/json", b"{}")
        for i, t in enumerate(run.time.tolist()):
            ns = round(t * 1e9)
            for cid, columns in topics:
                body = {name: values[i] for name, values in columns}
                writer.add_message(cid, ns, json.dumps(body).encode(), ns)
        writer.finish()


def baseline_read(path: Path) -> dict[str, np.ndarray]:
    names = {topic: dict(pairs) for topic, pairs in TOPICS.items()}
    lists: dict[str, list] = {}
    with open(path, "rb") as f:
        for _, channel, message in make_reader(f).iter_messages():
            fields = names.get(channel.topic)
            if fields is None:
                continue
            for key, value in json.loads(message.data).items():
                lists.setdefault(fields[key], []).append(value)
    return {name: np.array(values) for name, values in lists.items()}


def baseline_replay(path: Path, window: float) -> int:
    names = {topic: dict(pairs) for topic, pairs in TOPICS.items()}
    window_ns = round(window * 1e9)
    end = window_ns
    current: dict[str, list] = {}
    windows = []
    with open(path, "rb") as f:
        for _, channel, message in make_reader(f).iter_messages(log_time_order=True):
            if message.log_time >= end:
                windows.append(len({k: np.array(v) for k, v in current.items()}))
                current = {}
                end += window_ns
            fields = names[channel.topic]
            for key, value in json.loads(message.data).items():
                current.setdefault(fields[key], []).append(value)
    return len(windows) + bool(current)


def best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=2.0, help="run length [s]")
    parser.add_argument("--rate", type=float, default=20_000.0, help="sample rate [Hz]")
    parser.add_argument("--repeat", type=int, default=3, help="best of this many runs")
    parser.add_argument("--window", type=float, default=0.1, help="replay window [s]")
    args = parser.parse_args()

    run = synthetic_run(args.duration, args.rate)
    messages = len(run) * len(TOPICS)
    with tempfile.TemporaryDirectory() as tmp:
        ours, theirs = Path(tmp) / "ours.mcap", Path(tmp) / "theirs.mcap"
        # Warm-up (imports, first-call costs), then check both sides agree.
        write_mcap(run, ours)
        baseline_write(run, theirs)
        mine, other = read_mcap(theirs), baseline_read(ours)
        for name in CHANNEL_NAMES:
            assert np.array_equal(mine[name], run[name]), name
            assert np.array_equal(other[name], run[name]), name

        rows = [
            (
                "write (Run → .mcap)",
                best(lambda: write_mcap(run, ours), args.repeat),
                best(lambda: baseline_write(run, theirs), args.repeat),
            ),
            (
                "read (.mcap → arrays)",
                best(lambda: read_mcap(ours), args.repeat),
                best(lambda: baseline_read(ours), args.repeat),
            ),
            (
                f"replay ({args.window:g} s windows)",
                best(lambda: list(iter_windows(ours, args.window)), args.repeat),
                best(lambda: baseline_replay(ours, args.window), args.repeat),
            ),
        ]
        sizes = ours.stat().st_size, theirs.stat().st_size

    print(
        f"{args.duration:g} s at {args.rate:g} Hz, {len(CHANNEL_NAMES)} channels: "
        f"{messages} messages on {len(TOPICS)} topics; best of {args.repeat}\n"
    )
    print("| operation | prsm_health [msg/s] | baseline mcap + json [msg/s] | speed-up |")
    print("|---|---:|---:|---:|")
    for label, t_ours, t_base in rows:
        print(
            f"| {label} | {messages / t_ours:,.0f} | {messages / t_base:,.0f} "
            f"| {t_base / t_ours:.1f}× |"
        )
    print(f"\nfile size: prsm_health {sizes[0] / 1e6:.2f} MB, baseline {sizes[1] / 1e6:.2f} MB")


if __name__ == "__main__":
    main()
