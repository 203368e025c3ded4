#!/usr/bin/env python3
"""A twin study over 2 local shards against 1 (issue 27's benchmark): the same study, each run
into its own SQLite file, once as `synbench study run --shard 0/1` and once as two processes
`--shard 0/2` and `--shard 1/2` at once; wall time of each and the speed-up as a ratio in one run.
Checks that both runs stored every point exactly once.

  study_shards_bench.py SYNBENCH [--points N] [--smoke]

--points (default 20000, the issue's size) is rounded to whole samples of 20 points (encoder and
EEMF-LUT at 700 rpm, 1 N m, 10 angles, 0.2 s windows) over a Monte Carlo of Ld and Rs;
--smoke runs 160 points (the ctest smoke run). Figures: docs/benchmarks.md."""
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
ap.add_argument("--points", type=int, default=20000)
ap.add_argument("--smoke", action="store_true")
args = ap.parse_args()
points = 160 if args.smoke else args.points
PER_SAMPLE = 20
samples = max(2, points // PER_SAMPLE)
check = Checks(verbose=True)
tmp = tempfile.mkdtemp(prefix="synbench-study-bench-")

plan = {
    "name": "bench",
    "sweep": {"name": "s", "window_s": 0.2, "thermal": {"enabled": False},
              "dimensions": {"speed_rpm": [700], "load_Nm": [1.0], "angle_deg": list(range(44, 64, 2)),
                             "configurations": [{"estimator": "encoder", "pwm": "capwm"},
                                                {"estimator": "eemf-lut", "pwm": "capwm"}]}},
    "monte_carlo": {"samples": samples, "seed": 27,
                    "parameters": {"ld_pct": {"distribution": "uniform", "half_width": 25},
                                   "rs_pct": {"distribution": "normal", "sd": 5}}},
}
path = os.path.join(tmp, "study.json")
with open(path, "w") as f:
    json.dump(plan, f)


def run(shards):
    db = os.path.join(tmp, f"{shards}.db")
    t0 = time.monotonic()
    procs = [subprocess.Popen([args.synbench, "study", "run", path, "--shard", f"{k}/{shards}", "--db", db, "--quiet"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True) for k in range(shards)]
    codes = [(p.wait(), p.stderr.read()) for p in procs]
    wall = time.monotonic() - t0
    for k, (c, err) in enumerate(codes):
        check(c == 0, f"{shards} shard(s): shard {k} exits 0 ({c}: {err.strip()[-300:]})")
    con = sqlite3.connect(db)
    n, distinct = con.execute("SELECT COUNT(*), COUNT(DISTINCT sweep_id || '/' || point_index) FROM points").fetchone()
    con.close()
    check(n == samples * PER_SAMPLE and distinct == n, f"{shards} shard(s): {n} points, each once")
    return wall


one = run(1)
two = run(2)
total = samples * PER_SAMPLE
print(f"study of {total} twin points ({samples} samples x {PER_SAMPLE}): 1 shard {one:.1f} s "
      f"({total / one:.0f} points/s), 2 shards {two:.1f} s ({total / two:.0f} points/s), "
      f"speed-up {one / two:.2f}x", flush=True)
check.finish("study shards bench ok")
