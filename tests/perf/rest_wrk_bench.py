#!/usr/bin/env python3
"""REST throughput and latency of `synbench serve` under wrk (keep-alive connections): GET
/api/health (no token) and GET /api/bench/status (a viewer token, so the router hashes and
compares the token on every request), with the bench loop running. Reports requests/s and the
latency percentiles of `wrk --latency`.

usage: rest_wrk_bench.py path/to/synbench [--connections 50] [--threads 2] [--seconds 10] [--smoke]
  --smoke: 4 connections for 1 s per route, checks that requests succeed (for ctest; skipped,
  exit 77, without wrk).
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "server"))
from daemon import Daemon  # noqa: E402
from script_args import flag, option  # noqa: E402


def run_wrk(d, path, token, connections, threads, seconds):
    cmd = ["wrk", "-t%d" % threads, "-c%d" % connections, "-d%ds" % seconds, "--latency"]
    if token:
        cmd += ["-H", "Authorization: Bearer " + token]
    cmd.append("http://%s%s" % (d.host, path))
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    rps = float(re.search(r"Requests/sec:\s+([\d.]+)", out).group(1))
    pct = dict(re.findall(r"^\s+(50|75|90|99)%\s+(\S+)", out, re.M))
    non2xx = re.search(r"Non-2xx or 3xx responses:\s+(\d+)", out)
    errors = re.search(r"Socket errors:.*", out)
    return rps, pct, int(non2xx.group(1)) if non2xx else 0, errors.group(0) if errors else "", out


def main():
    if not shutil.which("wrk"):
        print("SKIP: wrk is not installed")
        sys.exit(1 if os.environ.get("CI") else 77)  # CI installs it (scripts/debian-packages.txt)
    smoke = flag("--smoke")
    connections = option("--connections", 4 if smoke else 50)
    threads = option("--threads", 2)
    seconds = option("--seconds", 1 if smoke else 10)
    tmp = tempfile.mkdtemp(prefix="synbench-wrk-")
    d = Daemon(sys.argv[1], os.path.join(tmp, "data"))
    ok = True
    try:
        viewer = d.token("viewer")
        for path, token in [("/api/health", None), ("/api/bench/status", viewer)]:
            rps, pct, non2xx, errors, out = run_wrk(d, path, token, connections, threads, seconds)
            print("GET %-18s %d connections, %d threads, %d s: %.0f req/s, latency p50 %s p90 %s p99 %s%s%s" % (
                path, connections, threads, seconds, rps, pct.get("50"), pct.get("90"), pct.get("99"),
                ", %d non-2xx" % non2xx if non2xx else "", ", " + errors if errors else ""))
            if non2xx or rps <= 0:
                ok = False
                print(out)
    finally:
        rc, _ = d.stop()
    if not ok or rc != 0:
        print("FAIL: errors under load, or the daemon did not exit 0 (%s)" % rc)
        sys.exit(1)


if __name__ == "__main__":
    main()
