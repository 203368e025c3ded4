#!/usr/bin/env python3
"""A twin sweep on every core against one (issue 37, item 7): the thesis preset
(`{"preset": "thesis-grid"}`, 4123 points, all eight configurations) as `synbench sweep --jobs 1`
and `--jobs N` (N: the machine's cores), each into its own SQLite file, in one run: wall time,
CPU time and peak RSS of each and the speed-up as a ratio. Checks that both completed and stored
every point exactly once.

  sweep_jobs_bench.py SYNBENCH [--jobs N] [--smoke]

--smoke runs the preset with the encoder/CAPWM configuration only at 0.2 s windows (the ctest
smoke run). Figures: docs/benchmarks.md (a Release build: build/release/server/synbench)."""
import argparse
import json
import os
import sqlite3
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "server"))
from checks import Checks  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("synbench")
ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
ap.add_argument("--smoke", action="store_true")
args = ap.parse_args()
check = Checks(verbose=True)
tmp = tempfile.mkdtemp(prefix="synbench-sweep-jobs-bench-")
plan = {"preset": "thesis-grid"}
if args.smoke:
    plan.update({"window_s": 0.2, "dimensions": {"configurations": [{"estimator": "encoder", "pwm": "capwm"}]}})
plan_path = os.path.join(tmp, "plan.json")
with open(plan_path, "w") as f:
    json.dump(plan, f)


def run(jobs):
    db = os.path.join(tmp, f"jobs{jobs}.db")
    t0 = time.monotonic()
    p = subprocess.Popen([args.synbench, "sweep", plan_path, "--db", db, "--jobs", str(jobs), "--quiet"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    err = p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)  # this child's own CPU time and peak RSS
    wall = time.monotonic() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    p.stderr = err
    cpu = usage.ru_utime + usage.ru_stime
    con = sqlite3.connect(db)
    idx = [r[0] for r in con.execute("SELECT point_index FROM points WHERE sweep_id = 1")]
    state, total = con.execute("SELECT state, total_points FROM sweeps WHERE id = 1").fetchone()
    con.close()
    check(p.returncode == 0 and state == "completed", f"--jobs {jobs}: completed ({p.returncode}, {state}, {p.stderr.strip()[-200:]})")
    check(len(idx) == len(set(idx)) == total, f"--jobs {jobs}: {len(idx)} points, each once, of {total}")
    return wall, cpu, usage.ru_maxrss / 1024.0, len(idx)


serial = run(1)
parallel = run(args.jobs)
print(f"{'jobs':>5} {'points':>7} {'wall s':>8} {'CPU s':>8} {'peak RSS MB':>12}")
for jobs, (wall, cpu, rss, n) in ((1, serial), (args.jobs, parallel)):
    print(f"{jobs:>5} {n:>7} {wall:>8.1f} {cpu:>8.1f} {rss:>12.0f}")
print(f"speed-up with {args.jobs} jobs: {serial[0] / parallel[0]:.2f}x (wall {parallel[0]:.1f} s against {serial[0]:.1f} s)")
check.finish("sweep jobs bench ok")
