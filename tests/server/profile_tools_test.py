#!/usr/bin/env python3
"""The tools for a drive synbench did not write (issue 23, items 8 and 9), as a user runs them:
`synbench profile check` on valid and broken profiles (every problem named by file and JSON
pointer), `synbench bench check` on a good and a bad config, `bench check --probe` against
`synbench emulate` over Modbus TCP and RTU (a socat pty pair) with the probed values checked from
the far side (our own Modbus TCP master reading the emulator's registers), and `synbench emulate
--profiles DIR` / `--bench CONFIG` serving the twin through a remapped register map (other
addresses, little-endian word order, other unit ids and state codes) on which `synbench point
--bench` measures a whole point, compared with the same point on the default map.
Exit 77 (skipped) without socat."""
import copy
import json
import os
import re
import shutil
import statistics
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402
import far_side  # noqa: E402

BIN = sys.argv[1]
PROFILES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "drivers", "profiles")
KINDS = ("synrm_drive", "load_drive", "vfc_meter")
TIME_SCALE = 20
# At 20x the firmware's 500 ms watchdog is 25 ms of wall time (see emulate_test.py).
SCALED = ["--time-scale", str(TIME_SCALE), "--watchdog-timeout-ms", "5000"]
POINT = ["--speed-rpm", "700", "--load-Nm", "2.5", "--angle-deg", "52", "--json"]
check = Checks(verbose=True)
tmp = tempfile.mkdtemp(prefix="synbench_profile_tools_")

if not shutil.which("socat"):
    print("skip: socat is not installed (scripts/debian-packages.txt)")
    sys.exit(77)


def run(*args, timeout=120):
    p = subprocess.run([BIN, *args], capture_output=True, text=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def load(kind):
    with open(os.path.join(PROFILES, kind + ".json")) as f:
        return json.load(f)


def write(path, doc):
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
    return path


def bench_config(name, link, profiles=None, units=None, time_scale=TIME_SCALE):
    devices = {}
    for k in KINDS:
        devices[k] = {"profile": (profiles or {}).get(k, "default"), "link": "emu"}
        if units:
            devices[k]["unit_id"] = units[k]
    return write(os.path.join(tmp, name + ".json"),
                 {"time_scale": time_scale, "window_margin_s": 60, "links": {"emu": link}, "devices": devices})


def probe_rows(cfg):
    code, out, err = run("bench", "check", cfg, "--probe", "--json", timeout=120)
    try:
        doc = json.loads(out)
    except ValueError:
        doc = {}
    return code, {(r["device"], r["signal"]): r for r in doc.get("probe", [])}, err


def f32(words, little=False):
    hi, lo = (words[1], words[0]) if little else (words[0], words[1])
    return struct.unpack(">f", struct.pack(">HH", hi, lo))[0]


# --- profile check ---------------------------------------------------------------------------
defaults = [os.path.join(PROFILES, k + ".json") for k in KINDS]
code, out, err = run("profile", "check", *defaults)
lines = out.strip().splitlines()
check(code == 0 and len(lines) == 3, f"profile check of the default profiles exits 0: {out.strip()} {err.strip()}")
synrm_signals = len([k for k in load("synrm_drive")["signals"] if not k.startswith("_")])
check(lines and lines[0] == f"{defaults[0]}: ok: synbench SynRM drive, synrm_drive, {synrm_signals} signals, unit ids 1",
      f"the summary names name, kind, signal count and unit ids: {lines[:1]}")
check("vfc_meter" in out and "unit ids 3" in out, "the meter's summary")

broken = {}
doc = load("synrm_drive")
doc["signals"]["state"]["address"] = -1
doc["signals"]["speed_rpm"]["colour"] = "red"
doc["signals"]["im_A"]["type"] = "f64"
broken["a"] = (write(os.path.join(tmp, "broken_a.json"), doc),
               ["/signals/state/address: ", "/signals/speed_rpm/colour: unknown field", "/signals/im_A/type: "])
doc = load("load_drive")
del doc["signals"]["state"]
doc["signals"]["fault_code"]["values"]["none"] = "zero"
doc["unit_id"] = 300
broken["b"] = (write(os.path.join(tmp, "broken_b.json"), doc),
               ["/signals/state: required signal of kind load_drive is missing",
                "/signals/fault_code/values/none: ", "/unit_id: "])
doc = load("vfc_meter")
doc["kind"] = "oscilloscope"
broken["c"] = (write(os.path.join(tmp, "broken_c.json"), doc), ["/kind: "])
path = os.path.join(tmp, "broken_d.json")
with open(path, "w") as f:
    f.write('{"name": "half a file",')
broken["d"] = (path, [""])
code, out, err = run("profile", "check", defaults[0], *[b[0] for b in broken.values()])
check(code == 1, f"profile check exits 1 when a file is broken ({code})")
check(out.startswith(f"{defaults[0]}: ok: "), "a valid file among broken ones is still summarised")
for file, pointers in broken.values():
    for p in pointers:
        check(any(line.startswith(f"{file}: {p}") for line in out.splitlines()), f"profile check names {file}: {p}")
check(all(line.split(": ")[0] in [defaults[0]] + [b[0] for b in broken.values()] for line in out.splitlines()),
      "every line starts with its file")
code, out, err = run("profile", "check")
check(code == 2 and "FILE" in err, f"profile check without a file is a usage error: {err.strip()}")
code, out, err = run("profile", "frob", defaults[0])
check(code == 2, f"an unknown profile action is a usage error: {err.strip()}")
code, out, _ = run("--help")
check("profile" in out, "--help lists profile")

# --- bench check -----------------------------------------------------------------------------
good = bench_config("good", far_side.tcp_link(1502))
code, out, err = run("bench", "check", good)
check(code == 0 and out.startswith(f"{good}: ok") and "synrm_drive: synbench SynRM drive" in out,
      f"bench check of a good config: {out.strip()} {err.strip()}")
bad = bench_config("bad", {"transport": "tcp", "host": "127.0.0.1", "port": 70000})
code, out, err = run("bench", "check", bad)
check(code == 1 and f"{bad}: /links/emu/port: 70000 is outside" in out,
      f"bench check of a bad config exits 1 naming the pointer: {out.strip()}")
bad = bench_config("bad_profile", far_side.tcp_link(1502), profiles={"synrm_drive": broken["a"][0]})
code, out, err = run("bench", "check", bad)
check(code == 1 and f"{bad}: /devices/synrm_drive/profile: {broken['a'][0]} /signals/state/address: " in out,
      f"a broken profile of a config: its file and pointer: {out.strip()[:300]}")
CONFIGS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "config")
for name in ("bench-emulate.json", "bench-twin.json"):
    code, out, err = run("bench", "check", os.path.join(CONFIGS, name))
    check(code == 0 and " ok\n" in out, f"the shipped config/{name} passes bench check: {out.strip()[:100]} {err.strip()}")
code, out, err = run("bench", "check", os.path.join(CONFIGS, "bench-twin.json"), "--probe")
check(code == 0 and "probe over twin" in out and re.search(r"^(\d+) of \1 signals read$", out, re.M),
      f"the in-process twin's register map probed: {out.strip().splitlines()[-1:]}")
clash = bench_config("clash", far_side.tcp_link(1502), units={"synrm_drive": 1, "load_drive": 1, "vfc_meter": 3})
code, out, err = run("bench", "check", clash)
check(code == 1 and f"{clash}: /devices/load_drive/profile: signal 'enable' (coil 0 at unit id 1) overlaps "
      "synrm_drive's signal 'enable'" in out, f"two devices on one link at one unit id: {out.strip()}")

# --- a remapped bench: other addresses, word order, unit ids and state codes -------------------
remap_dir = os.path.join(tmp, "vendor")
os.makedirs(remap_dir)
SHIFT = {"synrm_drive": 500, "load_drive": 700, "vfc_meter": 900}
UNIT = {"synrm_drive": 11, "load_drive": 12, "vfc_meter": 13}
STATE_CODES = {"disabled": 10, "running": 11, "stopping": 12, "faulted": 13}
remapped = {}
for k in KINDS:
    doc = load(k)
    doc["name"] = "vendor " + k
    doc["unit_id"] = UNIT[k]
    doc["word_order"] = "little"
    for s in doc["signals"].values():
        if isinstance(s, dict):
            s["address"] += SHIFT[k]
    if "state" in doc["signals"]:
        doc["signals"]["state"].update(min=10, max=13, values=copy.deepcopy(STATE_CODES))
    remapped[k] = write(os.path.join(remap_dir, f"vendor_{k}.json"), doc)
write(os.path.join(remap_dir, "notes.json"), {"_comment": "not a profile: no kind, skipped"})
code, out, err = run("profile", "check", *remapped.values())
check(code == 0 and "unit ids 11" in out, f"the remapped profiles are valid: {out.strip()} {err.strip()}")

code, out, err = run("emulate", "--tcp", "127.0.0.1:0", "--profiles", os.path.join(tmp, "nowhere"))
check(code == 2 and "--profiles" in err, f"emulate --profiles with no such directory: {err.strip()}")
code, out, err = run("emulate", "--tcp", "127.0.0.1:0", "--profiles", tmp)
check(code == 2 and "--profiles" in err and "broken_a.json: /signals/state/address" in err,
      f"emulate --profiles names a broken profile's file and pointer: {err.strip()[:300]}")
code, out, err = run("emulate", "--tcp", "127.0.0.1:0", "--bench", clash)
check(code == 2 and "--bench" in err and "overlaps" in err, f"emulate --bench refuses colliding devices: {err.strip()[:200]}")
collide_dir = os.path.join(tmp, "collide")
os.makedirs(collide_dir)
for k in KINDS:
    doc = load(k)
    if k == "load_drive":
        doc["unit_id"] = 1  # the SynRM drive's unit id, the same coils and registers
    write(os.path.join(collide_dir, k + ".json"), doc)
code, out, err = run("emulate", "--tcp", "127.0.0.1:0", "--profiles", collide_dir)
check(code == 2 and f"{collide_dir}/load_drive.json: signal 'enable' (coil 0 at unit id 1) overlaps synrm_drive's" in err,
      f"emulate --profiles refuses profiles whose registers collide: {err.strip()[:200]}")
code, out, err = run("emulate", "--tcp", "127.0.0.1:0", "--bench", good, "--profiles", remap_dir)
check(code == 2 and "not both" in err, "emulate --bench and --profiles together")


def states_dir(name, values):
    """The default profiles with the SynRM drive's state codes replaced by `values`."""
    d = os.path.join(tmp, name)
    os.makedirs(d)
    for k in KINDS:
        doc = load(k)
        if k == "synrm_drive":
            doc["signals"]["state"]["values"] = values
        write(os.path.join(d, k + ".json"), doc)
    return d


# A drive state the map has no number for (docs/modbus.md, "Other register maps"): without
# `stopping` the twin's ramp-down is served as running, said once at start; without `running`
# (nor a fallback for stopping) the emulator refuses to start.
no_stopping = states_dir("no_stopping", {"disabled": 0, "running": 1, "faulted": 3})
code, out, err = run("emulate", "--tcp", "127.0.0.1:0", "--profiles", no_stopping, "--duration-s", "0.5")
check(code == 0 and err.count("warning:") == 1 and
      "warning: profile 'synbench SynRM drive' (synrm_drive): signal state has no number for 'stopping'; "
      "the emulator serves 'running' (1) in that state" in err,
      f"emulate warns once for a state served as its fallback: {code} {err.strip()[:300]}")
no_running = states_dir("no_running", {"disabled": 0, "faulted": 3})
code, out, err = run("emulate", "--tcp", "127.0.0.1:0", "--profiles", no_running)
check(code == 2 and out == "" and "--profiles: profile 'synbench SynRM drive' (synrm_drive): signal state has no "
      "number for 'running'" in err and "no number for 'stopping'" in err,
      f"emulate refuses a drive state the map cannot show: {code} {err.strip()[:300]}")

# The reference: the point on the default map, in-process, over 8 noise seeds.
reference = []
for seed in range(1, 9):
    code, out, err = run("point", *POINT, "--seed", str(seed))
    check(code == 0, f"in-process point on the default map, seed {seed}")
    if code == 0:
        reference.append(json.loads(out)["efficiency"])
base, sigma = statistics.mean(reference), statistics.stdev(reference)

emu = far_side.Emulator(BIN, os.path.join(tmp, "emulate_profiles.log"), args=["--profiles", remap_dir, *SCALED])
far = far_side.ModbusTcp(emu.port)
# The far side: the remapped registers are where the profiles say, in their encodings.
state = far.input(UNIT["synrm_drive"], SHIFT["synrm_drive"] + 0)[0]
check(state == STATE_CODES["disabled"], f"far side: the SynRM drive's state at unit 11 input 500 is code 10: {state}")
try:
    far.input(1, 0)
    check(False, "unit 1 is not served by the remapped emulator")
except far_side.ModbusError:
    check(True, "unit 1 is not served by the remapped emulator")
vendor_tcp = bench_config("vendor_tcp", far_side.tcp_link(emu.port), profiles=remapped)
code, rows, err = probe_rows(vendor_tcp)
check(code == 0 and len(rows) > 40, f"bench check --probe over TCP reads every signal ({len(rows)}): {err.strip()[:200]}")
st = rows.get(("synrm_drive", "state"), {})
check(st.get("raw") == [10] and st.get("label") == "disabled" and st.get("unit_id") == 11 and st.get("address") == 500,
      f"probe: state raw 10 is disabled at unit 11 input 500: {st}")
udc = rows.get(("synrm_drive", "udc_V"), {})
udc_far = far.input(11, SHIFT["synrm_drive"] + 30)[0] * 0.1
check(udc.get("value") is not None and abs(udc["value"] - udc_far) < 2.0 and abs(udc["value"] - 425) < 25,
      f"probe: udc_V {udc.get('value')} V, far side {udc_far:.1f} V, twin source 425 V")
gate = rows.get(("vfc_meter", "f0_Hz"), {})
f0_far = far.holding(13, SHIFT["vfc_meter"] + 16, 2)
check(gate.get("raw") == f0_far and gate.get("value") == f32(f0_far, little=True) and gate.get("value", 0) > 0,
      f"probe: the meter's f0_Hz words {gate.get('raw')} are the far side's {f0_far}, little word order "
      f"-> {gate.get('value')} Hz")
far.close()

code, out, err = run("point", *POINT, "--bench", vendor_tcp, timeout=90)
check(code == 0, f"point --bench on the remapped bench over TCP: {err.strip()[:300]}")
if code == 0:
    rec = json.loads(out)
    # The map changes where the words sit, never what they say: the remapped point is the same
    # measurement as on the default map, so it lies within the noise of the default map's point
    # over seeds (6 sigma), or 1e-4 relative where the noise is smaller than f32 rounding.
    tol = max(6 * sigma, 1e-4 * base)
    check(abs(rec["efficiency"] - base) <= tol and rec["fault"] is None,
          f"remapped efficiency {rec['efficiency']:.6f} vs default map {base:.6f} (|d| "
          f"{abs(rec['efficiency'] - base):.2g} <= {tol:.2g}, sigma {sigma:.2g})")
code, emu_out = emu.stop()
check(code == 0, "emulate --profiles stops on SIGTERM")

# `emulate --bench` over RTU: the config's profiles at its unit ids, probed through the pty pair.
pair = far_side.SocatPair(tmp, "probe")
units = {"synrm_drive": 31, "load_drive": 32, "vfc_meter": 33}
served = bench_config("served", far_side.tcp_link(1), profiles=remapped, units=units)
emu = far_side.Emulator(BIN, os.path.join(tmp, "emulate_bench.log"), rtu=pair.a, args=["--bench", served, *SCALED])
vendor_rtu = bench_config("vendor_rtu", far_side.rtu_link(pair.b), profiles=remapped, units=units)
code, out, err = run("bench", "check", vendor_rtu, "--probe", timeout=120)
check(code == 0 and "probe over rtu " in out and "signals read" in out,
      f"bench check --probe over RTU prints a table: {out.strip().splitlines()[-1:]} {err.strip()[:200]}")
header = [line for line in out.splitlines() if line.startswith("device")]
check(header and header[0].split() == ["device", "signal", "table", "address", "unit_id", "raw", "value"],
      f"the table's columns: {header[:1]}")
state_line = [line for line in out.splitlines() if line.split()[:2] == ["load_drive", "state"]]
check(state_line and state_line[0].split()[2:] == ["input", "700", "32", "0x000A", "disabled"],
      f"the load drive's state row: {state_line[:1]}")
code, rows, err = probe_rows(vendor_rtu)
far = far_side.ModbusTcp(emu.port)
speed = rows.get(("synrm_drive", "speed_rpm"), {})
check(speed.get("unit_id") == 31 and speed.get("address") == 500 + 16 and len(speed.get("raw", [])) == 2
      and speed.get("value") == f32(speed["raw"], little=True) and abs(speed["value"]) < 5,
      f"probe over RTU: speed_rpm at rest, little word order: {speed}")
temp = rows.get(("synrm_drive", "temp_C"), {})
temp_far = far.input(31, 500 + 31)[0] * 0.1 - 50
check(temp.get("value") is not None and abs(temp["value"] - temp_far) < 0.5,
      f"probe over RTU: temp_C {temp.get('value')} degC, far side over TCP {temp_far:.1f}")
check(far.coils(31, 500 + 0)[0] == 0 and far.holding(31, 500 + 0)[0] == 0,
      "the probe wrote nothing: enable coil and heartbeat still 0")
far.close()
code, out, err = run("point", *POINT, "--bench", vendor_rtu, timeout=90)
check(code == 0, f"point --bench on the remapped bench over RTU (emulate --bench): {err.strip()[:300]}")
if code == 0:
    rec = json.loads(out)
    tol = max(6 * sigma, 1e-4 * base)
    check(abs(rec["efficiency"] - base) <= tol and rec["fault"] is None,
          f"remapped efficiency over RTU {rec['efficiency']:.6f} vs default map {base:.6f} (|d| "
          f"{abs(rec['efficiency'] - base):.2g} <= {tol:.2g})")
emu.stop()
pair.stop()

# The default map, probed over TCP, for the record the first time a user meets it.
emu = far_side.Emulator(BIN, os.path.join(tmp, "emulate_default.log"))
cfg = bench_config("default_tcp", far_side.tcp_link(emu.port), time_scale=1)
code, rows, err = probe_rows(cfg)
far = far_side.ModbusTcp(emu.port)
st = rows.get(("load_drive", "state"), {})
check(code == 0 and st.get("label") == "disabled" and st.get("raw") == [0], f"default map: load drive disabled: {st}")
speed = rows.get(("synrm_drive", "speed_rpm"), {})
check(speed.get("raw") and speed.get("value") == f32(speed["raw"]), f"default map: big word order f32: {speed}")
check(abs(rows.get(("synrm_drive", "udc_V"), {}).get("value", 0) - far.udc_V()) < 2.0,
      "default map: udc_V as the far side reads it")
far.close()
emu.stop()
code, out, err = run("bench", "check", cfg, "--probe", timeout=60)
check(code == 1 and out.count("error: ") > 40 and "0 of " in out,
      f"probing a stopped emulator: every signal's error, exit 1: {out.strip().splitlines()[-1:]}")

shutil.rmtree(tmp, ignore_errors=True)
check.finish("all checks passed")
