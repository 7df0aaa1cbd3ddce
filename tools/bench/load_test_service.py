"""Bounded load test of the HTTP diagnostics service (``prsm-health serve``).

Starts the service in a subprocess on 127.0.0.1 (a free port, a bearer token, a throw-away
history database), sends a fixed number of ``POST /v1/diagnose`` requests from concurrent
clients (each a simulated recording of ``--window`` seconds at ``--sample-rate``, stored in an
asset's history; ``--body`` json, arrow, parquet, mcap, or multipart for a Parquet upload to
``/v1/diagnose/file``), polls ``GET /v1/health`` meanwhile, then stops the service. The run ends
when every request is answered or at ``--time-cap`` seconds, whichever comes first.

Prints throughput, latency percentiles, errors, and the /v1/health latency under load::

    python tools/bench/load_test_service.py                 # 8 clients, 160 requests, 1 s at 20 kHz
    python tools/bench/load_test_service.py --clients 4 --requests 40 --json
    python tools/bench/load_test_service.py --body arrow --processes 2

Targets only 127.0.0.1: the service it measures is the one it starts.
"""

from __future__ import annotations

import argparse
import json
import os
import secrets
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _recording(window: float, sample_rate: float):
    from prsm_health import HealthState, OperatingProfile, SimulationOptions, simulate

    return simulate(
        "paper01",
        HealthState.uniform(20e-6),
        OperatingProfile(
            duration=window,
            load=0.0,
            load_profile="reversing",
            load_amplitude=300.0,
            load_frequency=10.0,
            accel_time=0.002,
        ),
        {"profile": "ideal", "sample_rate": sample_rate},
        7,
        options=SimulationOptions(contact_law="hertz"),
    )


#: Content types of the binary bodies of POST /v1/diagnose.
BODY_TYPES = {
    "arrow": "application/vnd.apache.arrow.stream",
    "parquet": "application/vnd.apache.parquet",
    "mcap": "application/vnd.mcap",
}


def _binary(rec, fmt: str) -> bytes:
    """The measured recording (truth left out) as a file of format ``fmt``, in memory."""
    measured = rec.without_truth()
    if fmt == "arrow":
        from prsm_health.io.arrow import write_run_arrow

        return write_run_arrow(measured)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"recording.{fmt}"
        if fmt == "parquet":
            from prsm_health.io.parquet import write_run_parquet

            write_run_parquet(measured, path)
        else:
            from prsm_health.io.mcap import write_mcap

            write_mcap(measured, path)
        return path.read_bytes()


def _cpu_seconds(server_pid: int) -> dict | None:
    """CPU time [s] used so far by the server process, its diagnosis processes and this load
    generator (None without psutil)."""
    try:
        import psutil
    except ImportError:
        return None
    try:
        server = psutil.Process(server_pid)
        children = server.children(recursive=True)
        used = {"server": sum(server.cpu_times()[:2])}
        used["diagnosis_processes"] = sum(sum(c.cpu_times()[:2]) for c in children)
        used["load_generator"] = sum(psutil.Process().cpu_times()[:2])
        machine = psutil.cpu_times()
    except psutil.Error:
        return None
    # busy time of every CPU of the machine: what exceeds the three above is other work
    used["machine_busy"] = sum(
        getattr(machine, name, 0.0)
        for name in ("user", "nice", "system", "irq", "softirq", "steal")
    )
    return used


def _http_parser(http: str) -> str:
    """The HTTP parser the service runs with (it runs in this interpreter's environment)."""
    if http != "auto":
        return http
    try:
        import httptools  # noqa: F401
    except ImportError:
        return "h11 (auto)"
    return "httptools (auto)"


def _percentiles(values: list[float]) -> dict:
    if not values:
        return {"n": 0}
    a = np.asarray(values) * 1e3
    return {
        "n": len(values),
        "p50_ms": float(np.percentile(a, 50)),
        "p90_ms": float(np.percentile(a, 90)),
        "p99_ms": float(np.percentile(a, 99)),
        "max_ms": float(a.max()),
    }


class _Service:
    """``serve`` in a subprocess; stopped with SIGINT (uvicorn's graceful shutdown)."""

    def __init__(
        self,
        db: Path,
        model: str | None,
        workers: int | None,
        processes: int,
        profile: str | None = None,
        http: str = "auto",
    ):
        self.port = _free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.token = secrets.token_urlsafe(24)
        settings = {"workers": workers, "processes": processes}
        limits = f"ServiceLimits(**{ {k: v for k, v in settings.items() if v}!r})"
        http_arg = "" if http == "auto" else f", http={http!r}"  # auto: serve's default
        call = (
            f"serve('127.0.0.1', {self.port}, sys.argv[1] or None, sys.argv[2], "
            f"limits={limits}, log_level='warning'{http_arg})"
        )
        if profile:  # the server's main thread (event loop) under cProfile, stats on exit
            call = f"import cProfile\ncProfile.run({call!r}, {str(profile)!r})"
        code = f"import sys\nfrom prsm_health.apps.service import ServiceLimits, serve\n{call}\n"
        env = {**os.environ, "PRSM_HEALTH_TOKEN": self.token}
        self.log_path = db.with_name("service.log")
        self._log = open(self.log_path, "wb")  # noqa: SIM115 - closed in stop()
        self.proc = subprocess.Popen(
            [sys.executable, "-c", code, model or "", str(db)],
            env=env,
            stdout=self._log,
            stderr=subprocess.STDOUT,
        )

    def wait_ready(self, timeout: float) -> dict:
        import httpx

        deadline = time.monotonic() + timeout
        headers = {"Authorization": f"Bearer {self.token}"}
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise SystemExit(f"service exited with status {self.proc.returncode}")
            try:
                r = httpx.get(f"{self.url}/v1/health", headers=headers, timeout=2)
                if r.status_code == 200 and r.json().get("warm"):
                    return r.json()
            except httpx.TransportError:
                pass
            time.sleep(0.2)
        raise SystemExit(f"service not ready after {timeout:g} s")

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self._log.close()

    def log_tail(self, lines: int = 40) -> str:
        text = self.log_path.read_text(errors="replace").splitlines()
        return "\n".join(text[-lines:])


def run(args) -> dict:
    import httpx

    from prsm_health.apps.service import ServiceLimits

    if args.recording:
        from prsm_health.io import read_recording

        rec = read_recording(args.recording).without_truth()
        args.window = len(rec) / rec.sample_rate
    else:
        rec = _recording(args.window, args.sample_rate)
    if args.body == "json":
        payloads = [
            json.dumps(
                {
                    "sample_rate": rec.sample_rate,
                    "channels": {k: v.tolist() for k, v in rec.channels.items()},
                    "asset_id": f"load-test-{c}",
                }
            ).encode()
            for c in range(args.clients)
        ]
        body_bytes = len(payloads[0])
    elif args.body == "multipart":  # a Parquet file uploaded as multipart form data
        parquet = _binary(rec, "parquet")
        payloads = [
            {
                "files": {"file": ("recording.parquet", parquet)},
                "data": {"asset_id": f"load-test-{c}"},
            }
            for c in range(args.clients)
        ]
        body_bytes = len(parquet)
    else:  # the recording as a binary body of POST /v1/diagnose, asset in the query
        binary = _binary(rec, args.body)
        payloads = [
            {
                "content": binary,
                "headers": {"content-type": BODY_TYPES[args.body]},
                "params": {"asset_id": f"load-test-{c}"},
            }
            for c in range(args.clients)
        ]
        body_bytes = len(binary)
    with tempfile.TemporaryDirectory(prefix="prsm-health-load-") as tmp:
        service = _Service(
            Path(tmp) / "history.sqlite",
            args.model,
            args.workers,
            args.processes,
            args.profile_server,
            args.http,
        )
        try:
            ready = service.wait_ready(args.startup_timeout)
            headers = {"Authorization": f"Bearer {service.token}"}
            lock = threading.Lock()
            issued = 0
            latencies: list[float] = []
            errors: list[str] = []
            health: list[float] = []
            health_errors: list[str] = []
            done = threading.Event()
            start = time.perf_counter()
            deadline = start + args.time_cap

            def client(k: int) -> None:
                nonlocal issued
                with httpx.Client(
                    base_url=service.url, headers=headers, timeout=args.time_cap
                ) as c:
                    while True:
                        with lock:
                            if issued >= args.requests or time.perf_counter() > deadline:
                                return
                            issued += 1
                        t0 = time.perf_counter()
                        try:
                            if args.body == "json":
                                r = c.post(
                                    "/v1/diagnose",
                                    content=payloads[k],
                                    headers={"content-type": "application/json"},
                                )
                            elif args.body == "multipart":
                                r = c.post("/v1/diagnose/file", **payloads[k])
                            else:
                                r = c.post("/v1/diagnose", **payloads[k])
                            ok = r.status_code == 200
                            problem = None if ok else f"{r.status_code}: {r.text[:200]}"
                        except httpx.HTTPError as exc:
                            problem = f"{type(exc).__name__}: {exc}"
                        elapsed = time.perf_counter() - t0
                        with lock:
                            if problem is None:
                                latencies.append(elapsed)
                            else:
                                errors.append(problem)

            def poll_health() -> None:
                with httpx.Client(base_url=service.url, headers=headers, timeout=30) as c:
                    while not done.is_set():
                        t0 = time.perf_counter()
                        try:
                            r = c.get("/v1/health")
                            if r.status_code == 200:
                                health.append(time.perf_counter() - t0)
                            else:
                                health_errors.append(str(r.status_code))
                        except httpx.HTTPError as exc:
                            health_errors.append(type(exc).__name__)
                        done.wait(args.health_interval)

            poller = threading.Thread(target=poll_health, daemon=True)
            cpu_before = _cpu_seconds(service.proc.pid)
            poller.start()
            clients = [threading.Thread(target=client, args=(k,)) for k in range(args.clients)]
            for t in clients:
                t.start()
            for t in clients:
                t.join()
            elapsed = time.perf_counter() - start
            cpu_after = _cpu_seconds(service.proc.pid)
            done.set()
            poller.join()
            with httpx.Client(base_url=service.url, headers=headers, timeout=30) as c:
                stored = sum(
                    c.get(f"/v1/assets/load-test-{k}/history", params={"limit": 1})
                    .json()
                    .get("total", 0)
                    for k in range(args.clients)
                )
        finally:
            service.stop()
            server_log = service.log_tail() if service.log_path.exists() else ""
    n_ok = len(latencies)
    cpu = other_cpus = None
    if cpu_before and cpu_after:
        used = {k: cpu_after[k] - cpu_before[k] for k in cpu_before}
        busy = used.pop("machine_busy")
        cpu = {k: 1e3 * v / max(n_ok, 1) for k, v in used.items()}
        # CPUs kept busy by other processes meanwhile (other jobs disturb the measurement)
        other_cpus = max(0.0, busy - sum(used.values())) / elapsed if elapsed > 0 else 0.0
    return {
        "clients": args.clients,
        "requests": args.requests,
        "answered": n_ok + len(errors),
        "window_s": args.window,
        "sample_rate_hz": rec.sample_rate,
        "samples_per_request": len(rec),
        "channels_per_request": len(rec.channels),
        "request_bytes": body_bytes,
        "body": args.body,
        "server_workers": args.workers or ServiceLimits().workers,
        "server_processes": args.processes,
        "server_http": _http_parser(args.http),
        "cpu_count": os.cpu_count(),
        "model": f"{ready['model']} v{ready['version']}",
        "elapsed_s": elapsed,
        "time_capped": n_ok + len(errors) < args.requests,
        "throughput_rps": n_ok / elapsed if elapsed > 0 else 0.0,
        "signal_seconds_per_s": n_ok * args.window / elapsed if elapsed > 0 else 0.0,
        "latency": _percentiles(latencies),
        "errors": len(errors),
        "error_examples": errors[:5],
        "stored_in_history": stored,
        "health_under_load": _percentiles(health),
        "health_errors": len(health_errors),
        "cpu_ms_per_request": cpu,
        "other_processes_cpus": other_cpus,
        "server_log_tail": server_log if (errors or health_errors) else "",
    }


def _report(r: dict) -> str:
    lat, h = r["latency"], r["health_under_load"]
    lines = [
        f"service load test: {r['clients']} clients, {r['answered']}/{r['requests']} requests answered"
        f"{' (time cap reached)' if r['time_capped'] else ''} in {r['elapsed_s']:.1f} s",
        f"  request: {r['window_s']:g} s at {r['sample_rate_hz']:g} Hz, {r['samples_per_request']} samples"
        f" x {r['channels_per_request']} channels, {r['request_bytes'] / 1e6:.1f} MB {r['body']}; model {r['model']}",
        f"  machine: {r['cpu_count']} CPUs, server workers {r['server_workers']}, diagnosis processes {r['server_processes']}, HTTP {r['server_http']}",
        f"  throughput: {r['throughput_rps']:.2f} diagnoses/s ({r['signal_seconds_per_s']:.2f} s of signal per s)",
    ]
    if lat["n"]:
        lines.append(
            f"  latency: p50 {lat['p50_ms']:.0f} ms, p90 {lat['p90_ms']:.0f} ms, "
            f"p99 {lat['p99_ms']:.0f} ms, max {lat['max_ms']:.0f} ms"
        )
    lines.append(f"  errors: {r['errors']}  (stored in history: {r['stored_in_history']})")
    for e in r["error_examples"]:
        lines.append(f"    {e}")
    if h["n"]:
        lines.append(
            f"  /v1/health under load ({h['n']} polls): p50 {h['p50_ms']:.1f} ms, "
            f"p99 {h['p99_ms']:.1f} ms, max {h['max_ms']:.1f} ms, errors {r['health_errors']}"
        )
    if r.get("cpu_ms_per_request"):
        lines.append(
            "  CPU per answered request: "
            + ", ".join(
                f"{k.replace('_', ' ')} {v:.1f} ms" for k, v in r["cpu_ms_per_request"].items()
            )
        )
        lines.append(
            f"  other processes on the machine meanwhile: {r['other_processes_cpus']:.2f} CPUs busy"
        )
    if r["server_log_tail"]:
        lines.append("  server log (tail):")
        lines.extend("    " + line for line in r["server_log_tail"].splitlines())
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--clients", type=int, default=8, help="concurrent clients")
    p.add_argument("--requests", type=int, default=160, help="diagnose requests in total")
    p.add_argument("--time-cap", type=float, default=180.0, help="stop issuing after this [s]")
    p.add_argument("--window", type=float, default=1.0, help="recording per request [s]")
    p.add_argument(
        "--recording",
        default=None,
        help="send this recording (.parquet, .mcap or .csv) instead of simulating one "
        "(--window and --sample-rate then come from it)",
    )
    p.add_argument("--sample-rate", type=float, default=20000.0, help="[Hz]")
    p.add_argument("--health-interval", type=float, default=0.05, help="/v1/health poll period [s]")
    p.add_argument(
        "--processes", type=int, default=0, help="server diagnosis processes (0: threads)"
    )
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        help="server diagnosis threads (default: half the CPUs)",
    )
    p.add_argument("--model", default=None, help="model bundle (default: the shipped model)")
    p.add_argument("--startup-timeout", type=float, default=180.0, help="[s]")
    p.add_argument("--json", action="store_true", help="machine-readable result")
    p.add_argument(
        "--http",
        choices=("auto", "httptools", "h11"),
        default="auto",
        help="the server's HTTP parser (auto: httptools when installed, else h11)",
    )
    p.add_argument(
        "--profile-server",
        metavar="FILE",
        default=None,
        help="run the server's main thread (event loop) under cProfile and write the stats "
        "to FILE when it stops (read with python -m pstats FILE)",
    )
    p.add_argument(
        "--body",
        choices=("json", "arrow", "parquet", "mcap", "multipart"),
        default="json",
        help="request body of POST /v1/diagnose: the JSON contract, or the recording as an "
        "Arrow IPC stream, a Parquet file or an MCAP file; multipart: a Parquet file uploaded "
        "to POST /v1/diagnose/file",
    )
    args = p.parse_args(argv)
    if not (1 <= args.clients <= 64 and 1 <= args.requests <= 10_000 and 0 < args.time_cap <= 3600):
        p.error("keep it bounded: 1-64 clients, 1-10000 requests, time cap in (0, 3600] s")
    result = run(args)
    print(json.dumps(result, indent=2) if args.json else _report(result))
    return 1 if result["errors"] or result["health_errors"] else 0


if __name__ == "__main__":
    sys.exit(main())
