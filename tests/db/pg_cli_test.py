"""synbench on a PostgreSQL lab store, end to end, on a throwaway cluster (tests/db/pg_cluster.sh):

- three `synbench sweep --db postgresql://...` on the twin at once, as three benches: every point
  stored, ids distinct, each sweep with its own bench name, host and the twin's devices;
- a writer killed (SIGKILL) mid-sweep, resumed with `--resume`: it restarts at its first missing
  point, every index once;
- two `synbench serve --db postgresql://...` daemons as two benches, each running a sweep over REST
  at the same time: both complete, each sweep under its own bench, read back over REST and with
  psql alike, and either daemon's history lists both benches' runs; `synbench report --db` on one;
- `synbench sweep --bench` over Modbus TCP against `synbench emulate`: the sweep carries the bench
  config's profiles, by name, with their content versions;
- a password in the URL is never printed by sweep, serve or report.

Fails (exit 1) when PostgreSQL is not installed: it is a dependency (README's setup)."""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "server"))
from checks import Checks  # noqa: E402
from daemon import Daemon, wait_for  # noqa: E402
import far_side as fs  # noqa: E402

BIN = sys.argv[1]
CLUSTER = os.path.join(HERE, "pg_cluster.sh")
check = Checks(verbose=False)
SECRET = "pw-never-printed"


def psql(sock_dir, port, db, sql):
    r = subprocess.run(["psql", "-X", "-q", "-A", "-t", "-v", "ON_ERROR_STOP=1",
                        "host=%s port=%d user=synbench dbname=%s" % (sock_dir, port, db), "-c", sql],
                       capture_output=True, text=True, timeout=60)
    if r.returncode != 0:
        raise RuntimeError("psql: " + r.stderr)
    return r.stdout.strip()


def write_plan(path, name, angles):
    with open(path, "w") as f:
        json.dump({"name": name, "window_s": 0.2,
                   "dimensions": {"speed_rpm": [500], "load_Nm": [1.0], "angle_deg": angles}}, f)


def main():
    work = tempfile.mkdtemp(prefix="synbench-pgcli-")
    cluster = tempfile.mkdtemp(prefix="synbench-pg-")  # its own, under /tmp: `nobody` must reach it
    r = subprocess.run([CLUSTER, "start", cluster], capture_output=True, text=True)
    if r.returncode != 0:
        print("FAIL: the PostgreSQL test cluster did not start: " + r.stderr.strip(), flush=True)
        sys.exit(1)
    port = int(r.stdout.strip())
    try:
        psql(cluster, port, "postgres", "CREATE DATABASE lab")
        url = "postgresql://synbench:%s@127.0.0.1:%d/lab" % (SECRET, port)  # trust: the password is unused
        parallel_sweeps(work, cluster, port, url)
        killed_and_resumed(work, cluster, port, url)
        served(work, cluster, port, url)
        over_modbus(work, cluster, port, url)
    finally:
        subprocess.run([CLUSTER, "stop", cluster])
        shutil.rmtree(work, ignore_errors=True)
    check.finish("pg cli test ok")


def parallel_sweeps(work, sock, port, url):
    angles = [40, 44, 48, 52, 56, 60]
    procs = []
    for b in range(3):
        plan = os.path.join(work, "plan%d.json" % b)
        write_plan(plan, "parallel %d" % b, angles)
        procs.append(subprocess.Popen([BIN, "sweep", plan, "--db", url, "--bench-name", "bench-%d" % b],
                                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))
    outs = [p.communicate(timeout=300) for p in procs]
    for b, (p, (out, err)) in enumerate(zip(procs, outs)):
        check(p.returncode == 0, "sweep %d into PostgreSQL exits 0 (%s)" % (b, err[-400:]))
        check(SECRET not in out + err, "sweep %d never prints the URL's password" % b)
        check("synbench:***@127.0.0.1" in err, "sweep %d names the store with the password redacted (%r)" % (b, err[-300:]))
    rows = psql(sock, port, "lab", "SELECT s.id, s.bench_name, s.bench_host, s.devices_json, s.state, count(p.id), "
                "count(DISTINCT p.point_index) FROM sweeps s LEFT JOIN points p ON p.sweep_id = s.id "
                "GROUP BY s.id ORDER BY s.id").splitlines()
    check(len(rows) == 3, "three sweeps stored (%r)" % rows)
    names = set()
    for row in rows:
        sid, name, host, devices, state, n, distinct = row.split("|")
        names.add(name)
        check(state == "completed" and int(n) == len(angles) and int(distinct) == len(angles),
              "sweep %s: completed with all %d points, each index once (%s)" % (sid, len(angles), row))
        check(host == os.uname().nodename, "sweep %s carries this host (%s)" % (sid, host))
        devs = json.loads(devices)
        check([d["device"] for d in devs] == ["synrm_drive", "load_drive", "vfc_meter"] and
              all(d["profile"] == "synbench twin" and d["version"] for d in devs),
              "sweep %s carries the twin's devices and versions (%s)" % (sid, devices))
    check(names == {"bench-0", "bench-1", "bench-2"}, "each sweep carries its own bench name (%s)" % names)
    ids = psql(sock, port, "lab", "SELECT count(*), count(DISTINCT id) FROM points")
    check(ids == "%d|%d" % (3 * len(angles), 3 * len(angles)), "point ids distinct across writers (%s)" % ids)


def killed_and_resumed(work, sock, port, url):
    plan = os.path.join(work, "killed.json")
    angles = list(range(30, 80, 4))  # 13 points
    write_plan(plan, "killed", angles)
    p = subprocess.Popen([BIN, "sweep", plan, "--db", url, "--print-committed", "--quiet"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    committed = [p.stdout.readline() for _ in range(3)]
    p.send_signal(signal.SIGKILL)
    p.communicate(timeout=30)
    check(all(c.startswith("committed") for c in committed), "the writer committed 3 points before the kill (%r)" % committed)
    sid = psql(sock, port, "lab", "SELECT id FROM sweeps WHERE name = 'killed'")
    before = int(psql(sock, port, "lab", "SELECT count(*) FROM points WHERE sweep_id = %s" % sid))
    check(3 <= before < len(angles), "the killed sweep holds its committed points only (%d)" % before)
    first_missing = int(psql(sock, port, "lab", "SELECT min(i) FROM generate_series(0, %d) i WHERE i NOT IN "
                             "(SELECT point_index FROM points WHERE sweep_id = %s)" % (len(angles) - 1, sid)))
    r = subprocess.run([BIN, "sweep", "--resume", sid, "--db", url, "--print-committed", "--quiet"],
                       capture_output=True, text=True, timeout=300)
    check(r.returncode == 0, "the resumed sweep completes (%s)" % r.stderr[-400:])
    resumed = [int(l.split()[1]) for l in r.stdout.splitlines() if l.startswith("committed")]
    check(resumed and resumed[0] == first_missing, "it resumes at the first missing point %d (%r)" % (first_missing, resumed[:3]))
    stats = psql(sock, port, "lab", "SELECT count(*), count(DISTINCT point_index), min(point_index), max(point_index) "
                 "FROM points WHERE sweep_id = %s" % sid)
    check(stats == "%d|%d|0|%d" % (len(angles), len(angles), len(angles) - 1),
          "every index stored exactly once after the resume (%s)" % stats)


def served(work, sock, port, url):
    """Two daemons, two benches, one lab store: each runs a sweep over REST at the same time."""
    benches = ("served-bench", "served-bench-2")
    daemons = []
    try:
        for name in benches:
            daemons.append(Daemon(BIN, os.path.join(work, name), extra_args=["--db", url, "--bench-name", name]))
        sids = []
        for k, d in enumerate(daemons):
            s, body = d.request("POST", "/api/sweeps", {
                "name": "over rest %d" % k, "window_s": 0.2,
                "dimensions": {"speed_rpm": [500], "load_Nm": [1.0], "angle_deg": [44, 50, 56]}})
            check(s == 201, "daemon %d: POST /api/sweeps -> 201 (%s)" % (k, body))
            sids.append(body["id"])
        check(len(set(sids)) == 2, "the two daemons' sweeps have distinct ids in the one store (%s)" % sids)
        for k, (d, sid) in enumerate(zip(daemons, sids)):
            s, body = d.request("POST", "/api/sweeps/%d/start" % sid)
            check(s == 202, "daemon %d: start -> 202 (%s)" % (k, body))
        for k, (d, sid) in enumerate(zip(daemons, sids)):
            done = wait_for(lambda: d.request("GET", "/api/sweeps/%d" % sid)[1].get("state") == "completed", 180, 0.5)
            check(done, "daemon %d: its sweep completes while the other writes (%s)" % (k, d.request("GET", "/api/sweeps/%d" % sid),))
        for k, (d, sid) in enumerate(zip(daemons, sids)):
            s, pts = d.request("GET", "/api/sweeps/%d/points" % sid)
            items = pts["points"] if isinstance(pts, dict) and "points" in pts else pts
            check(s == 200 and len(items) == 3, "daemon %d: three points over REST (%s)" % (k, str(pts)[:300]))
            rest_im = sorted(float(p["im_A"]) for p in items)
            db_im = sorted(float(x) for x in psql(
                sock, port, "lab", "SELECT im_a FROM points WHERE sweep_id = %d" % sid).splitlines())
            check(rest_im == db_im, "daemon %d: REST and psql read the same points (%s vs %s)" % (k, rest_im, db_im))
            who = psql(sock, port, "lab", "SELECT bench_name FROM sweeps WHERE id = %d" % sid)
            check(who == benches[k], "daemon %d: its sweep carries its own bench name (%s)" % (k, who))
            _, sweep = d.request("GET", "/api/sweeps/%d" % sid)
            check(sweep.get("bench", {}).get("name") == benches[k] and len(sweep["bench"]["devices"]) == 3 and
                  sweep.get("key") is None, "daemon %d: GET /api/sweeps/{id} gives the bench's identity (%s)" % (k, sweep.get("bench")))
            check(not os.path.exists(os.path.join(work, benches[k], "synbench.db")),
                  "daemon %d: no SQLite file beside: the store is PostgreSQL" % k)
        # The lab's history: either daemon lists both benches' runs, each under its bench.
        for k, d in enumerate(daemons):
            s, history = d.request("GET", "/api/sweeps")
            by_id = {h["id"]: (h.get("bench") or {}).get("name") for h in history}
            check(s == 200 and [by_id.get(sid) for sid in sids] == list(benches),
                  "daemon %d's history holds both benches' sweeps under their names (%s)" % (k, by_id))
        out = os.path.join(work, "report")
        r = subprocess.run([BIN, "report", str(sids[0]), "--db", url, "--out", out], capture_output=True, text=True, timeout=120)
        check(r.returncode == 0 and any(f.endswith(".html") for f in os.listdir(out)),
              "synbench report --db postgresql://... writes the report (%s)" % r.stderr[-300:])
        check(SECRET not in r.stdout + r.stderr, "report never prints the password")
    finally:
        for d in daemons:
            _, err = d.stop()
            check(SECRET not in (err or ""), "serve never prints or logs the password")


def over_modbus(work, sock, port, url):
    emu = fs.Emulator(BIN, os.path.join(work, "emulate.log"), args=["--duration-s", "300"])
    try:
        cfg = fs.write_bench_config(os.path.join(work, "bench.json"), fs.tcp_link(emu.port))
        plan = os.path.join(work, "modbus.json")
        with open(plan, "w") as f:
            json.dump({"name": "over modbus", "window_s": 0.5,
                       "dimensions": {"speed_rpm": [500], "load_Nm": [0.5], "angle_deg": [50, 54],
                                      "configurations": [{"estimator": "encoder", "pwm": "capwm"}]}}, f)
        r = subprocess.run([BIN, "sweep", plan, "--bench", cfg, "--db", url, "--bench-name", "modbus-bench", "--quiet"],
                           capture_output=True, text=True, timeout=240)
        check(r.returncode == 0, "sweep --bench over Modbus TCP into PostgreSQL (%s)" % r.stderr[-400:])
        row = psql(sock, port, "lab", "SELECT s.devices_json, count(p.id) FROM sweeps s JOIN points p ON p.sweep_id = s.id "
                   "WHERE s.bench_name = 'modbus-bench' GROUP BY s.id")
        devices_text, n = row.rsplit("|", 1) if row else ("[]", "0")
        check(n == "2", "both points over Modbus stored (%s)" % n)
        devices = json.loads(devices_text)
        names = {}
        for kind, file in (("synrm_drive", "synrm_drive"), ("load_drive", "load_drive"), ("vfc_meter", "vfc_meter")):
            with open(os.path.join(HERE, "..", "..", "drivers", "profiles", file + ".json")) as f:
                names[kind] = json.load(f)["name"]
        check([(d["device"], d["profile"]) for d in devices] == list(names.items()),
              "the sweep names the bench config's profiles (%s)" % devices)
        versions = [d["version"] for d in devices]
        check(all(re.fullmatch(r"fnv1a64:[0-9a-f]{16}", v) for v in versions) and len(set(versions)) == 3,
              "each with its own content version (%s)" % versions)
    finally:
        emu.stop()


if __name__ == "__main__":
    main()
