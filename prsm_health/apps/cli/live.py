"""``replay --live`` and ``simulate --live``: play a recording or a run to Foxglove
(:class:`prsm_health.apps.live.LivePlayer`) and say what happens, one line at a time."""

from __future__ import annotations

import signal
import sys

from ..live import LivePlayer

#: Bind addresses that only this machine reaches.
LOOPBACK = ("127.0.0.1", "localhost", "::1")


def play_live(source, args, bundle, window: float, *, rate: float | None) -> int:
    """Play ``source`` (a file or a Run) to Foxglove until its end, then keep the server up
    until Ctrl-C (exit 0)."""
    if args.host not in LOOPBACK:
        print(
            f"warning: --host {args.host}: the Foxglove WebSocket protocol has no "
            "authentication; anyone who reaches this address sees the recording",
            file=sys.stderr,
        )
    # Ctrl-C stops the server whatever this process inherited: a non-interactive shell starts
    # background jobs with SIGINT ignored, and a launcher may leave it blocked (`serve` too
    # installs its own handler).
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    live = None
    try:
        live = LivePlayer(
            source,
            window=window,
            bundle=bundle,
            host=args.host,
            port=args.port,
            rate=rate,
            decimate=args.live_decimate,
        )
        print(
            f"live: open {live.url} in Foxglove (Open connection → Foxglove WebSocket); "
            "playing starts when it subscribes; Ctrl-C stops",
            flush=True,
        )
        if bundle is not None and not live.diagnosing:
            print(
                f"warning: no complete {window:g} s window in the recording: "
                "no diagnosis is published",
                file=sys.stderr,
            )
        live.wait_for_client()
        stats = live.play()
        pace = "as fast as possible" if rate is None else f"at {rate:g}× real time"
        print(
            f"played {stats.samples} samples ({stats.log_span:.3f} s of log time) {pace} "
            f"in {stats.wall_time:.3f} s, every {live.decimate}. sample published, "
            f"{stats.diagnoses} diagnoses; the server stays up until Ctrl-C",
            flush=True,
        )
        live.hold()
    except KeyboardInterrupt:
        # A second Ctrl-C must not interrupt the shutdown with a traceback.
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
        try:
            if live is not None:
                live.close()
            print("stopped", file=sys.stderr)
        finally:
            signal.signal(signal.SIGINT, previous)
    finally:
        if live is not None:
            live.close()
    return 0
