"""Benchmark the live Foxglove view (prsm_health.apps.live) with a real WebSocket client.

Measured side by side in one run, on a simulated 1 s flight-ema recording at 20 kHz (truth
kept: three topics):

1. message payloads: ``prsm_health.io.mcap.writer.sample_payloads`` (one %-template per topic)
   against ``json.dumps`` of a dict per sample, the code a user would write;
2. ``LivePlayer`` publishing every sample to one local aiohttp client subscribed to every
   topic, at ``--rate max`` and at real time: messages per second of wall time and the share
   the client received (a slow client's oldest messages are dropped when its backlog fills).

    python tools/bench/bench_live.py [--duration 1.0]
"""

from __future__ import annotations

import argparse
import asyncio
import json
import threading
import time
from pathlib import Path

import aiohttp

from prsm_health import HealthState, OperatingProfile, simulate
from prsm_health.apps.live import LivePlayer
from prsm_health.io.mcap.writer import sample_payloads

ROOT = Path(__file__).resolve().parents[2]

SUBPROTOCOLS = ("foxglove.sdk.v1", "foxglove.websocket.v1")


async def _count(url: str, n_topics: int, done: threading.Event, got: dict) -> None:
    async with aiohttp.ClientSession() as session:
        async with session.ws_connect(url, protocols=SUBPROTOCOLS, max_msg_size=0) as ws:
            channels = []
            while True:
                try:
                    msg = await asyncio.wait_for(ws.receive(), 0.5)
                except asyncio.TimeoutError:
                    if done.is_set():
                        return
                    continue
                if msg.type == aiohttp.WSMsgType.TEXT:
                    data = json.loads(msg.data)
                    if data["op"] == "advertise" and not channels:
                        channels = data["channels"][:n_topics]
                        subscribe = [
                            {"id": k, "channelId": c["id"]} for k, c in enumerate(channels)
                        ]
                        await ws.send_str(
                            json.dumps({"op": "subscribe", "subscriptions": subscribe})
                        )
                elif msg.type == aiohttp.WSMsgType.BINARY:
                    got["n"] += 1
                else:
                    return


def play(run, rate) -> tuple[float, int, int]:
    """(messages/s of wall time, sent, received) for one played run."""
    with LivePlayer(run, rate=rate, decimate=1, port=0) as player:
        done, got, result = threading.Event(), {"n": 0}, {}

        def serve():
            if player.wait_for_client(timeout=15):
                result["stats"] = player.play()
            done.set()

        thread = threading.Thread(target=serve)
        thread.start()
        asyncio.run(_count(player.url, len(player.topics), done, got))
        thread.join(30)
    stats = result["stats"]
    sent = stats.published * len(player.topics)
    return sent / stats.wall_time, sent, got["n"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--duration", type=float, default=1.0)
    args = parser.parse_args()
    run = simulate(
        "paper01", HealthState(), OperatingProfile(duration=args.duration), "flight-ema", 1
    )
    fields = ["axial", "tangential", "radial_x", "radial_y"]
    columns = [run.channels["nut_axial_accel"]] * 4
    t0 = time.perf_counter()
    sample_payloads(fields, columns)
    ours = (time.perf_counter() - t0) / len(run)
    t0 = time.perf_counter()
    for row in zip(*[c.tolist() for c in columns]):
        json.dumps(dict(zip(fields, row))).encode()
    plain = (time.perf_counter() - t0) / len(run)
    print("| what | prsm_health | baseline | ratio |\n|---|---|---|---|")
    print(
        f"| JSON payload of one 4-field sample | {ours * 1e6:.2f} µs (`sample_payloads`) | "
        f"{plain * 1e6:.2f} µs (`json.dumps` of a dict) | {plain / ours:.1f}× |"
    )
    for rate, label in ((None, "max"), (1.0, "real time")):
        speed, sent, received = play(run, rate)
        print(
            f"| LivePlayer, every sample, {label} | {speed:,.0f} messages/s, "
            f"{received}/{sent} received ({received / sent:.0%}) | – | – |"
        )


if __name__ == "__main__":
    main()
