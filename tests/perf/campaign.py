#!/usr/bin/env python3
"""Benchmark: wall time of the full thesis campaign (thesis-grid preset, every configuration) on
the in-process twin, one `synbench sweep` process per configuration, two at a time on this
2-core machine. Target (issue "Sweep engine"): <= 2 minutes. Prints per-configuration state,
points and wall time, and the total. usage: tests/perf/campaign.py [path/to/synbench] [jobs]"""
import json
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

BIN = sys.argv[1] if len(sys.argv) > 1 else "build/release/server/synbench"
JOBS = int(sys.argv[2]) if len(sys.argv) > 2 else 2
CONFIGS = [("encoder", "capwm"), ("encoder", "aspwm"), ("ekf-basic", "aspwm"), ("ekf-rs", "aspwm"),
           ("hfi", "capwm"), ("eemf-const", "capwm"), ("eemf-lut", "capwm"), ("eemf-rls", "capwm")]
tmp = tempfile.mkdtemp(prefix="synbench-campaign-")


def one(cfg):
    est, pwm = cfg
    plan = os.path.join(tmp, f"{est}-{pwm}.json")
    speeds = [500, 700, 900] if est.startswith("eemf") else [100, 300, 500, 700, 900]
    with open(plan, "w") as f:
        json.dump({"name": f"thesis {est}/{pwm}", "preset": "thesis-grid",
                   "dimensions": {"speed_rpm": speeds, "configurations": [{"estimator": est, "pwm": pwm}]}}, f)
    db = os.path.join(tmp, f"{est}-{pwm}.db")
    t0 = time.time()
    p = subprocess.run([BIN, "sweep", plan, "--db", db, "--quiet"], capture_output=True, text=True)
    wall = time.time() - t0
    import sqlite3
    con = sqlite3.connect(db)
    state, err = con.execute("select state, last_error from sweeps where id = 1").fetchone()
    n = con.execute("select count(*) from points").fetchone()[0]
    total = con.execute("select total_points from sweeps where id = 1").fetchone()[0]
    con.close()
    return est, pwm, state, n, total, wall, err


t0 = time.time()
with ThreadPoolExecutor(max_workers=JOBS) as ex:
    results = list(ex.map(one, CONFIGS))
total_wall = time.time() - t0
points = 0
for est, pwm, state, n, total, wall, err in results:
    points += n
    print(f"{est + '/' + pwm:18s} {state:10s} {n:4d}/{total:<4d} points  {wall:6.1f} s" + (f"  ({err})" if err else ""))
print(f"campaign: {points} points in {total_wall:.1f} s wall with {JOBS} jobs (target <= 120 s)")
