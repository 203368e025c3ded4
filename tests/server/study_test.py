#!/usr/bin/env python3
"""`synbench study` as a user and a cluster run it: a refused plan names its JSON pointers; a
study sharded over 4 processes writing at once into one SQLite file (and then into a throwaway
PostgreSQL cluster, tests/db/pg_cluster.sh), one of them killed with
SIGKILL mid-sample and re-run, ends with every sample complete, no point stored twice, and the
same merged analysis as an unkilled single-process run; `status` counts the shards; the
Kubernetes Indexed Job and Slurm array scripts parse and the command lines they run are accepted
(with --dry-run) and give each shard its own samples (tests/deploy/slurm_test.py runs the Slurm
script on a real one-node Slurm).

Usage: study_test.py SYNBENCH [SOURCE_DIR]"""
import glob
import json
import os
import re
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time

from checks import Checks
from study_compare import PLAN, POINTS_PER_SAMPLE, SAMPLES, cells, compare

BIN = sys.argv[1]
SRC = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(__file__), "..", "..")
check = Checks(verbose=True)
tmp = tempfile.mkdtemp(prefix="synbench-study-")


def write(name, obj):
    path = os.path.join(tmp, name)
    with open(path, "w") as f:
        json.dump(obj, f)
    return path


def study(*args, timeout=600):
    p = subprocess.run([BIN, "study", *args], capture_output=True, text=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


plan = write("study.json", PLAN)

# --- refusals ---
bad = write("bad.json", {"name": "x y", "sweep": "thesis-grid", "grid": {"ld_pct": [500]}, "monte_carlo": {}})
code, out, err = study("run", bad, "--shard", "0/1", "--dry-run")
check(code == 2, f"bad plan: exit 2 ({code})")
check("/name: must be 1..64 characters" in err and "not both" in err, f"bad plan: every problem named ({err.strip()[:300]})")
bad = write("bad2.json", {"name": "x", "sweep": {"window_s": -1}, "grid": {"ld_pct": [500], "lx_pct": [1]}})
code, out, err = study("run", bad, "--shard", "0/1", "--dry-run")
check(code == 2 and "/sweep/window_s:" in err and "/grid/ld_pct/0: must be within [-75, 300]" in err
      and "/grid/lx_pct: unknown study parameter" in err, f"bad plan: JSON pointers ({err.strip()[:400]})")
code, out, err = study("run", plan, "--shard", "4/4", "--dry-run")
check(code == 2 and "--shard" in err and "below N" in err, f"shard 4/4 refused ({code}, {err.strip()})")
code, out, err = study("run", plan, "--dry-run")
check(code == 2 and "--shard" in err, f"--shard required ({code}, {err.strip()})")
code, out, err = study("frobnicate", plan)
check(code == 2 and "unknown study command" in err, f"unknown subcommand ({code}, {err.strip()})")

# --- dry run: the shard's samples and keys, nothing opened ---
code, out, err = study("run", plan, "--shard", "1/4", "--db", os.path.join(tmp, "never.db"), "--dry-run")
keys = re.findall(r"^ld-rs/([0-9a-f]{16})/(\d+) ", out, re.M)
check(code == 0 and [int(i) for _, i in keys] == [1, 5], f"dry run lists shard 1/4's samples 1, 5 ({out.strip()})")
check(not os.path.exists(os.path.join(tmp, "never.db")), "dry run opens no store")
plan_hash = keys[0][0] if keys else ""


PSQL = next(iter(sorted(glob.glob("/usr/lib/postgresql/*/bin/psql"), reverse=True)), None)


def query(db, sql):
    """Rows of `sql` on a SQLite file or a postgresql:// URL (psql)."""
    if db.startswith("postgresql://"):
        p = subprocess.run([PSQL, "-At", "-F", "\t", db, "-c", sql], capture_output=True, text=True, timeout=30)
        if p.returncode != 0:
            return []
        return [tuple(int(x) if x.isdigit() else x for x in line.split("\t")) for line in p.stdout.splitlines()]
    if not os.path.exists(db):
        return []
    try:
        con = sqlite3.connect(db, timeout=5)
        rows = con.execute(sql).fetchall()
        con.close()
        return rows
    except sqlite3.Error:
        return []


def points_per_sweep(db):
    return sorted(query(db, "SELECT s.key, s.state, COUNT(p.id), COUNT(DISTINCT p.point_index) FROM sweeps s "
                            "LEFT JOIN points p ON p.sweep_id = s.id GROUP BY s.id, s.key, s.state"))


def stored_points(db, shard, shards):
    rows = query(db, "SELECT s.key, COUNT(p.id) FROM sweeps s JOIN points p ON p.sweep_id = s.id GROUP BY s.id, s.key")
    return sum(n for key, n in rows if int(key.rsplit("/", 1)[1]) % shards == shard)


# --- reference: one process, all samples ---
ref_db = os.path.join(tmp, "ref.db")
t0 = time.monotonic()
code, out, err = study("run", plan, "--shard", "0/1", "--db", ref_db, "--quiet")
check(code == 0, f"single-process run completes ({code}, {err.strip()[-300:]})")
print(f"single process: {time.monotonic() - t0:.1f} s for {SAMPLES * POINTS_PER_SAMPLE} points", flush=True)
code, out, err = study("analyse", plan, "--db", ref_db, "--json-out", os.path.join(tmp, "ref.json"))
check(code == 0 and "eemf-lut/capwm" in out, f"analyse prints the table ({code})")
print(out, flush=True)
ref = json.load(open(os.path.join(tmp, "ref.json")))

# --- 4 shards at once into one store, shard 2 killed mid-sample ---
def sharded_study(db, label):
    """4 shards at once into `db`, shard 2 killed mid-sample and re-run; against the reference."""
    def chk(cond, what):
        return check(cond, f"[{label}] {what}")

    procs = {k: subprocess.Popen([BIN, "study", "run", plan, "--shard", f"{k}/4", "--db", db],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for k in range(4)}
    victim, killed_at = 2, None
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and procs[victim].poll() is None:
        n = stored_points(db, victim, 4)
        if n >= 1 and n % POINTS_PER_SAMPLE != 0:  # inside a sample, not between two
            procs[victim].send_signal(signal.SIGKILL)
            killed_at = n
            break
        time.sleep(0.005)
    results = {k: (p.wait(timeout=600), p.stderr.read()) for k, p in procs.items()}
    chk(killed_at is not None and results[victim][0] == -signal.SIGKILL,
          f"shard {victim} killed with SIGKILL after {killed_at} points, mid-sample ({results[victim][0]})")
    for k in range(4):
        if k != victim:
            chk(results[k][0] == 0, f"shard {k}/4 completes beside the others ({results[k][0]}: {results[k][1].strip()[-300:]})")

    code, out, err = study("status", plan, "--db", db, "--shards", "4", "--json")
    st = json.loads(out) if code == 0 else {"shards": []}
    by_shard = {s["shard"]: s for s in st["shards"]}
    v = by_shard.get(f"{victim}/4", {})
    chk(v.get("running") == 1 and v.get("done", 0) < v.get("samples", 0),
          f"status: the killed shard has its sample left running ({v})")
    chk(all(by_shard.get(f"{k}/4", {}).get("done") == 2 for k in range(4) if k != victim),
          f"status: the other shards are done ({st['shards']})")

    # Re-run the killed shard: resumes, stores only what is missing.
    code, out, err = study("run", plan, "--shard", f"{victim}/4", "--db", db)
    chk(code == 0, f"re-run of shard {victim} completes ({code}, {err.strip()[-300:]})")
    resumed = [int(b) for b in re.findall(r"\((\d+) before this run\)", err)]
    chk(killed_at is not None and any(killed_at % POINTS_PER_SAMPLE <= b < POINTS_PER_SAMPLE for b in resumed if b > 0),
          f"re-run resumes the killed sample at its first missing point ({err.strip()})")
    # Re-running a complete shard stores nothing.
    before = points_per_sweep(db)
    code, out, err = study("run", plan, "--shard", "0/4", "--db", db)
    chk(code == 0 and err.count("already complete") == 2 and points_per_sweep(db) == before,
          f"re-running a complete shard stores nothing ({err.strip()})")

    rows = points_per_sweep(db)
    chk(len(rows) == SAMPLES, f"one sweep per sample ({len(rows)})")
    chk(all(state == "completed" and n == POINTS_PER_SAMPLE and d == n for _, state, n, d in rows),
          f"every sample completed with each point once ({rows})")
    chk(sorted(int(name.rsplit("/", 1)[1]) for name, *_ in rows) == list(range(SAMPLES))
          and all(name.startswith(f"ld-rs/{plan_hash}/") for name, *_ in rows), "sweeps stored under their keys")
    code, out, err = study("status", plan, "--db", db, "--shards", "4", "--json")
    st = json.loads(out)
    chk(all(s["done"] == s["samples"] and s["missing"] == 0 and s["running"] == 0 for s in st["shards"]),
          f"status after the re-run: every shard done ({st['shards']})")

    code, out, err = study("analyse", plan, "--db", db, "--json-out", os.path.join(tmp, label + ".json"))
    chk(code == 0, f"analyse the sharded study ({code})")
    sharded = json.load(open(os.path.join(tmp, label + ".json")))


    compare(chk, ref, sharded, label)

    # The sensitivity shows: EEMF-LUT's position error grows with |Ld deviation|.
    ld = {g["from"]: next(c for c in g["configurations"] if c["configuration"] == "eemf-lut/capwm")
          for g in next(p for p in ref["parameters"] if p["parameter"] == "ld_pct")["groups"]}
    chk(ld[-25]["pos_err_abs_mean_deg"] > ld[0]["pos_err_abs_mean_deg"] + 0.5,
          f"EEMF-LUT |position error| at Ld -25 % ({ld[-25]['pos_err_abs_mean_deg']:.2f}) above nominal "
          f"({ld[0]['pos_err_abs_mean_deg']:.2f})")


sharded_study(os.path.join(tmp, "shared.db"), "sqlite")

# The same on a throwaway PostgreSQL 15 cluster (tests/db/pg_cluster.sh); no PostgreSQL: a failure.
pg_dir = tempfile.mkdtemp(prefix="synbench-study-pg-")  # /tmp-level: the cluster's owner (nobody as root) reaches it
p = subprocess.run(["sh", os.path.join(SRC, "tests", "db", "pg_cluster.sh"), "start", pg_dir],
                   capture_output=True, text=True, timeout=120)
if check(p.returncode == 0 and PSQL, f"PostgreSQL cluster started ({p.stderr.strip()[-300:]})"):
    port = p.stdout.strip().splitlines()[-1]
    try:
        subprocess.run([PSQL, f"postgresql://synbench@127.0.0.1:{port}/postgres", "-c", "CREATE DATABASE study"],
                       capture_output=True, check=True, timeout=30)
        sharded_study(f"postgresql://synbench@127.0.0.1:{port}/study", "postgresql")
    finally:
        subprocess.run(["sh", os.path.join(SRC, "tests", "db", "pg_cluster.sh"), "stop", pg_dir],
                       capture_output=True, timeout=120)

# --- cluster manifests ---
job_path = os.path.join(SRC, "deploy", "k8s", "study-job.yaml")
array_path = os.path.join(SRC, "deploy", "slurm", "study-array.sh")
try:
    import yaml
    job = yaml.safe_load(open(job_path))
except ImportError:
    job = None
    check(False, "python3-yaml is installed (README setup) to parse the Kubernetes manifest")
if job:
    spec = job["spec"]
    c = spec["template"]["spec"]["containers"][0]
    env = {e["name"]: e for e in c["env"]}
    check(job["kind"] == "Job" and spec["completionMode"] == "Indexed", "k8s: an Indexed Job")
    check(int(env["SHARDS"]["value"]) == spec["completions"], "k8s: SHARDS equals completions")
    check("job-completion-index" in env["SHARD"]["valueFrom"]["fieldRef"]["fieldPath"], "k8s: the shard is the completion index")
    check("secretKeyRef" in env["SYNBENCH_DB"]["valueFrom"], "k8s: the database URL comes from a Secret")
    mount = c["volumeMounts"][0]["mountPath"]
    for k in (0, spec["completions"] - 1):
        values = {"SHARD": str(k), "SHARDS": env["SHARDS"]["value"], "SYNBENCH_DB": os.path.join(tmp, "k8s.db")}
        args = [re.sub(r"\$\((\w+)\)", lambda m: values[m.group(1)], a) for a in c["args"]]
        args = [plan if a.startswith(mount + "/") else a for a in args]
        p = subprocess.run([BIN, *args, "--dry-run"], capture_output=True, text=True, timeout=60)
        check(p.returncode == 0 and f"shard {k}/{spec['completions']}" in p.stdout,
              f"k8s: pod {k}'s command line is accepted: synbench {' '.join(args)} ({p.returncode}, {p.stderr.strip()})")

p = subprocess.run(["bash", "-n", array_path], capture_output=True, text=True)
check(p.returncode == 0, f"slurm: the script parses ({p.stderr.strip()})")
envs = dict(os.environ, SLURM_ARRAY_TASK_ID="3", SLURM_ARRAY_TASK_COUNT="1", SLURM_ARRAY_TASK_MIN="3",
            SYNBENCH=BIN, SYNBENCH_DB=os.path.join(tmp, "slurm.db"), SYNBENCH_STUDY_FLAGS="--dry-run")
# As in a re-run of task 3 alone (`sbatch --array=3 ...`): the array has one task, the shard is
# still 3 of the submitted 4. A real Slurm runs the whole sequence in tests/deploy/slurm_test.py.
p = subprocess.run(["bash", array_path, plan, "4"], capture_output=True, text=True, env=envs, timeout=60)
check(p.returncode == 0 and "shard 3/4" in p.stdout and re.search(r"/7 ", p.stdout),
      f"slurm: task 3 re-run alone runs shard 3/4 (samples 3, 7) ({p.returncode}, {p.stdout.strip()} {p.stderr.strip()})")
p = subprocess.run(["bash", array_path, plan], capture_output=True, text=True, env=envs, timeout=60)
check(p.returncode != 0 and "shard count, is required" in p.stderr, f"slurm: N is required ({p.stderr.strip()})")
p = subprocess.run(["bash", array_path, plan, "3"], capture_output=True, text=True, env=envs, timeout=60)
check(p.returncode == 2 and "array index 3 is not a shard of 3: submit indices 0..2" in p.stderr,
      f"slurm: an index outside 0..N-1 is refused ({p.stderr.strip()})")
p = subprocess.run(["bash", array_path, plan, "4"], capture_output=True, text=True,
                   env={k: v for k, v in envs.items() if not k.startswith("SLURM_")}, timeout=60)
check(p.returncode != 0 and "SLURM_ARRAY_TASK_ID" in p.stderr, f"slurm: outside an array it says so ({p.stderr.strip()})")

check.finish("study test ok")
