#!/usr/bin/env python3
"""examples/scripted_sweep.py end to end against `synbench serve` on loopback: the example
creates its small sweep, follows it to completion and downloads points and analysis; the test
checks the downloads against the plan (20 points, 4 curves) and the physics (MTPA inside the
angles measured, ME at or above MTPA, efficiency rising with load at each speed).

usage: scripted_sweep_test.py path/to/synbench path/to/python3-with-requests
"""
import csv
import json
import os
import re
import subprocess
import sys
import tempfile

BIN, PYTHON = sys.argv[1], sys.argv[2]
EXAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples", "scripted_sweep.py")
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def main():
    r = subprocess.run([PYTHON, "-c", "import requests"], capture_output=True)
    if r.returncode != 0:
        raise SystemExit("%s has no requests module: install python3-requests (scripts/install-deps.sh)" % PYTHON)
    tmp = tempfile.mkdtemp(prefix="synbench-example-")
    data_dir, out = os.path.join(tmp, "data"), os.path.join(tmp, "out")
    proc = subprocess.Popen([BIN, "serve", "--listen", "127.0.0.1:0", "--data-dir", data_dir],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        m = re.match(r"listening on (http://127\.0\.0\.1:\d+)", proc.stdout.readline())
        check(m is not None, "the daemon starts")
        if not m:
            return
        r = subprocess.run([PYTHON, EXAMPLE, "--url", m.group(1), "--token-file", os.path.join(data_dir, "operator.token"),
                            "--out", out, "--poll-s", "0.5", "--timeout-s", "300"], capture_output=True, text=True, timeout=400)
        print(r.stdout[-2000:])
        check(r.returncode == 0, "the example exits 0 (%s)" % r.stderr[-500:])
        check("completed" in r.stdout and "20/20 points" in r.stdout, "the example reports the sweep completed")
        with open(os.path.join(out, "sweep-1-points.csv")) as f:
            rows = list(csv.DictReader(f))
        check(len(rows) == 20, "20 points downloaded as CSV (%d)" % len(rows))
        check(len(json.load(open(os.path.join(out, "sweep-1-points.json")))) == 20, "20 points downloaded as JSON")
        analysis = json.load(open(os.path.join(out, "sweep-1-analysis.json")))
        curves = analysis["curves"]["entries"]
        check(len(curves) == 4, "4 curves analysed (%d)" % len(curves))
        for c in curves:
            what = "%s rpm %s N m" % (c["speed_rpm"], c["load_Nm"])
            check(44 <= c["mtpa"]["angle_deg"] <= 60, what + ": MTPA inside 44..60 deg (%.1f)" % c["mtpa"]["angle_deg"])
            check(c["me"]["angle_deg"] >= c["mtpa"]["angle_deg"] - 0.5, what + ": ME at or above MTPA")
            check(0.3 < c["me"]["efficiency"] < 0.95, what + ": efficiency plausible (%.3f)" % c["me"]["efficiency"])
        for speed in (300, 600):
            eff = [c["me"]["efficiency"] for c in sorted(curves, key=lambda c: c["load_Nm"]) if c["speed_rpm"] == speed]
            check(eff == sorted(eff), "%d rpm: efficiency rises from 1 to 2 N m (%s)" % (speed, eff))
        lines = open(os.path.join(out, "sweep-1-analysis.csv")).read().splitlines()
        check(len(lines) == 5 and lines[0].startswith("estimator,pwm,speed_rpm"), "analysis CSV: header and 4 curves")
        # A viewer token cannot run a sweep: the example says so and exits 1.
        viewer = subprocess.run([BIN, "token", "create", "--role", "viewer", "--data-dir", data_dir],
                                capture_output=True, text=True).stdout.strip()
        r = subprocess.run([PYTHON, EXAMPLE, "--url", m.group(1), "--token", viewer, "--out", out],
                           capture_output=True, text=True, timeout=60)
        check(r.returncode == 1 and "operator" in r.stderr, "a viewer token: exit 1 naming the operator role")
    finally:
        proc.terminate()
        proc.wait(timeout=30)
    if failures:
        print("%d failure(s)" % len(failures))
        sys.exit(1)
    print("scripted sweep example ok")


if __name__ == "__main__":
    main()
