#!/usr/bin/env python3
"""GET /api/bench/status of `synbench serve` (the embedded twin, drives disabled, a viewer token
checked on every request) against Debian's nginx (one worker, started here on loopback as the
user) serving the same bytes as a file, under wrk with keep-alive connections, at 1, 16 and 64
connections (issue 37, item 3). Each concurrency is measured side by side in one run: the daemon,
then nginx, then (with --before) another build's daemon, each for the same seconds; the ratio
synbench / nginx is printed per concurrency. Target: >= 0.8 at every one.

usage: status_vs_nginx_bench.py path/to/synbench [--seconds 5] [--connections 1,16,64]
           [--before path/to/old/synbench] [--smoke]
  --smoke: 1 s per server and concurrency; fails when a request fails, never on the ratio (ctest;
  skipped, exit 77, without wrk or nginx).
"""
import os
import shutil
import sys
import tempfile
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "server"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from daemon import Daemon  # noqa: E402
from estop_latency_bench import LOCAL, Nginx, run_wrk  # noqa: E402
from script_args import flag, option  # noqa: E402


def status_body(d, token):
    req = urllib.request.Request("http://%s/api/bench/status" % d.host, headers={"Authorization": "Bearer " + token})
    return LOCAL.open(req, timeout=10).read()


def main():
    for tool in ("wrk", "nginx"):
        if not shutil.which(tool):
            print("SKIP: %s is not installed" % tool)
            sys.exit(1 if os.environ.get("CI") else 77)
    binary = sys.argv[1]
    smoke = flag("--smoke")
    seconds = 1 if smoke else int(option("--seconds", "5"))
    levels = [int(c) for c in option("--connections", "1,16,64").split(",")]
    before = option("--before", "")
    tmp = tempfile.mkdtemp(prefix="synbench-status-nginx-")
    daemons = []
    nginx = None
    ok = True
    try:
        ours = Daemon(binary, os.path.join(tmp, "data"), stderr=open(os.devnull, "w"))
        daemons.append(ours)
        viewer = ours.token("viewer")
        body = status_body(ours, viewer)
        nginx = Nginx(tmp, body)
        old = old_viewer = None
        if before:
            old = Daemon(before, os.path.join(tmp, "data-before"), stderr=open(os.devnull, "w"))
            daemons.append(old)
            old_viewer = old.token("viewer")
        print("GET /api/bench/status under wrk (keep-alive, %d s per server and concurrency), a %d-byte body; "
              "nginx %s, 1 worker, serving the same bytes" % (seconds, len(body), nginx.version))
        print("  %11s %-16s %10s %9s %9s %9s" % ("connections", "server", "req/s", "p50", "p90", "p99"))
        for c in levels:
            threads = min(2, c)
            rows = [("synbench", run_wrk("http://%s/api/bench/status" % ours.host, viewer, c, threads, seconds)),
                    ("nginx", run_wrk(nginx.url, viewer, c, threads, seconds))]
            if old:
                rows.append(("before", run_wrk("http://%s/api/bench/status" % old.host, old_viewer, c, threads, seconds)))
            for name, r in rows:
                print("  %11d %-16s %10.0f %9s %9s %9s%s" % (c, name, r["rps"], r["pct"].get("50"), r["pct"].get("90"),
                                                           r["pct"].get("99"), "  " + r["errors"] if r["errors"] else ""))
                if r["non2xx"] or r["rps"] <= 0:
                    print("FAIL: %s at %d connections: %d non-2xx, %.0f req/s\n%s" % (name, c, r["non2xx"], r["rps"], r["out"]))
                    ok = False
            res = dict(rows)
            line = "  %11d ratio synbench / nginx: %.2f" % (c, res["synbench"]["rps"] / res["nginx"]["rps"])
            if old:
                line += "; before / nginx: %.2f" % (res["before"]["rps"] / res["nginx"]["rps"])
            print(line, flush=True)
    finally:
        if nginx:
            nginx.stop()
        for d in daemons:
            d.stop(read_stderr=False)
        shutil.rmtree(tmp, ignore_errors=True)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
