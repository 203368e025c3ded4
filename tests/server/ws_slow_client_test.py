#!/usr/bin/env python3
"""A WebSocket client that stops reading must not cost the daemon memory or other clients their
rate. One client (small SO_RCVBUF) subscribes to telemetry at 50 Hz and to events, then reads
nothing for 60 s; another reads telemetry at 20 Hz all along. Checks: the daemon's RSS
(/proc/PID/status VmRSS) grows by less than 10 MB, the slow client is dropped (the daemon says
so on stderr; its socket ends in EOF or a reset), and the other client keeps 20 Hz +/- 15 % in
every 5 s window. Takes about 70 s.

usage: ws_slow_client_test.py path/to/synbench [--seconds N]
"""
import json
import os
import socket
import sys
import tempfile
import threading
import time

from ws_util import Daemon, connect, recv_until, websocket

BIN = sys.argv[1]
SECONDS = float(sys.argv[sys.argv.index("--seconds") + 1]) if "--seconds" in sys.argv else 60.0
WINDOW_S = 5.0
failures = []


def check(cond, what):
    print(("ok: " if cond else "FAIL: ") + what)
    if not cond:
        failures.append(what)


def main():
    tmp = tempfile.mkdtemp(prefix="synbench-ws-slow-")
    d = Daemon(BIN, os.path.join(tmp, "data"))
    stderr_lines = []

    def read_stderr():
        for line in d.proc.stderr:
            stderr_lines.append((time.time(), line.rstrip()))

    threading.Thread(target=read_stderr, daemon=True).start()
    try:
        viewer = d.token("viewer")
        # The slow client: a receive buffer of a few KiB so the daemon's side fills quickly.
        slow, hello = connect(d, viewer, sockopt=((socket.SOL_SOCKET, socket.SO_RCVBUF, 4096),))
        check(hello["type"] == "hello", "slow client authenticated")
        slow.send(json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": 50}))
        slow.send(json.dumps({"op": "subscribe", "channel": "events"}))
        recv_until(slow, lambda m: m["type"] == "state")

        good, _ = connect(d, viewer)
        good.send(json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": 20}))
        recv_until(good, lambda m: m["type"] == "telemetry")
        arrivals = []
        stop = threading.Event()

        def read_good():
            good.settimeout(1.0)
            while not stop.is_set():
                try:
                    m = json.loads(good.recv())
                except websocket.WebSocketTimeoutException:
                    continue
                except Exception as e:  # noqa: BLE001 - the check below reports it
                    arrivals.append(("error", str(e)))
                    return
                if m["type"] == "telemetry":
                    arrivals.append(time.time())

        reader = threading.Thread(target=read_good, daemon=True)
        reader.start()
        time.sleep(1.0)
        rss0 = d.rss_kB()
        t0 = time.time()
        # The slow client now reads nothing at all.
        rss_max = rss0
        while time.time() - t0 < SECONDS:
            time.sleep(1.0)
            rss_max = max(rss_max, d.rss_kB())
        stop.set()
        reader.join(timeout=3)

        growth_MB = (rss_max - rss0) / 1024.0
        check(growth_MB < 10, "daemon RSS grows %.2f MB (< 10 MB) over %.0f s (from %.1f MB)" % (growth_MB, SECONDS, rss0 / 1024.0))
        drops = [(t, l) for t, l in stderr_lines if "dropped" in l]
        check(len(drops) == 1, "the daemon drops the slow client (%s)" % [l for _, l in drops])
        if drops:
            check(drops[0][0] - t0 < 30, "dropped after %.1f s (< 30 s): %s" % (drops[0][0] - t0, drops[0][1]))
        # Its socket: what the kernel still held, then EOF or a reset.
        slow.sock.settimeout(10)
        ended, drained = False, 0
        try:
            while True:
                chunk = slow.sock.recv(65536)
                if not chunk:
                    ended = True
                    break
                drained += len(chunk)
        except (ConnectionResetError, BrokenPipeError):
            ended = True
        except socket.timeout:
            pass
        check(ended, "the slow client's socket ends (EOF or reset) after %d buffered bytes" % drained)

        errors = [a for a in arrivals if isinstance(a, tuple)]
        check(not errors, "the good client's connection held (%s)" % errors)
        times = [a for a in arrivals if not isinstance(a, tuple)]
        windows = int(SECONDS // WINDOW_S)
        worst = None
        for w in range(windows):
            lo = t0 + w * WINDOW_S
            n = sum(1 for t in times if lo <= t < lo + WINDOW_S)
            rate = n / WINDOW_S
            if worst is None or abs(rate - 20) > abs(worst - 20):
                worst = rate
            if abs(rate - 20) > 3:
                check(False, "good client at 20 Hz in window %d: %.1f Hz" % (w, rate))
        total_rate = len(times) / SECONDS
        check(worst is not None and abs(worst - 20) <= 3,
              "good client keeps 20 Hz +/- 15 %% in every %g s window (worst %.1f Hz, overall %.2f Hz)" % (WINDOW_S, worst or 0, total_rate))
        good.close()
    finally:
        rc, _ = d.stop(read_stderr=False)
    check(rc == 0, "SIGTERM -> exit 0 (%s)" % rc)
    if failures:
        print("%d failure(s)" % len(failures))
        sys.exit(1)
    print("ws slow client test ok")


if __name__ == "__main__":
    main()
