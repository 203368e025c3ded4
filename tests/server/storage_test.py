#!/usr/bin/env python3
"""Storage that cannot be lost unseen, against the real `synbench serve` and `synbench sweep`:
the database deleted (with its WAL and index) while the daemon runs a sweep faults the sweep
with a message naming the file, the daemon logs it on stderr and its routes answer 500
`database` instead of serving from the vanished file; a database with damaged pages and a
read-only one are refused at start (exit 1, the file named); a sweep a crash left `running` is
marked aborted at the daemon's start. Standard library only.

usage: storage_test.py path/to/synbench
"""
import json
import os
import re
import shutil
import sqlite3
import subprocess
import sys
import tempfile
import time

from checks import Checks
from daemon import Daemon, run_sweep

BIN = sys.argv[1]
check = Checks(verbose=False)


def serve_exits(data_dir):
    """Starts serve expecting it to refuse: (exit status, stderr)."""
    r = subprocess.run([BIN, "serve", "--listen", "127.0.0.1:0", "--data-dir", data_dir],
                       capture_output=True, text=True, timeout=30)
    return r.returncode, r.stderr


def tiny_sweep(db, tmp):
    plan = {"name": "tiny", "window_s": 0.2,
            "dimensions": {"speed_rpm": [500], "load_Nm": [1.0], "angle_deg": [44, 48, 52, 56]}}
    r = run_sweep(BIN, plan, db, tmp, "--quiet")
    check(r.returncode == 0, "a tiny sweep into %s (%s)" % (db, r.stderr[-300:]))


def deleted_during_sweep(tmp):
    data_dir = os.path.join(tmp, "deleted")
    db = os.path.join(data_dir, "synbench.db")
    d = Daemon(BIN, data_dir)
    try:
        s, body = d.request("POST", "/api/sweeps", {
            "name": "doomed", "window_s": 0.3,
            "dimensions": {"speed_rpm": [400], "load_Nm": [0.5], "angle_deg": [40, 44, 48, 52, 56, 60, 64, 68]}})
        check(s == 201, "POST /api/sweeps -> 201 (%s)" % body)
        sid = body["id"]
        s, body = d.request("POST", "/api/sweeps/%d/start" % sid)
        check(s == 202, "start -> 202 (%s)" % body)
        # Once the first point is committed, the data directory's database goes.
        deadline = time.time() + 90
        sweep = None
        while time.time() < deadline:
            _, st = d.request("GET", "/api/bench/status")
            sweep = st["sweep"]
            if sweep and sweep["done"] >= 1:
                break
            time.sleep(0.1)
        check(sweep and sweep["done"] >= 1, "the first point was stored (%s)" % sweep)
        for suffix in ("", "-wal", "-shm"):
            if os.path.exists(db + suffix):
                os.remove(db + suffix)
        done_at_delete = sweep["done"]
        while time.time() < deadline:
            _, st = d.request("GET", "/api/bench/status")
            sweep = st["sweep"]
            if sweep["state"] in ("faulted", "completed", "aborted"):
                break
            time.sleep(0.1)
        check(sweep["state"] == "faulted", "the sweep ends faulted (%s)" % sweep)
        check("synbench.db was deleted (link count 0)" in (sweep["error"] or ""),
              "its error names the deleted file: %r" % sweep["error"])
        check(sweep["done"] <= done_at_delete + 1, "no more points counted stored after the deletion (%s)" % sweep)
        check(not st["supervisor"]["tripped"] and not st["supervisor"]["alarm"],
              "the bench stopped in order, no alarm (%s)" % st["supervisor"])
        # Nothing is served from the vanished file.
        s, body = d.request("GET", "/api/sweeps")
        check(s == 500 and body["error"]["code"] == "database" and "synbench.db was deleted" in body["error"]["message"],
              "GET /api/sweeps -> 500 database naming the file (%d %s)" % (s, body))
        s, body = d.request("GET", "/api/sweeps/%d/points" % sid)
        check(s == 500 and body["error"]["code"] == "database", "GET points -> 500 database (%d %s)" % (s, body))
        s, body = d.request("POST", "/api/sweeps", {"name": "x", "dimensions": {"speed_rpm": [400], "load_Nm": [0.5],
                                                                                "angle_deg": [40]}})
        check(s == 500 and body["error"]["code"] == "database", "POST /api/sweeps -> 500 database (%d %s)" % (s, body))
        check(not os.path.exists(db), "the daemon did not write a new file in its place")
    finally:
        code, err = d.stop()
    check(code == 0, "SIGTERM -> exit 0 (%s)" % code)
    check(re.search(r"bench fault: sweep \d+ faulted: storing point \d+ failed: .*synbench\.db was deleted \(link count 0\)", err),
          "the daemon logged the sweep's fault with the file on stderr")
    check("database error: " in err and "synbench.db was deleted" in err, "and the storage failure itself")
    check(err.count("GET") == 0 and err.count("database error: %s" % db) <= 2,
          "a failure repeated by every request is logged once, not per request")


def deleted_under_the_cli(tmp):
    """`synbench sweep`: the file deleted after the first committed point; the sweep faults, exit 1."""
    work = os.path.join(tmp, "cli")
    os.makedirs(work)
    db = os.path.join(work, "campaign.db")
    plan = os.path.join(work, "plan.json")
    with open(plan, "w") as f:
        json.dump({"preset": "thesis-grid", "dimensions": {"configurations": [{"estimator": "encoder", "pwm": "capwm"}]}}, f)
    p = subprocess.Popen([BIN, "sweep", plan, "--db", db, "--print-committed", "--quiet"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = p.stdout.readline()
    for suffix in ("", "-wal", "-shm"):
        if os.path.exists(db + suffix):
            os.remove(db + suffix)
    rest, err = p.communicate(timeout=120)
    check(first.startswith("committed"), "the CLI committed a first point (%r)" % first)
    check(p.returncode == 1, "synbench sweep exits 1 when its database is deleted (%d)" % p.returncode)
    check("%s was deleted (link count 0)" % db in err, "and says so on stderr: %r" % err[-600:])
    # (How many points it committed before it noticed depends on timing: the deletion races the
    # sweep, which runs on virtual time; the store's tests pin the exact behaviour.)
    check("completed" not in err, "nothing reports the sweep completed")


def damaged(tmp):
    data_dir = os.path.join(tmp, "damaged")
    os.makedirs(data_dir)
    db = os.path.join(data_dir, "synbench.db")
    tiny_sweep(db, tmp)
    c = sqlite3.connect(db)
    root = c.execute("SELECT rootpage FROM sqlite_schema WHERE name = 'points'").fetchone()[0]
    page = c.execute("PRAGMA page_size").fetchone()[0]
    c.close()
    with open(db, "r+b") as f:
        f.seek((root - 1) * page)
        f.write(b"\x5a" * page)
    code, err = serve_exits(data_dir)
    check(code == 1, "serve on a damaged database exits 1 (%d)" % code)
    check(db in err and ("quick_check" in err or "malformed" in err), "and names the file and quick_check: %r" % err)
    r = subprocess.run([BIN, "sweep", "--resume", "1", "--db", db], capture_output=True, text=True)
    check(r.returncode == 1 and db in r.stderr, "synbench sweep refuses it too: %d %r" % (r.returncode, r.stderr))


def left_running(tmp):
    data_dir = os.path.join(tmp, "crashed")
    os.makedirs(data_dir)
    db = os.path.join(data_dir, "synbench.db")
    tiny_sweep(db, tmp)
    # As a crash leaves it: running, owned by a process that no longer exists.
    gone = subprocess.Popen(["true"])
    gone.wait()
    c = sqlite3.connect(db)
    c.execute("UPDATE sweeps SET state = 'running', finished_at = NULL, owner_host = ?, owner_pid = ?",
              (os.uname().nodename, gone.pid))
    c.execute("DELETE FROM points WHERE point_index = 3")
    c.commit()
    c.close()
    d = Daemon(BIN, data_dir)
    try:
        s, body = d.request("GET", "/api/sweeps/1")
        check(s == 200 and body["state"] == "aborted", "a sweep left running is aborted at start (%s)" % body)
        check("marked aborted at start: left running by a previous process (pid %d" % gone.pid in (body["last_error"] or ""),
              "with the reason and the process: %r" % body["last_error"])
        s, body = d.request("POST", "/api/sweeps/1/start")
        check(s == 202, "and it can be resumed (%d %s)" % (s, body))
    finally:
        code, err = d.stop()
    check("sweep 1 marked aborted at start" in err, "the daemon logs it at start")


def read_only(tmp):
    ro_dir = os.path.join(tmp, "ro")
    os.makedirs(ro_dir)
    db = os.path.join(ro_dir, "synbench.db")
    tiny_sweep(db, tmp)
    os.chmod(db, 0o444)
    cmd = [BIN, "sweep", "--resume", "1", "--db", db]
    if os.geteuid() == 0:
        # Root writes any file: the refusal is only seen without root's privilege.
        if not shutil.which("setpriv"):
            print("skip: read-only as root needs setpriv")
            return
        for p in (tmp, ro_dir):
            os.chmod(p, 0o777)
        cmd = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"] + cmd
    r = subprocess.run(cmd, capture_output=True, text=True)
    check(r.returncode == 1, "synbench sweep on a read-only database exits 1 (%d %s)" % (r.returncode, r.stderr))
    check(db in r.stderr and "synbench must write it" in r.stderr, "naming the file and why: %r" % r.stderr)


def main():
    tmp = tempfile.mkdtemp(prefix="synbench-storage-")
    os.chmod(tmp, 0o755)
    try:
        deleted_during_sweep(tmp)
        deleted_under_the_cli(tmp)
        damaged(tmp)
        left_running(tmp)
        read_only(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    check.finish("storage_test: all passed")


if __name__ == "__main__":
    main()
