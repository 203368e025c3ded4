#!/usr/bin/env python3
"""WebSocket fan-out of `synbench serve`: N clients subscribed to telemetry at R Hz; per message
the delivery latency = client receive time - the message's sent_unix_ms (set when the hub built
it, so it includes the session's queue, the socket and the client). One client process, one
thread, select() over every socket, so the client adds little of its own. Reports p50/p99/max
latency, the rate each client got and the daemon's CPU time.

usage: ws_fanout_bench.py path/to/synbench [--clients 50] [--rate-hz 20] [--seconds 30] [--smoke]
  --smoke: 5 clients for 3 s, checks that every client receives telemetry (for ctest).
"""
import json
import os
import selectors
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "server"))
from daemon import Daemon  # noqa: E402
from script_args import flag, option  # noqa: E402
from ws_util import connect, recv_until  # noqa: E402


def cpu_s(pid):
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def percentile(xs, p):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(p / 100.0 * (len(xs) - 1))))] if xs else float("nan")


def main():
    smoke = flag("--smoke")
    clients = option("--clients", 5 if smoke else 50)
    rate_hz = option("--rate-hz", 20.0)
    seconds = option("--seconds", 3.0 if smoke else 30.0)
    tmp = tempfile.mkdtemp(prefix="synbench-ws-bench-")
    d = Daemon(sys.argv[1], os.path.join(tmp, "data"))
    try:
        viewer = d.token("viewer")
        sel = selectors.DefaultSelector()
        socks = []
        for i in range(clients):
            ws, hello = connect(d, viewer)
            assert hello["type"] == "hello", hello
            ws.send(json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": rate_hz}))
            recv_until(ws, lambda m: m["type"] == "subscribed")
            ws.settimeout(5)
            sel.register(ws.sock, selectors.EVENT_READ, (i, ws))
            socks.append(ws)
        # What queued while the others connected is not a delivery latency: drain it first.
        drain_until = time.time() + 1.0
        while time.time() < drain_until:
            for key, _ in sel.select(timeout=0.05):
                key.data[1].recv()
        counts = [0] * clients
        latencies_ms, wake_latencies_ms = [], []
        cpu0 = cpu_s(d.proc.pid)
        t0 = time.time()
        while time.time() - t0 < seconds:
            ready = sel.select(timeout=0.5)
            # Every socket in `ready` had its data when select returned: latency to the wake-up
            # excludes this client's own serial processing of the batch.
            wake_ms = time.time() * 1000.0
            for key, _ in ready:
                i, ws = key.data
                raw = ws.recv()
                now_ms = time.time() * 1000.0
                m = json.loads(raw)
                if m["type"] != "telemetry":
                    continue
                counts[i] += 1
                latencies_ms.append(now_ms - m["sent_unix_ms"])
                wake_latencies_ms.append(wake_ms - m["sent_unix_ms"])
        elapsed = time.time() - t0
        cpu = cpu_s(d.proc.pid) - cpu0
        for ws in socks:
            ws.close()
    finally:
        rc, _ = d.stop()
    rates = [c / elapsed for c in counts]
    print("clients %d at %g Hz for %.1f s: %d messages" % (clients, rate_hz, elapsed, sum(counts)))
    print("per-client rate: min %.2f Hz, max %.2f Hz" % (min(rates), max(rates)))
    print("delivery latency: p50 %.2f ms, p99 %.2f ms, max %.2f ms" % (
        percentile(latencies_ms, 50), percentile(latencies_ms, 99), max(latencies_ms) if latencies_ms else float("nan")))
    print("latency to the client's wake-up: p50 %.2f ms, p99 %.2f ms" % (
        percentile(wake_latencies_ms, 50), percentile(wake_latencies_ms, 99)))
    print("daemon CPU: %.2f s in %.1f s (%.1f %% of one core)" % (cpu, elapsed, 100.0 * cpu / elapsed))
    if smoke and (min(counts) == 0 or rc != 0):
        print("FAIL: a client received no telemetry, or the daemon did not exit 0")
        sys.exit(1)


if __name__ == "__main__":
    main()
