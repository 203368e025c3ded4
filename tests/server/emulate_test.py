#!/usr/bin/env python3
"""`synbench emulate` as a user and a third-party master meet it: --help, bad input rejected with
exit 2 naming the flag, mbpoll (Debian's Modbus master) reading documented telemetry and writing a
setpoint over TCP and RTU, and over both at once on one twin (a write on one link read back on the
other, a cut silencing both), and `synbench point --bench` measuring one operating point over Modbus
TCP and RTU (socat pseudo-terminals) with the same record as in-process, within the measurement
noise, the emulator then serving that window's batches (10 per quantity, consistent with the
window's means and counts). Exit 77 (skipped) where mbpoll or socat is missing."""
import json
import os
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time

from checks import Checks

BIN = sys.argv[1]
TIME_SCALE = 20  # twin seconds per wall second, on both sides
# At 20x the firmware's 500 ms watchdog is 25 ms of wall time: a loaded CI machine can stall
# the bench that long. The watchdog has its own tests (tests/drivers/bus/link_cut_test.cpp).
SCALED = ["--time-scale", str(TIME_SCALE), "--watchdog-timeout-ms", "5000"]
POINT = ["--speed-rpm", "700", "--load-Nm", "2.5", "--angle-deg", "52", "--json"]
MEASURED = """speed_meas_rpm im_A id_A iq_A ud_V uq_V udc_V idcm_A idcg_A pdcm_W pdcg_W pm_W
efficiency""".split()
check = Checks(verbose=True)
tmp = tempfile.mkdtemp(prefix="synbench_emulate_test_")

for tool in ("mbpoll", "socat"):
    if not shutil.which(tool):
        print(f"skip: {tool} is not installed (scripts/debian-packages.txt)")
        sys.exit(77)


def run(*args, timeout=120):
    p = subprocess.run([BIN, *args], capture_output=True, text=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


class Emulator:
    """synbench emulate in the background; stopped (and its fault counts read) on exit."""

    def __init__(self, *args):
        self.p = subprocess.Popen([BIN, "emulate", *args, "--duration-s", "120"], stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True)
        self.banner = self.p.stdout.readline().strip()
        m = re.match(r"listening on tcp .*:(\d+)$", self.banner)
        self.port = int(m.group(1)) if m else None

    def stop(self):
        self.p.send_signal(signal.SIGTERM)
        out, err = self.p.communicate(timeout=10)
        return self.p.returncode, out, err


def mbpoll(*args):
    p = subprocess.run(["mbpoll", "-1", "-0", "-o", "1", *args], capture_output=True, text=True, timeout=20)
    return p.returncode, dict((int(k), v) for k, v in re.findall(r"^\[(\d+)\]:\s+(\S+)", p.stdout, re.M))


class SocatPair:
    def __init__(self, name):
        self.a, self.b = os.path.join(tmp, name + "_a"), os.path.join(tmp, name + "_b")
        self.p = subprocess.Popen(["socat", f"pty,raw,echo=0,link={self.a}", f"pty,raw,echo=0,link={self.b}"],
                                  stderr=subprocess.DEVNULL)
        for _ in range(200):
            if os.path.exists(self.a) and os.path.exists(self.b):
                break
            time.sleep(0.01)

    def stop(self):
        self.p.terminate()
        self.p.wait(timeout=10)


def bench_config(name, link, **extra):
    path = os.path.join(tmp, name + ".json")
    with open(path, "w") as f:
        # A generous window margin: on a loaded machine the twin may fall behind the bench's clock.
        json.dump({"time_scale": TIME_SCALE, "window_margin_s": 60, "links": {"emu": link},
                   "devices": {k: {"profile": "default", "link": "emu"}
                               for k in ("synrm_drive", "load_drive", "vfc_meter")}, **extra}, f)
    return path


# --- the command line ------------------------------------------------------------------------
code, out, _ = run("emulate", "--help")
check(code == 0 and "--tcp" in out and "--rtu" in out and "--time-scale" in out and "--fault-drop-pct" in out,
      "emulate --help")
code, out, _ = run("--help")
check("emulate" in out, "--help lists emulate")
code, out, _ = run("point", "--help")
check("--bench" in out, "point --help documents --bench")

bad = [
    ([], "--tcp"),
    (["--tcp", "127.0.0.1"], "--tcp"),
    (["--tcp", "127.0.0.1:99999"], "--tcp"),
    (["--rtu", ""], "--rtu"),
    (["--tcp", "127.0.0.1:0", "--baud", "9600"], "--baud"),
    (["--rtu", "/dev/null", "--baud", "12345"], "--baud"),
    (["--rtu", "/dev/null", "--parity", "mark"], "--parity"),
    (["--tcp", "127.0.0.1:0", "--time-scale", "0"], "--time-scale"),
    (["--tcp", "127.0.0.1:0", "--time-scale", "abc"], "--time-scale"),
    (["--tcp", "127.0.0.1:0", "--fault-drop-pct", "120"], "--fault-drop-pct"),
    (["--tcp", "127.0.0.1:0", "--fault-delay-pct", "60", "--fault-drop-pct", "60"], "--fault-delay-pct"),
    (["--tcp", "127.0.0.1:0", "--fault-delay-ms", "0"], "--fault-delay-ms"),
    (["--tcp", "127.0.0.1:0", "--watchdog-timeout-ms", "-5"], "--watchdog-timeout-ms"),
    (["--tcp", "127.0.0.1:0", "--fault-stuck", "7:speed_rpm"], "--fault-stuck"),
    (["--tcp", "127.0.0.1:0", "--fault-stuck", "1:no_such_signal"], "--fault-stuck"),
    (["--tcp", "127.0.0.1:0", "--frobnicate"], "--frobnicate"),
]
for args, flag in bad:
    code, out, err = run("emulate", *args)
    check(code == 2 and flag in err and out == "", f"emulate exit 2 naming {flag} for {' '.join(args)}: {err.strip()}")
code, out, err = run("emulate", "--rtu", os.path.join(tmp, "no_such_port"))
check(code == 1 and "--rtu" in err, f"emulate exit 1 when the port does not open: {err.strip()}")

tcp_cfg = bench_config("tcp_bad_port", {"transport": "tcp", "host": "127.0.0.1", "port": 70000})
code, out, err = run("point", *POINT, "--bench", tcp_cfg)
check(code == 2 and "--bench" in err and "/links/emu/port" in err and out == "",
      f"point --bench names the bad key: {err.strip()}")
code, out, err = run("point", *POINT, "--bench", os.path.join(tmp, "missing.json"))
check(code == 2 and "--bench" in err, "point --bench with a missing file")
tcp_cfg = bench_config("tcp_ok", {"transport": "tcp", "host": "127.0.0.1", "port": 1})
code, out, err = run("point", *POINT, "--bench", tcp_cfg, "--seed", "3")
check(code == 2 and "--seed" in err, f"--seed refused for a remote bench: {err.strip()}")
code, out, err = run("point", *POINT, "--bench", tcp_cfg)
# Under the safety supervisor a link that never answers is a lost link: a latched fault (exit 3),
# and the drives, which cannot be read back, raise the alarm.
check(code == 3 and "link_loss" in err and "ALARM" in err, f"point exits 3 on a lost link: {err.strip()[:160]}")

# --- mbpoll against the emulator -------------------------------------------------------------
emu = Emulator("--tcp", "127.0.0.1:0")
check(emu.port is not None, f"emulate prints its port: {emu.banner}")
tcp = ["-m", "tcp", "-p", str(emu.port)]
code, v = mbpoll(*tcp, "-a", "1", "-t", "3", "-r", "0", "-c", "2", "127.0.0.1")
check(code == 0 and v == {0: "0", 1: "0"}, f"mbpoll reads state and fault_code (input 0-1): {v}")
code, v = mbpoll(*tcp, "-a", "1", "-t", "3", "-r", "30", "-c", "1", "127.0.0.1")
check(code == 0 and 4000 <= int(v.get(30, 0)) <= 4500, f"mbpoll reads udc_V (input 30, 0.1 V): {v}")
code, v = mbpoll(*tcp, "-a", "1", "-t", "4:float", "-B", "-r", "16", "127.0.0.1", "700")
check(code == 0, "mbpoll writes speed_setpoint_rpm (holding 16-17, f32) = 700")
code, v = mbpoll(*tcp, "-a", "1", "-t", "4:float", "-B", "-r", "16", "127.0.0.1")
check(code == 0 and float(v.get(16, "nan")) == 700.0, f"mbpoll reads the setpoint back: {v}")
code, v = mbpoll(*tcp, "-a", "2", "-t", "4:float", "-B", "-r", "16", "127.0.0.1", "60")
check(code != 0, "a torque setpoint outside the profile's limits is refused")
code, v = mbpoll(*tcp, "-a", "3", "-t", "3:float", "-B", "-r", "106", "-c", "1", "127.0.0.1")
check(code == 0 and float(v.get(106, "nan")) == 0.0, f"mbpoll reads the meter's gate_s: {v}")
emu.p.send_signal(signal.SIGUSR1)
time.sleep(0.2)
code, v = mbpoll(*tcp, "-a", "1", "-t", "3", "-r", "0", "127.0.0.1")
check(code != 0, "SIGUSR1 cuts the link")
code, out, err = emu.stop()
check(code == 0 and "link cut for 2 s" in out and "faults: requests" in out,
      f"emulate stops on SIGTERM and reports: {out.strip().splitlines()[-2:]}")

pair = SocatPair("mbpoll")
emu = Emulator("--rtu", pair.a)
check(emu.banner == f"listening on rtu {pair.a}", f"emulate --rtu banner: {emu.banner}")
code, v = mbpoll("-m", "rtu", "-b", "115200", "-P", "none", "-a", "1", "-t", "3", "-r", "0", "-c", "2", pair.b)
check(code == 0 and v == {0: "0", 1: "0"}, f"mbpoll over RTU reads state and fault_code: {v}")
code, v = mbpoll("-m", "rtu", "-b", "115200", "-P", "none", "-a", "1", "-t", "4", "-r", "19", pair.b, "1")
check(code == 0, "mbpoll over RTU writes pwm_scheme = aspwm")
emu.stop()

# Both links at once on the same twin: a write over RTU is read back over TCP, and the other way.
emu = Emulator("--rtu", pair.a, "--tcp", "127.0.0.1:0")
rtu_banner = emu.p.stdout.readline().strip()
check(emu.port is not None and rtu_banner == f"listening on rtu {pair.a}",
      f"emulate --rtu --tcp prints both links: {emu.banner} / {rtu_banner}")
rtu = ["-m", "rtu", "-b", "115200", "-P", "none"]
code, _ = mbpoll(*rtu, "-a", "1", "-t", "4:float", "-B", "-r", "16", pair.b, "321")
code2, v = mbpoll("-m", "tcp", "-p", str(emu.port), "-a", "1", "-t", "4:float", "-B", "-r", "16", "127.0.0.1")
check(code == 0 and code2 == 0 and float(v.get(16, "nan")) == 321.0,
      f"speed_setpoint_rpm written over RTU reads 321 over TCP: {v}")
code, _ = mbpoll("-m", "tcp", "-p", str(emu.port), "-a", "1", "-t", "4", "-r", "19", "127.0.0.1", "1")
code2, v = mbpoll(*rtu, "-a", "1", "-t", "4", "-r", "19", pair.b)
check(code == 0 and code2 == 0 and v.get(19) == "1", f"pwm_scheme written over TCP reads 1 over RTU: {v}")
emu.p.send_signal(signal.SIGUSR1)
time.sleep(0.2)
code, _ = mbpoll("-m", "tcp", "-p", str(emu.port), "-a", "1", "-t", "3", "-r", "0", "127.0.0.1")
code2, _ = mbpoll(*rtu, "-a", "1", "-t", "3", "-r", "0", pair.b)
check(code != 0 and code2 != 0, "SIGUSR1 cuts both links")
emu.stop()
pair.stop()

# --- one operating point: in-process, over TCP, over RTU --------------------------------------
reference = []
for seed in range(1, 9):
    code, out, err = run("point", *POINT, "--seed", str(seed))
    check(code == 0, f"in-process point, seed {seed}")
    reference.append(json.loads(out))
base = reference[0]
sigma = {k: statistics.stdev(r[k] for r in reference) for k in MEASURED}


def same_record(name, rec):
    """Within the measurement noise: 6 standard deviations of the in-process record over 8 noise
    seeds, or 1e-4 relative (f32 registers; the twin cools slightly while the emulator idles)."""
    worst = []
    for k in MEASURED:
        tol = max(6 * sigma[k], 1e-4 * abs(base[k]))
        dev = abs(rec[k] - base[k])
        worst.append((dev / tol, k))
        check(dev <= tol, f"{name}: {k} {rec[k]:.6g} vs {base[k]:.6g} (|d| {dev:.3g} <= {tol:.3g})")
    print(f"  {name}: largest deviation {max(worst)[0]:.2f} of tolerance ({max(worst)[1]}); "
          + ", ".join(f"{k} {abs(rec[k] - base[k]) / sigma[k]:.1f} sigma" for k in ("efficiency", "pdcm_W", "im_A")))
    check(abs(rec["temp_C"] - base["temp_C"]) < 0.5, f"{name}: temp_C {rec['temp_C']:.3f}")
    check(rec["samples"] == base["samples"] and abs(rec["window_s"] - base["window_s"]) < 1e-6,
          f"{name}: the same window ({rec['samples']} samples)")
    for k in ("voltage_limited", "unstable", "fault", "estimator", "pwm"):
        check(rec[k] == base[k], f"{name}: {k} = {rec[k]}")
    check(rec["truth"] is None, f"{name}: no truth from a Modbus bench")


def served_batches(name, link, host):
    """The last window's batches as `synbench emulate` serves them (docs/register-map.md): 10
    f32 batch means per drive quantity averaging to the window's mean (mbpoll prints 6 digits),
    10 u32 sub-gate counts per meter channel summing to the gate's counts exactly."""
    def values(unit, table, address, count):
        code, v = mbpoll(*link, "-a", str(unit), "-t", table, "-B", "-r", str(address), "-c", str(count), host)
        return [float(v[k]) for k in sorted(v)] if code == 0 else []
    for unit, mean_at, batches_at, what in ((1, 110, 144, "window_im_A"), (1, 108, 164, "window_speed_meas_rpm"),
                                            (2, 104, 106, "window_torque_Nm")):
        mean, batches = values(unit, "3:float", mean_at, 1), values(unit, "3:float", batches_at, 10)
        ok = len(mean) == 1 and len(batches) == 10 and mean[0] != 0
        # Speed: a batch's encoder count is 0.03 rpm of the mean over 10 batches at 1 s.
        tol = 2e-5 * abs(mean[0]) + (0.1 if what == "window_speed_meas_rpm" else 0)
        check(ok and abs(sum(batches) / 10 - mean[0]) <= tol,
              f"{name}: emulate serves 10 batches of {what} averaging to its window mean: {mean} vs {batches}")
    for total_at, batches_at, what in ((102, 112, "counts_m"), (104, 132, "counts_g")):
        total, batches = values(3, "3:int", total_at, 1), values(3, "3:int", batches_at, 10)
        check(len(total) == 1 and len(batches) == 10 and total[0] > 0 and sum(batches) == total[0],
              f"{name}: emulate serves 10 sub-gate {what} summing to the gate's: {total} vs {batches}")


emu = Emulator("--tcp", "127.0.0.1:0", *SCALED)
# The bench config's "uncertainty" reaches the point's budget over Modbus (docs/uncertainty.md).
cfg = bench_config("tcp", {"transport": "tcp", "host": "127.0.0.1", "port": emu.port, "response_timeout_ms": 200},
                   uncertainty={"udc_gain_u_pct": 2.0, "torque_offset_u_Nm": 0.05})
t0 = time.time()
code, out, err = run("point", *POINT, "--bench", cfg, "--budget", timeout=60)
wall = time.time() - t0
check(code == 0, f"point over TCP ({wall:.2f} s wall): {err.strip()[:200]}")
if code == 0:
    rec, budget = json.loads(out)["record"], json.loads(out)["budget"]
    same_record("tcp", rec)
    served_batches("tcp", ["-m", "tcp", "-p", str(emu.port)], "127.0.0.1")
    comps = {c["name"]: c for c in budget["components"]}
    check(abs(comps["U_dc gain"]["u"] - 0.02 * rec["udc_V"]) < 1e-6 and comps["torque offset"]["u"] == 0.05,
          f"tcp: the bench config's uncertainty section in the budget ({comps['U_dc gain']['u']} V)")
    check(rec["pdcm_u_W"] is not None and rec["pdcm_u_repeat_W"] is not None and rec["efficiency_u"] is not None,
          f"tcp: the served batches give every uncertainty (pdcm_u_repeat_W {rec['pdcm_u_repeat_W']})")
    check(rec["pdcm_u_W"] == budget["combined"]["pdcm_W"] and rec["pm_u_W"] == budget["combined"]["pm_W"]
          and rec["efficiency_u_repeat"] == budget["repeat"]["efficiency"],
          f"tcp: the record's u fields are its budget's (pdcm_u_W {rec['pdcm_u_W']})")
code, emu_out, _ = emu.stop()
print("  " + " | ".join(emu_out.strip().splitlines()[-2:]))

pair = SocatPair("point")
emu = Emulator("--rtu", pair.a, *SCALED)
cfg = bench_config("rtu", {"transport": "rtu", "device": pair.b, "baud": 115200, "response_timeout_ms": 200})
t0 = time.time()
code, out, err = run("point", *POINT, "--bench", cfg, timeout=60)
wall = time.time() - t0
check(code == 0, f"point over RTU ({wall:.2f} s wall): {err.strip()[:200]}")
if code == 0:
    same_record("rtu", json.loads(out))
    served_batches("rtu", ["-m", "rtu", "-b", "115200", "-P", "none"], pair.b)
code, emu_out, _ = emu.stop()
print("  " + " | ".join(emu_out.strip().splitlines()[-2:]))
pair.stop()

twin_cfg = bench_config("twin", {"transport": "twin"})
code, out, err = run("point", *POINT, "--bench", twin_cfg)
check(code == 0, "point --bench on the in-process twin's register map")
if code == 0:
    rec = json.loads(out)
    check(all(abs(rec[k] - base[k]) <= 1e-6 * abs(base[k]) + 1e-9 for k in MEASURED),
          "the in-process register map gives the direct record to f32 precision")

shutil.rmtree(tmp, ignore_errors=True)
check.finish("all checks passed")
