#!/usr/bin/env python3
"""deploy/slurm/study-array.sh on a real one-node Slurm (Debian's slurmctld, slurmd and munge,
started by tests/deploy/slurm_cluster.sh) into a throwaway PostgreSQL cluster
(tests/db/pg_cluster.sh), the way docs/deployment.md tells a lab to run it:

  sbatch --array=0-3 deploy/slurm/study-array.sh study.json 4
  scancel JOB_1                      (task 1 cancelled mid-sample: SIGTERM)
  sbatch --array=1 deploy/slurm/study-array.sh study.json 4

The re-run runs shard 1 of 4 (not the whole study), resumes the cancelled sample at its first
missing point; `synbench study status` then counts every shard done and the merged analysis
equals an uninterrupted single-process run's. An index outside 0..N-1 is refused by the job.

Usage: slurm_test.py SYNBENCH [SOURCE_DIR]"""
import glob
import json
import os
import re
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "server"))
from checks import Checks  # noqa: E402
from study_compare import PLAN, POINTS_PER_SAMPLE, SAMPLES, compare  # noqa: E402

BIN = os.path.abspath(sys.argv[1])
SRC = os.path.abspath(sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(__file__), "..", ".."))
SCRIPT = os.path.join(SRC, "deploy", "slurm", "study-array.sh")
PSQL = next(iter(sorted(glob.glob("/usr/lib/postgresql/*/bin/psql"), reverse=True)), "psql")
check = Checks(verbose=True)
tmp = tempfile.mkdtemp(prefix="synbench-slurm-")
os.chmod(tmp, 0o755)
plan = os.path.join(tmp, "study.json")
with open(plan, "w") as f:
    json.dump(PLAN, f)


def run(*args, timeout=120, **kw):
    return subprocess.run(list(args), capture_output=True, text=True, timeout=timeout, **kw)


def psql(url, sql):
    p = run(PSQL, "-At", "-F", "\t", url, "-c", sql, timeout=30)
    return [line.split("\t") for line in p.stdout.splitlines()] if p.returncode == 0 else []


def shard_points(url, shard, shards):
    rows = psql(url, "SELECT s.key, COUNT(p.id) FROM sweeps s JOIN points p ON p.sweep_id = s.id GROUP BY s.id, s.key")
    return sum(int(n) for key, n in rows if int(key.rsplit("/", 1)[1]) % shards == shard)


def sbatch(env, *args):
    """The documented submission, from the study's directory; returns the job id."""
    p = run("sbatch", *args, cwd=tmp, env=env)
    m = re.search(r"Submitted batch job (\d+)", p.stdout)
    check(m is not None, f"sbatch {' '.join(args)}: submitted ({p.stdout.strip()} {p.stderr.strip()})")
    return m.group(1) if m else None


def job_tasks(env, job):
    """{array index: state} of the job's tasks still queued or running."""
    p = run("squeue", "-h", "-r", "-j", job, "-o", "%K %T", env=env)
    out = {}
    for line in p.stdout.splitlines():
        k, state = line.split()
        if k.isdigit():
            out[int(k)] = state
    return out


def wait_done(env, job, timeout_s=600):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if run("squeue", "-h", "-j", job, env=env).stdout.strip() == "":
            return True
        time.sleep(0.2)
    return False


def output(job, task):
    path = os.path.join(tmp, f"synbench-study-{job}_{task}.out")
    return open(path).read() if os.path.exists(path) else f"(no {path})"


def study(*args, timeout=600):
    p = run(BIN, "study", *args, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


# --- reference: one process, every sample, uninterrupted ---
ref_db = os.path.join(tmp, "ref.db")
code, out, err = study("run", plan, "--shard", "0/1", "--db", ref_db, "--quiet")
check(code == 0, f"reference run completes ({code}, {err.strip()[-300:]})")
code, out, err = study("analyse", plan, "--db", ref_db, "--json-out", os.path.join(tmp, "ref.json"))
ref = json.load(open(os.path.join(tmp, "ref.json"))) if code == 0 else None

pg_dir = tempfile.mkdtemp(prefix="synbench-slurm-pg-")
slurm_dir = tempfile.mkdtemp(prefix="synbench-slurm-cluster-")
pg = run("sh", os.path.join(SRC, "tests", "db", "pg_cluster.sh"), "start", pg_dir)
sl = run("sh", os.path.join(SRC, "tests", "deploy", "slurm_cluster.sh"), "start", slurm_dir)
try:
    if not (check(pg.returncode == 0, f"PostgreSQL cluster started ({pg.stderr.strip()[-300:]})")
            and check(sl.returncode == 0, f"one-node Slurm started ({sl.stderr.strip()[-600:]})")):
        check.finish("")
    url = f"postgresql://synbench@127.0.0.1:{pg.stdout.split()[-1]}/study"
    run(PSQL, url.rsplit("/", 1)[0] + "/postgres", "-c", "CREATE DATABASE study", timeout=30)
    env = dict(os.environ, SLURM_CONF=sl.stdout.split()[-1], SYNBENCH=BIN, SYNBENCH_DB=url)
    print(run("sinfo", "-N", "-o", "%N %c %t", env=env).stdout, flush=True)

    # --- the study as four array tasks; task 1 cancelled mid-sample ---
    job = sbatch(env, "--array=0-3", SCRIPT, plan, "4")
    victim, cancelled_at = 1, None
    deadline = time.monotonic() + 300
    while job and time.monotonic() < deadline:
        if victim not in job_tasks(env, job):
            break  # ended before it could be cancelled: a failure below
        n = shard_points(url, victim, 4)
        if n >= 1 and n % POINTS_PER_SAMPLE != 0:  # inside a sample, not between two
            p = run("scancel", f"{job}_{victim}", env=env)
            check(p.returncode == 0, f"scancel {job}_{victim} ({p.stderr.strip()})")
            cancelled_at = n
            break
        time.sleep(0.01)
    check(cancelled_at is not None, f"task {victim} cancelled mid-sample after {cancelled_at} points")
    check(job and wait_done(env, job), "the array's tasks end")
    for k in range(4):
        print(f"--- task {k} ---\n{output(job, k)}", flush=True)
        check(f"shard {k}/4" in output(job, k), f"task {k} runs shard {k}/4")
    check(re.search(r"interrupted", output(job, victim)) is not None,
          f"the cancelled task stops in order (SIGTERM): {output(job, victim).strip()[-300:]}")

    code, out, err = study("status", plan, "--db", url, "--shards", "4", "--json")
    st = {s["shard"]: s for s in json.loads(out)["shards"]} if code == 0 else {}
    v = st.get(f"{victim}/4", {})
    check(v.get("done", 0) < v.get("samples", 0), f"status: shard {victim} is incomplete ({v})")
    check(all(st.get(f"{k}/4", {}).get("done") == 2 for k in range(4) if k != victim),
          f"status: the other shards are done ({list(st.values())})")

    # --- the documented re-run of task 1: shard 1 of 4, resumed ---
    rerun = sbatch(env, f"--array={victim}", SCRIPT, plan, "4")
    check(rerun and wait_done(env, rerun), "the re-run ends")
    text = output(rerun, victim)
    print(f"--- re-run of task {victim} ---\n{text}", flush=True)
    check(f"shard {victim}/4" in text and "shard 0/1" not in text, f"the re-run runs shard {victim}/4, not the whole study")
    resumed = [int(b) for b in re.findall(r"\((\d+) before this run\)", text)]
    check(cancelled_at is not None and any(cancelled_at % POINTS_PER_SAMPLE <= b < POINTS_PER_SAMPLE for b in resumed if b > 0),
          f"the re-run resumes the cancelled sample at its first missing point ({resumed}, cancelled at {cancelled_at})")

    code, out, err = study("status", plan, "--db", url, "--shards", "4", "--json")
    shards = json.loads(out)["shards"] if code == 0 else []
    check(len(shards) == 4 and all(s["done"] == s["samples"] and s["missing"] == 0 and s["running"] == 0 for s in shards),
          f"status after the re-run: every shard done ({shards})")
    rows = psql(url, "SELECT s.state, COUNT(p.id), COUNT(DISTINCT p.point_index) FROM sweeps s "
                     "LEFT JOIN points p ON p.sweep_id = s.id GROUP BY s.id, s.state")
    check(len(rows) == SAMPLES and all(r == ["completed", str(POINTS_PER_SAMPLE), str(POINTS_PER_SAMPLE)] for r in rows),
          f"every sample completed with each point once ({rows})")
    code, out, err = study("analyse", plan, "--db", url, "--json-out", os.path.join(tmp, "slurm.json"))
    if check(code == 0 and ref is not None, f"analyse the Slurm study and the reference ({code}, {err.strip()[-200:]})"):
        compare(check, ref, json.load(open(os.path.join(tmp, "slurm.json"))), "slurm")

    # --- an index outside 0..N-1 is refused by the job ---
    bad = sbatch(env, "--array=4", SCRIPT, plan, "4")
    check(bad and wait_done(env, bad), "the out-of-range task ends")
    text = output(bad, 4)
    check("array index 4 is not a shard of 4: submit indices 0..3" in text, f"index 4 of 4 refused ({text.strip()})")
finally:
    run("sh", os.path.join(SRC, "tests", "deploy", "slurm_cluster.sh"), "stop", slurm_dir)
    run("sh", os.path.join(SRC, "tests", "db", "pg_cluster.sh"), "stop", pg_dir)

check.finish("slurm test ok")
