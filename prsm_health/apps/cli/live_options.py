"""The ``--live`` options of ``replay`` and ``simulate`` (:mod:`.live`, docs/live.md)."""

from __future__ import annotations

from .options import port, positive_int, rate

#: ``--live`` defaults and message budget (prsm_health.apps.live, which imports foxglove).
LIVE_HOST, LIVE_PORT, LIVE_MESSAGE_BUDGET = "127.0.0.1", 8765, 20_000


def add_live_options(p, *, rate_option: bool) -> None:
    """The ``--live`` options of ``replay`` and ``simulate``."""
    p.add_argument(
        "--live",
        action="store_true",
        help="play the recording to Foxglove over its WebSocket protocol, with the diagnosis "
        "of each window (docs/live.md)",
    )
    p.add_argument(
        "--host",
        default=LIVE_HOST,
        help="--live: bind address (the protocol has no authentication: keep it local)",
    )
    p.add_argument(
        "--port", type=port, default=LIVE_PORT, help="--live: TCP port (0: any free port)"
    )
    if rate_option:
        p.add_argument("--rate", type=rate, default=1.0, help="--live: real-time factor, or 'max'")
    p.add_argument(
        "--live-decimate",
        type=positive_int,
        default=None,
        metavar="N",
        default_text=f"the smallest N that keeps all topics under {LIVE_MESSAGE_BUDGET} "
        "messages/s: 2 for a 20 kHz recording, 3 with truth",
        help="--live: publish every Nth sample",
    )
