#!/usr/bin/env python3
"""A WebSocket client that stops reading must not cost the daemon memory or other clients their
telemetry. One client (small SO_RCVBUF) subscribes to telemetry at 50 Hz and to events, then reads
nothing for 60 s; another reads telemetry at 20 Hz all along. Checks: the daemon's RSS
(/proc/PID/status VmRSS) grows by less than 10 MB, the slow client is dropped (the daemon says
so on stderr; its socket ends in EOF or a reset), and the other client's connection holds and it
keeps receiving telemetry after the drop. Takes about 70 s. The other client's rate while the
slow one stalls depends on the machine's load, so it is measured by a benchmark, not checked
here: tests/perf/ws_slow_client_bench.py.

usage: ws_slow_client_test.py path/to/synbench [--seconds N]
"""
import os
import socket
import sys
import tempfile
import threading
import time

from checks import Checks
from daemon import Daemon
from script_args import option
from ws_util import TelemetryReader, stalled_client

BIN = sys.argv[1]
SECONDS = option("--seconds", 60.0)
check = Checks(verbose=True)


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
        slow, hello = stalled_client(d, viewer)
        check(hello["type"] == "hello", "slow client authenticated")
        good = TelemetryReader(d, viewer, 20)
        time.sleep(1.0)
        rss0 = d.rss_kB()
        t0 = time.time()
        # The slow client now reads nothing at all.
        rss_max = rss0
        while time.time() - t0 < SECONDS:
            time.sleep(1.0)
            rss_max = max(rss_max, d.rss_kB())
        good.stop()

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

        check(not good.errors, "the good client's connection held (%s)" % good.errors)
        after_drop = [t for t in good.times if drops and t > drops[0][0]]
        check(len(after_drop) > 0, "the good client receives telemetry after the drop (%d messages in %.0f s)"
              % (len(after_drop), t0 + SECONDS - drops[0][0] if drops else 0))
    finally:
        rc, _ = d.stop(read_stderr=False)
    check(rc == 0, "SIGTERM -> exit 0 (%s)" % rc)
    check.finish("ws slow client test ok")


if __name__ == "__main__":
    main()
