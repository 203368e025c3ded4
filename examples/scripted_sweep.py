#!/usr/bin/env python3
"""Scripted experiment over synbench's REST API: validate a plan, create a sweep, run it on the
daemon's bench, follow its progress, download the points and the analysis, print the MTPA and
maximum-efficiency angles. Needs only python3-requests (Debian package).

    python3 examples/scripted_sweep.py --url http://127.0.0.1:8080 \
        --token-file synbench-data/operator.token --out results/

Without --plan it runs a small grid (2 speeds x 2 loads x 5 current angles, encoder/CAPWM) that
takes about a minute of bench time. Exit status: 0 completed, 1 the sweep ended otherwise or the
daemon refused, 2 bad arguments.
"""
import argparse
import json
import os
import sys
import time

import requests

SMALL_PLAN = {
    "name": "scripted example",
    "dimensions": {
        "speed_rpm": [300, 600],
        "load_Nm": [1.0, 2.0],
        "angle_deg": {"from": 44, "to": 60, "step": 4},
        "configurations": [{"estimator": "encoder", "pwm": "capwm"}],
    },
    "window_s": 0.5,
}


class Api:
    def __init__(self, url, token):
        self.url = url.rstrip("/")
        self.session = requests.Session()
        self.session.headers["Authorization"] = "Bearer " + token

    def call(self, method, path, **kw):
        r = self.session.request(method, self.url + path, timeout=30, **kw)
        if r.status_code >= 400:
            try:
                err = r.json()["error"]
                detail = "%s: %s" % (err["code"], err["message"])
            except ValueError:
                detail = r.text[:200]
            raise SystemExit("%s %s -> %d %s" % (method, path, r.status_code, detail))
        return r

    def json(self, method, path, **kw):
        return self.call(method, path, **kw).json()


def progress_line(sweep, started):
    done, total = sweep["points_stored"], max(sweep["total_points"], 1)
    elapsed = time.time() - started
    eta = elapsed / done * (total - done) if done else float("nan")
    return "sweep %d %-9s %4d/%d points (%5.1f %%) elapsed %5.0f s, ETA %5.0f s" % (
        sweep["id"], sweep["state"], done, total, 100.0 * done / total, elapsed, eta)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--url", default="http://127.0.0.1:8080", help="the daemon (default %(default)s)")
    ap.add_argument("--token", help="an operator token (or --token-file, or SYNBENCH_TOKEN)")
    ap.add_argument("--token-file", default="synbench-data/operator.token", help="default %(default)s")
    ap.add_argument("--plan", help="a sweep plan JSON file (docs/sweep-plan.md); default: a small grid")
    ap.add_argument("--out", default="synbench-results", help="directory for the downloads (default %(default)s)")
    ap.add_argument("--poll-s", type=float, default=1.0, help="progress poll period (default %(default)s s)")
    ap.add_argument("--timeout-s", type=float, default=1800, help="give up after this long (default %(default)s s)")
    args = ap.parse_args()

    token = args.token or os.environ.get("SYNBENCH_TOKEN")
    if not token:
        try:
            token = open(args.token_file).read().strip()
        except OSError as e:
            print("scripted_sweep: --token-file: %s" % e, file=sys.stderr)
            return 2
    plan = SMALL_PLAN
    if args.plan:
        try:
            plan = json.load(open(args.plan))
        except (OSError, ValueError) as e:
            print("scripted_sweep: --plan: %s" % e, file=sys.stderr)
            return 2

    api = Api(args.url, token)
    health = api.json("GET", "/api/health")
    me = api.json("GET", "/api/whoami")
    print("daemon %s, signed in as %s (%s)" % (health["version"], me["id"], me["role"]))
    if me["role"] != "operator":
        print("scripted_sweep: running a sweep needs an operator token", file=sys.stderr)
        return 1

    estimate = api.json("POST", "/api/sweeps/estimate", json=plan)
    print("plan: %d points, about %.0f s of bench time" % (estimate["points"], estimate["duration_s"]))
    sweep = api.json("POST", "/api/sweeps", json=plan)
    sid = sweep["id"]
    api.call("POST", "/api/sweeps/%d/start" % sid)

    started = time.time()
    last = None
    while True:
        sweep = api.json("GET", "/api/sweeps/%d" % sid)
        line = progress_line(sweep, started)
        if sweep["points_stored"] != last or sweep["state"] not in ("created", "running", "paused"):
            print(line, flush=True)
            last = sweep["points_stored"]
        if sweep["state"] not in ("created", "running", "paused"):
            break
        if time.time() - started > args.timeout_s:
            api.call("POST", "/api/sweeps/%d/abort" % sid)
            print("scripted_sweep: timed out after %.0f s; sweep aborted" % args.timeout_s, file=sys.stderr)
            return 1
        time.sleep(args.poll_s)

    os.makedirs(args.out, exist_ok=True)
    files = {
        "points.json": "/api/sweeps/%d/points" % sid,
        "points.csv": "/api/sweeps/%d/points?format=csv" % sid,
        "analysis.json": "/api/sweeps/%d/analysis" % sid,
        "analysis.csv": "/api/sweeps/%d/analysis?format=csv" % sid,
    }
    for name, path in files.items():
        with open(os.path.join(args.out, "sweep-%d-%s" % (sid, name)), "wb") as f:
            f.write(api.call("GET", path).content)
    print("downloaded %s to %s" % (", ".join("sweep-%d-%s" % (sid, n) for n in files), args.out))

    analysis = api.json("GET", "/api/sweeps/%d/analysis" % sid)
    print("%-10s %-8s %-9s %-10s %-9s %s" % ("config", "speed", "load", "MTPA", "ME", "efficiency at ME"))
    for c in analysis["curves"]["entries"]:
        eff = c["me"]["efficiency"]
        print("%-10s %5.0f rpm %5.2f N m %6.1f deg %6.1f deg %s" % (
            c["estimator"], c["speed_rpm"], c["load_Nm"], c["mtpa"]["angle_deg"], c["me"]["angle_deg"],
            "%.1f %%" % (100 * eff) if eff is not None else "-"))
    if sweep["state"] != "completed":
        print("scripted_sweep: the sweep ended %s: %s" % (sweep["state"], sweep.get("last_error")), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
