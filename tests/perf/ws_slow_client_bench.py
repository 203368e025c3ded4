#!/usr/bin/env python3
"""The telemetry rate a WebSocket client of `synbench serve` gets while another client stalls: one
client (small SO_RCVBUF) subscribes to telemetry at 50 Hz and to events and then reads nothing, as
tests/server/ws_slow_client_test.py's does, until the daemon drops it; another reads telemetry at
R Hz all along. Reports the good client's rate in every W s window (worst, mean, best; the target
is R +/- 15 %), its longest gap between two messages, and when the slow client was dropped.

usage: ws_slow_client_bench.py path/to/synbench [--rate-hz 20] [--seconds 60] [--window-s 5] [--smoke]
  --smoke: 6 s in 2 s windows, checks that the good client receives telemetry and its connection
  holds (for ctest; no rate is asserted).
"""
import os
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "server"))
from daemon import Daemon  # noqa: E402
from script_args import flag, option  # noqa: E402
from ws_util import TelemetryReader, stalled_client  # noqa: E402

TOLERANCE = 0.15


def main():
    smoke = flag("--smoke")
    rate_hz = option("--rate-hz", 20.0)
    seconds = option("--seconds", 6.0 if smoke else 60.0)
    window_s = option("--window-s", 2.0 if smoke else 5.0)
    tmp = tempfile.mkdtemp(prefix="synbench-ws-slow-bench-")
    d = Daemon(sys.argv[1], os.path.join(tmp, "data"))
    dropped_at = []

    def read_stderr():
        for line in d.proc.stderr:
            if "dropped" in line:
                dropped_at.append(time.time())

    threading.Thread(target=read_stderr, daemon=True).start()
    try:
        viewer = d.token("viewer")
        slow, _ = stalled_client(d, viewer)
        good = TelemetryReader(d, viewer, rate_hz)
        time.sleep(1.0)
        t0 = time.time()
        time.sleep(seconds)
        good.stop()
        slow.sock.close()
    finally:
        rc, _ = d.stop(read_stderr=False)
    times = [t for t in good.times if t0 <= t < t0 + seconds]
    windows = int(seconds // window_s)
    starts = [t0 + w * window_s for w in range(windows)]
    rates = [sum(1 for t in times if lo <= t < lo + window_s) / window_s for lo in starts]
    gaps = [b - a for a, b in zip(times, times[1:])]
    worst = max(rates, key=lambda r: abs(r - rate_hz)) if rates else float("nan")
    print("good client at %g Hz for %.0f s while a client stalls, in %g s windows:" % (rate_hz, seconds, window_s))
    print("  rate: worst %.2f Hz, mean %.2f Hz, min %.2f Hz, max %.2f Hz; %s %g Hz +/- %.0f %% in every window" % (
        worst, len(times) / seconds, min(rates or [float("nan")]), max(rates or [float("nan")]),
        "within" if rates and abs(worst - rate_hz) <= TOLERANCE * rate_hz else "NOT within", rate_hz, 100 * TOLERANCE))
    print("  longest gap between two messages: %.0f ms" % (1000 * max(gaps) if gaps else float("nan")))
    print("  slow client dropped after %s" % ("%.1f s" % (dropped_at[0] - t0) if dropped_at else "-- (not in the run)"))
    if good.errors:
        print("  the good client's connection ended: %s" % good.errors)
    if smoke and (not times or good.errors or rc != 0):
        print("FAIL: the good client got no telemetry or lost its connection, or the daemon exited %s" % rc)
        sys.exit(1)


if __name__ == "__main__":
    main()
