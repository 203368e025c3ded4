#!/usr/bin/env python3
"""`synbench serve --bench` on `synbench emulate`, judged from the far side: every check reads the
drives' registers from the emulator over a Modbus TCP connection of its own (far_side.py), never
the daemon's status. Once with the daemon on Modbus TCP, once on Modbus RTU (a socat pty pair at
115200 baud; the emulator serves the same twin on TCP too, for the checks).

The daemon answers a command once it has acted on it, so what a command does is read from the
registers as soon as its reply arrives (the ordered stop and the spin-up excepted: they take
time by design). For each link:
 1. enable over REST: both drives' state registers read running;
 2. setpoints over REST (600 rpm, 1 N m, 50 deg): the setpoint registers hold them (and the
    status's `commanded` says what they hold), the heartbeat registers change, the shaft turns
    at 600 rpm;
 3. disable (the ordered stop): both drives read disabled;
 4. a sweep started over REST: the drives run it;
 5. E-stop while it runs: both drives read disabled within 1 s of the request, stay disabled,
    and the heartbeat registers stop changing (the heartbeats stop at once); when its reply
    arrives, the drives already read disabled;
 6. the drives' own watchdog is the second line: the load drive, enabled behind the daemon's
    back at zero torque, trips its watchdog (nothing sends heartbeats), or the daemon disables
    it again;
 7. reset: 200, both drives' latched faults cleared (state disabled, fault_code none);
 8. enable again: the E-stop zeroed the held setpoints, set again; the drives run, the shaft
    turns at the setpoint;
 9. SIGTERM: the daemon exits 0 and both drives read disabled, and stay so past the watchdog.
The E-stop's answer says per drive that the disable was acknowledged (supervisor.disable), the
status then says confirmed, and the setpoint registers read zero after it. Then `cut`: an E-stop
while the emulator's links are cut, whose answer says "repeating" for both drives, and whose
repeated disable stops them once the line is back.

The emulator's watchdog is 3 s here (--watchdog-timeout-ms 3000: a loaded CI machine can stall
the daemon for a fraction of a second); the E-stop deadline, 1 s, stays well inside it, and a
drive the watchdog stopped reads faulted, not disabled: a drive reading disabled within the
deadline was disabled by the daemon.

Then `ramp`: an E-stop on a drive that ramps down on its disable, with and without its documented
stop time in its profile (run_ramp).

usage: serve_bench_test.py path/to/synbench [tcp|rtu|cli|slow|cut|ramp ...]
Exit 77 (skipped) without socat (scripts/debian-packages.txt), 1 on any failure. Standard
library only: the Modbus master is far_side.py's, not mbpoll (a process per read is too slow to
time an E-stop).
"""
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import far_side as fs  # noqa: E402
from checks import Checks  # noqa: E402
from daemon import Daemon, PendingRequest, wait_for  # noqa: E402

BIN = sys.argv[1]
LINKS = sys.argv[2:] or ["tcp", "rtu", "cli", "slow", "cut", "ramp"]
WATCHDOG_MS = 3000
ESTOP_DEADLINE_S = 1.0    # the bound: request sent -> both drives read disabled
STAY_S = 2.0              # and they stay disabled this long
# A heartbeat already on the wire may still land: on a loaded machine a request socat holds in
# the pty (RTU) reaches the emulator after the daemon gave up on it.
HEARTBEAT_SETTLE_S = 0.6
SPEED, LOAD_NM, ANGLE = 600.0, 1.0, 50.0
# Starting processes, spinning up, ordered stops: generous, for a loaded 2-core machine.
SLOW_S = 30.0
PLAN = {"name": "estop under a sweep", "window_s": 1.0,
        "dimensions": {"speed_rpm": [SPEED], "load_Nm": [LOAD_NM], "angle_deg": [46, 50, 54, 58]}}
check = Checks(verbose=True)
failures = check.failures

if not shutil.which("socat"):
    print("skip: socat is not installed (scripts/debian-packages.txt)")
    sys.exit(77)


def note(what):
    print("     " + what)


def both(state):
    return lambda far: all(s == state for s, _ in far.states())


def running_at(far, speed, tol):
    (s1, _), (s2, _) = far.states()
    return s1 == fs.RUNNING and s2 == fs.RUNNING and abs(far.speed_rpm() - speed) <= tol


def spin_timeout(far):
    """Spinning up takes seconds on a loaded machine; no need to wait when the drives are off."""
    return SLOW_S if both(fs.RUNNING)(far) else 2.0


def sweep_state(serve, sid):
    status, body = serve.request("GET", "/api/sweeps/%s" % sid)
    return body.get("state") if status == 200 and isinstance(body, dict) else "HTTP %s" % status


def watch_estop(far, pending, deadline_s, stay_s):
    """Polls the drives' state and heartbeat registers every 2 ms or so from the moment the
    E-stop request was sent (no faster: the emulator also serves the daemon, and this is a test
    of a 1 s bound, not a benchmark): when both first read disabled, what they read after that,
    and the heartbeat values seen after the settling time; and what the first read started
    after the daemon's reply saw."""
    t_disabled = None
    relapses = []
    beats = set()
    last = at_reply = None
    while True:
        answered = pending.poll()
        states = far.states()
        now = time.monotonic() - pending.sent_at
        if answered and at_reply is None:
            at_reply = states
        last = states
        off = all(s == fs.DISABLED for s, _ in states)
        if t_disabled is None and off:
            t_disabled = now
        elif t_disabled is not None and not off and len(relapses) < 5:
            relapses.append("%.3f s: %s" % (now, fs.describe(states)))
        if now >= HEARTBEAT_SETTLE_S:
            beats.add(far.heartbeats())
        if t_disabled is None and now > deadline_s + 1.0:
            break  # it will not come; the verdict is in
        if t_disabled is not None and now > t_disabled + stay_s:
            break
        time.sleep(0.002)
    pending.wait(10)
    return t_disabled, relapses, beats, last, at_reply


def run_link(kind, tmp):
    print("--- daemon over Modbus %s" % kind.upper())
    pair = fs.SocatPair(tmp, kind) if kind == "rtu" else None
    emu = fs.Emulator(BIN, os.path.join(tmp, kind + "_emulate.log"), rtu=pair.a if pair else None,
                      args=["--watchdog-timeout-ms", str(WATCHDOG_MS), "--duration-s", "900"])
    far = fs.ModbusTcp(emu.port)
    serve = None
    try:
        # The far side itself first: plausible values decode.
        udc = far.udc_V()
        check(400 <= udc <= 450, "%s: far side reads udc_V (SynRM input 30, 0.1 V): %.1f V" % (kind, udc))
        check(far.states() == ((0, 0), (0, 0)), "%s: both drives disabled, no fault before the daemon starts: %s"
              % (kind, fs.describe(far.states())))
        link = fs.rtu_link(pair.b) if pair else fs.tcp_link(emu.port)
        cfg = fs.write_bench_config(os.path.join(tmp, kind + "_bench.json"), link)
        data_dir = os.path.join(tmp, kind + "_data")
        serve = Daemon(BIN, data_dir, ["--bench", cfg], log_path=os.path.join(tmp, kind + "_serve.log"),
                       start_timeout_s=SLOW_S)
        status, devices = serve.request("GET", "/api/devices")
        check(status == 200 and all(d.get("backend") == "modbus" for d in devices),
              "%s: the daemon's devices are Modbus devices (%s)" % (kind, devices))

        # 1. Enable.
        status, body = serve.request("POST", "/api/bench/enable", {"enabled": True})
        now = far.states()
        check(status == 200, "%s: POST /api/bench/enable -> 200 (%s %s)" % (kind, status, str(body)[:200]))
        check(all(s == fs.RUNNING for s, _ in now),
              "%s: both drives read running when the reply arrives: %s" % (kind, fs.describe(now)))

        # 2. Setpoints.
        status, body = serve.request("POST", "/api/bench/setpoints",
                                     {"speed_rpm": SPEED, "load_Nm": LOAD_NM, "angle_deg": ANGLE})
        check(status == 200, "%s: POST /api/bench/setpoints -> 200 (%s %s)" % (kind, status, str(body)[:200]))
        sp = (far.speed_setpoint_rpm(), far.angle_setpoint_deg(), far.torque_setpoint_Nm())
        check(sp[0] == SPEED and abs(sp[1] - ANGLE) < 0.006 and sp[2] == LOAD_NM,
              "%s: setpoint registers when the reply arrives: speed %.1f rpm (SynRM holding 16-17 f32), angle %.2f deg (holding 18 i16 "
              "x0.01), torque %.2f N m (load holding 16-17 f32)" % (kind, sp[0], sp[1], sp[2]))
        cmd = (body or {}).get("commanded", {}) if isinstance(body, dict) else {}
        check(cmd.get("speed_rpm") == sp[0] and abs(cmd.get("angle_deg", -1) - sp[1]) < 0.006 and cmd.get("load_Nm") == sp[2],
              "%s: the status's commanded setpoints are what the registers hold (%s)" % (kind, cmd))
        spun = wait_for(lambda: running_at(far, SPEED, 0.05 * SPEED), spin_timeout(far), 0.1)
        check(spun, "%s: the shaft turns at %.0f rpm (SynRM input 16-17 f32: %.1f rpm), %s"
              % (kind, SPEED, far.speed_rpm(), fs.describe(far.states())))
        hb0 = far.heartbeats()
        time.sleep(0.5)
        hb1 = far.heartbeats()
        check(hb0[0] != hb1[0] and hb0[1] != hb1[1],
              "%s: the daemon's heartbeats reach both drives (holding 0: %s -> %s in 0.5 s)" % (kind, hb0, hb1))

        # 3. The ordered stop.
        status, body = serve.request("POST", "/api/bench/enable", {"enabled": False})
        check(status == 200, "%s: POST /api/bench/enable false -> 200 (%s)" % (kind, status))
        ok = wait_for(lambda: both(fs.DISABLED)(far), SLOW_S, 0.05)
        check(ok, "%s: the ordered stop ends with both drives disabled: %s, %.1f rpm"
              % (kind, fs.describe(far.states()), far.speed_rpm()))

        # 4. A sweep.
        status, sweep = serve.request("POST", "/api/sweeps", PLAN)
        check(status == 201, "%s: POST /api/sweeps -> 201 (%s %s)" % (kind, status, str(sweep)[:200]))
        sid = sweep.get("id") if isinstance(sweep, dict) else None
        status, body = serve.request("POST", "/api/sweeps/%s/start" % sid)
        if status == 409 and isinstance(body, dict) and body.get("error", {}).get("code") == "tripped":
            # On a starved machine the supervisor may have tripped (a lost link is a trip): say so
            # and do what an operator would, once.
            trip = (serve.request("GET", "/api/bench/status")[1].get("supervisor") or {}).get("trip")
            note("%s: the supervisor had tripped before the sweep (%s): reset and start again" % (kind, trip))
            serve.request("POST", "/api/bench/reset")
            status, body = serve.request("POST", "/api/sweeps/%s/start" % sid)
        check(status == 202, "%s: POST /api/sweeps/%s/start -> 202 (%s %s)" % (kind, sid, status, str(body)[:200]))
        spun = wait_for(lambda: running_at(far, SPEED, 0.5 * SPEED), SLOW_S, 0.05)
        check(spun, "%s: the sweep runs the drives: %s, %.1f rpm" % (kind, fs.describe(far.states()), far.speed_rpm()))
        state = sweep_state(serve, sid)
        check(state == "running", "%s: the sweep is running when the E-stop comes (%s)" % (kind, state))

        # 5. E-stop while it runs.
        before = far.states()
        hb_before = far.heartbeats()
        pending = PendingRequest(serve.port, serve.raw_request_bytes("POST", "/api/bench/estop"))
        t_off, relapses, beats, last, at_reply = watch_estop(far, pending, ESTOP_DEADLINE_S, STAY_S)
        reply_s = pending.answered_at - pending.sent_at if pending.answered_at else None
        note("%s: before the E-stop %s; E-stop answered %s in %s" % (
            kind, fs.describe(before), pending.status, "%.1f ms" % (1e3 * reply_s) if reply_s is not None else "-"))
        check(pending.status == 200, "%s: POST /api/bench/estop -> 200 (%s %s)" % (kind, pending.status, (pending.body or b"")[:200]))
        check(t_off is not None and t_off <= ESTOP_DEADLINE_S,
              "%s: both drives read disabled within %.1f s of the E-stop request (%s; now %s)"
              % (kind, ESTOP_DEADLINE_S, "%.1f ms" % (1e3 * t_off) if t_off is not None else "never", fs.describe(last)))
        check(at_reply is not None and all(s == fs.DISABLED for s, _ in at_reply),
              "%s: when the E-stop's reply arrives, both drives already read disabled (it replies once it "
              "has acted): %s" % (kind, fs.describe(at_reply) if at_reply else "no reply"))
        check(t_off is not None and not relapses,
              "%s: and stay disabled for %.0f s (%s)" % (kind, STAY_S, "; ".join(relapses) or "no relapse"))
        check(len(beats) == 1,
              "%s: the heartbeat registers stop changing from %.1f s after the E-stop (before %s; after: %s)"
              % (kind, HEARTBEAT_SETTLE_S, hb_before, sorted(beats)[:6]))
        answer = estop_disable(pending)
        check(answer is not None and all(answer.get(d, {}).get("first_acknowledged") and
                                         answer[d].get("state") in ("acknowledged", "confirmed") for d in ("synrm", "load")),
              "%s: the E-stop's answer says both drives acknowledged the disable (supervisor.disable: %s)" % (kind, answer))
        status, st = serve.request("GET", "/api/bench/status")
        sup = st.get("supervisor", {}) if isinstance(st, dict) else {}
        check(sup.get("phase") == "estopped" and sup.get("tripped"),
              "%s: the daemon says estopped (%s)" % (kind, sup))
        check((sup.get("disable") or {}).get("confirmed") is True,
              "%s: and its status says both disables confirmed by the read-back (%s)" % (kind, sup.get("disable")))
        zeroed = wait_for(lambda: far.speed_setpoint_rpm() == 0.0 and far.torque_setpoint_Nm() == 0.0, 2.0, 0.05)
        check(zeroed, "%s: after the disable the setpoint registers read zero: speed %.1f rpm (SynRM holding 16-17), "
                      "torque %.2f N m (load holding 16-17)" % (kind, far.speed_setpoint_rpm(), far.torque_setpoint_Nm()))
        _, st = serve.request("GET", "/api/bench/status")
        cmd = st.get("commanded", {}) if isinstance(st, dict) else {}
        check(cmd.get("speed_rpm") == 0.0 and cmd.get("load_Nm") == 0.0,
              "%s: and the status's commanded setpoints say so (%s)" % (kind, cmd))
        ended = wait_for(lambda: sweep_state(serve, sid) != "running", 10, 0.2)
        check(ended, "%s: the sweep stops running (%s)" % (kind, sweep_state(serve, sid)))

        # 6. The drives' own watchdog, the second line: the load drive is enabled behind the
        # daemon's back, at zero torque so it cannot turn the shaft. With no heartbeats flowing it
        # must trip its watchdog (fault 6) within the timeout (bench time = wall time here).
        if t_off is not None:
            far.write_words(fs.LOAD, fs.TORQUE_SETPOINT, fs.f32_words(0.0))
            far.write_coil(fs.LOAD, fs.ENABLE_COIL, True)
            t0 = time.monotonic()
            check(far.state(fs.LOAD)[0] == fs.RUNNING, "%s: the far side enables the load drive at 0 N m" % kind)
            # (A watchdog trip passes through stopping, the torque ramped to zero, to faulted.)
            wait_for(lambda: far.state(fs.LOAD)[0] in (fs.DISABLED, fs.FAULTED), WATCHDOG_MS / 1000 + 3, 0.01)
            dt = time.monotonic() - t0
            end = far.states()
            tripped = end[1] == (fs.FAULTED, fs.WATCHDOG)
            redisabled = end[1][0] == fs.DISABLED
            check(tripped or redisabled,
                  "%s: ... and it stops after %.2f s: %s (%s)" % (kind, dt, fs.describe(end),
                                                              "its watchdog tripped: no heartbeats" if tripped else
                                                              "the daemon disabled it" if redisabled else "still running"))
            if tripped:
                check(WATCHDOG_MS / 1000 - 0.1 <= dt, "%s: not before the watchdog's %d ms (%.2f s)" % (kind, WATCHDOG_MS, dt))
            if not (tripped or redisabled):
                try:
                    far.write_coil(fs.LOAD, fs.ENABLE_COIL, False)
                except fs.ModbusError as e:
                    note("%s: disabling the load drive again: %s" % (kind, e))
        else:
            note("%s: the second line is not tried: the drives never stopped" % kind)
        faults_before = far.states()

        # 7. Reset.
        status, body = serve.request("POST", "/api/bench/reset")
        check(status == 200, "%s: POST /api/bench/reset -> 200 (%s %s)" % (kind, status, str(body)[:200]))
        now = far.states()
        check(now == ((fs.DISABLED, 0), (fs.DISABLED, 0)),
              "%s: reset has cleared the drives' latched faults when its reply arrives (before: %s; after: %s)"
              % (kind, fs.describe(faults_before), fs.describe(now)))

        # 8. Enable again (from disabled: a drive that never stopped proves nothing here). The
        # E-stop zeroed the held speed and load setpoints: they are set again first.
        check(isinstance(body, dict) and body["setpoints"]["speed_rpm"] == 0 and body["setpoints"]["load_Nm"] == 0,
              "%s: after the E-stop and the reset the held setpoints are 0 (%s)" % (kind, isinstance(body, dict) and body.get("setpoints")))
        status, body = serve.request("POST", "/api/bench/setpoints", {"speed_rpm": SPEED})
        check(status == 200, "%s: setpoints again after the reset -> 200 (%s)" % (kind, status))
        was_off = all(s == fs.DISABLED for s, _ in far.states())
        status, body = serve.request("POST", "/api/bench/enable", {"enabled": True})
        now = far.states()
        check(status == 200, "%s: POST /api/bench/enable after the reset -> 200 (%s %s)" % (kind, status, str(body)[:200]))
        check(was_off and all(s == fs.RUNNING for s, _ in now),
              "%s: both drives, disabled before, read running when the reply arrives: %s" % (kind, fs.describe(now)))
        spun = wait_for(lambda: running_at(far, SPEED, 0.05 * SPEED), spin_timeout(far), 0.1)
        check(was_off and spun and far.speed_setpoint_rpm() == SPEED,
              "%s: the drives, disabled before, run again at %.0f rpm: %s, %.1f rpm, setpoint register %.1f%s"
              % (kind, SPEED, fs.describe(far.states()), far.speed_rpm(), far.speed_setpoint_rpm(),
                 "" if was_off else " (they were never disabled)"))

        # 9. SIGTERM.
        rc, _ = serve.stop()
        after = far.states()
        check(rc == 0, "%s: SIGTERM -> the daemon exits 0 (%s)" % (kind, rc))
        check(all(s == fs.DISABLED for s, _ in after), "%s: both drives read disabled when it has exited: %s"
              % (kind, fs.describe(after)))
        time.sleep(WATCHDOG_MS / 1000 + 0.5)
        later = far.states()
        check(later == ((0, 0), (0, 0)), "%s: and %.1f s later, past the watchdog: %s"
              % (kind, WATCHDOG_MS / 1000 + 0.5, fs.describe(later)))
    finally:
        if serve is not None and serve.proc.poll() is None:
            serve.kill()
        far.close()
        rc, out = emu.stop()
        note("%s: emulator: %s" % (kind, " | ".join(out[-2:])))
        if pair:
            pair.stop()
    if failures:
        for name in ("serve", "emulate"):
            log = os.path.join(tmp, "%s_%s.log" % (kind, name))
            if os.path.exists(log):
                tail = open(log).read().strip().splitlines()[-8:]
                note("%s: last lines of %s's log:" % (kind, name))
                for line in tail:
                    note("  " + ("(a line with the token)" if "sbt_" in line else line))


def estop_disable(pending):
    """supervisor.disable of an E-stop's answer, or None."""
    try:
        return json.loads(pending.body)["supervisor"]["disable"]
    except (TypeError, ValueError, KeyError):
        return None


def run_cut(tmp):
    """An E-stop while the RTU line is dead (the emulator's link cut: nothing answers, on any link):
    the answer comes at once and says, per drive, that the disable was not acknowledged and is
    being repeated; the repeat gets through once the line is back, both drives read disabled
    (not faulted: the watchdog is 30 s here, so only the daemon's disable can have stopped them),
    the status says confirmed, and the setpoint registers read zero."""
    print("--- an E-stop on a dead RTU line")
    # Longer than the tick in flight when the E-stop comes (every request of it times out) and
    # the E-stop's two disables.
    cut_s = 3.0
    pair = fs.SocatPair(tmp, "cut")
    emu = fs.Emulator(BIN, os.path.join(tmp, "cut_emulate.log"), rtu=pair.a,
                      args=["--watchdog-timeout-ms", "30000", "--duration-s", "900", "--fault-cut-s", str(cut_s)])
    far = fs.ModbusTcp(emu.port, timeout=5.0)
    serve = None
    try:
        cfg = fs.write_bench_config(os.path.join(tmp, "cut_bench.json"), fs.rtu_link(pair.b))
        serve = Daemon(BIN, os.path.join(tmp, "cut_data"), ["--bench", cfg], log_path=os.path.join(tmp, "cut_serve.log"),
                       start_timeout_s=SLOW_S)
        status, _ = serve.request("POST", "/api/bench/setpoints", {"speed_rpm": SPEED, "load_Nm": LOAD_NM, "angle_deg": ANGLE})
        check(status == 200, "cut: setpoints -> 200 (%s)" % status)
        status, _ = serve.request("POST", "/api/bench/enable", {"enabled": True})
        check(status == 200, "cut: enable -> 200 (%s)" % status)
        spun = wait_for(lambda: running_at(far, SPEED, 0.1 * SPEED), SLOW_S, 0.1)
        check(spun, "cut: the drives run at %.0f rpm: %s" % (SPEED, fs.describe(far.states())))
        emu.proc.send_signal(signal.SIGUSR1)
        line = emu.lines.get(5)
        check(line is not None and line.startswith("link cut"), "cut: the emulator cuts its links (%s)" % line)
        pending = PendingRequest(serve.port, serve.raw_request_bytes("POST", "/api/bench/estop"))
        pending.wait(10)
        reply_s = pending.answered_at - pending.sent_at if pending.answered_at else None
        answer = estop_disable(pending)
        check(pending.status == 200 and reply_s is not None and reply_s < cut_s,
              "cut: the E-stop is answered 200 before the line is back (%s in %s)"
              % (pending.status, "%.2f s" % reply_s if reply_s is not None else "-"))
        check(answer is not None and all(answer.get(d, {}).get("state") == "repeating" and
                                         answer[d].get("first_acknowledged") is False and answer[d].get("error")
                                         for d in ("synrm", "load")) and answer.get("confirmed") is False,
              "cut: its answer says neither disable was acknowledged and both are being repeated (%s)" % answer)
        time.sleep(max(0.0, cut_s + 0.1 - (time.monotonic() - pending.sent_at)))
        far.close()
        far = fs.ModbusTcp(emu.port, timeout=5.0)  # the cut closed the far side's connection too
        off = wait_for(lambda: far.states() == ((fs.DISABLED, 0), (fs.DISABLED, 0)), 2.0, 0.01)
        t_off = time.monotonic() - pending.sent_at
        check(off, "cut: once the line is back the repeated disable stops both drives (%.2f s after the E-stop): %s"
              % (t_off, fs.describe(far.states())))
        confirmed = wait_for(lambda: (serve.request("GET", "/api/bench/status")[1]["supervisor"]["disable"] or {}).get("confirmed"),
                             2.0, 0.05)
        d = serve.request("GET", "/api/bench/status")[1]["supervisor"]["disable"]
        check(confirmed and d["synrm"]["attempts"] > 1 and d["load"]["attempts"] > 1 and not d["synrm"]["first_acknowledged"],
              "cut: the status says confirmed, after %s and %s requests" % (d["synrm"]["attempts"], d["load"]["attempts"]))
        zeroed = wait_for(lambda: far.speed_setpoint_rpm() == 0.0 and far.torque_setpoint_Nm() == 0.0, 2.0, 0.05)
        check(zeroed, "cut: and the setpoint registers read zero: speed %.1f rpm, torque %.2f N m"
              % (far.speed_setpoint_rpm(), far.torque_setpoint_Nm()))
    finally:
        if serve is not None:
            serve.stop()
        far.close()
        emu.stop()
        pair.stop()


def run_ramp(tmp):
    """A SynRM drive that ramps down on its disable (an SS1-style stop: the twin's
    firmware.disable_action "ramp", 1000 rpm/s, reading stopping meanwhile) stopped by an E-stop at
    1000 rpm. With the drive's documented stop time in its profile (stop_time_ms 1500) the daemon
    leaves it to its ramp: one disable request, no alarm, and the far side reads the state
    stopping and the speed falling along the ramp, then disabled, not faulted, about 1 s later.
    Without it (the default profile) the same stop raises the alarm after 0.3 s, and the disable
    is repeated at most every 0.1 s, not every tick (about 170 requests in 1.4 s before)."""
    print("--- an E-stop on a drive that ramps down on its disable")
    twin_cfg = os.path.join(tmp, "ramp_twin.json")
    with open(twin_cfg, "w") as f:
        json.dump({"firmware": {"disable_action": "ramp"}}, f)
    profiles = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "drivers", "profiles")
    profile = json.load(open(os.path.join(profiles, "synrm_drive.json")))
    profile["stop_time_ms"] = 1500
    with open(os.path.join(tmp, "ramp_synrm.json"), "w") as f:
        json.dump(profile, f)
    emu = fs.Emulator(BIN, os.path.join(tmp, "ramp_emulate.log"),
                      args=["--config", twin_cfg, "--watchdog-timeout-ms", str(WATCHDOG_MS), "--duration-s", "900"])
    far = fs.ModbusTcp(emu.port)
    try:
        for documented in (True, False):
            label = "ramp (stop_time_ms 1500)" if documented else "ramp (no stop time)"
            cfg = fs.write_bench_config(os.path.join(tmp, "ramp_bench.json"), fs.tcp_link(emu.port))
            if documented:
                bench = json.load(open(cfg))
                bench["devices"]["synrm_drive"]["profile"] = os.path.join(tmp, "ramp_synrm.json")
                json.dump(bench, open(cfg, "w"))
            serve = Daemon(BIN, os.path.join(tmp, "ramp_data_%d" % documented), ["--bench", cfg],
                           log_path=os.path.join(tmp, "ramp_serve_%d.log" % documented), start_timeout_s=SLOW_S)
            try:
                # The first round's drives tripped their watchdog after the daemon stopped: reset.
                wait_for(lambda: serve.request("POST", "/api/bench/reset")[0] == 200
                         and far.states() == ((fs.DISABLED, 0), (fs.DISABLED, 0)), 10.0, 0.2)
                serve.request("POST", "/api/bench/setpoints", {"speed_rpm": 1000, "load_Nm": 1.0, "angle_deg": ANGLE})
                status, _ = serve.request("POST", "/api/bench/enable", {"enabled": True})
                spun = wait_for(lambda: running_at(far, 1000, 50), SLOW_S, 0.1)
                check(status == 200 and spun, "%s: the drives run at 1000 rpm: %s" % (label, fs.describe(far.states())))
                t0 = time.monotonic()
                status, _ = serve.request("POST", "/api/bench/estop")
                samples = []  # (s after the E-stop, SynRM state, fault, speed) from the far side
                while time.monotonic() - t0 < 2.0:
                    (state, fault), _ = far.states()
                    samples.append((time.monotonic() - t0, state, fault, far.speed_rpm()))
                    time.sleep(0.02)
                st = serve.request("GET", "/api/bench/status")[1]["supervisor"]
                d, alarm = st["disable"], st["alarm"]
                stopping = [s for s in samples if s[1] == fs.STOPPING]
                at_half = min(samples, key=lambda s: abs(s[0] - 0.5))
                off = next((s for s in samples if s[1] == fs.DISABLED), None)
                check(status == 200 and stopping, "%s: the far side reads the SynRM stopping after the E-stop (%d samples)"
                      % (label, len(stopping)))
                check(300 < at_half[3] < 700, "%s: its speed follows the ramp: %.0f rpm at %.2f s" % (label, at_half[3], at_half[0]))
                check(off is not None and 0.7 < off[0] < 1.5 and off[2] == 0,
                      "%s: then it reads disabled, fault none: %s" % (label, off))
                if documented:
                    check(alarm is None, "%s: no alarm (%s)" % (label, alarm))
                    check(d["synrm"]["attempts"] == 1 and d["synrm"]["state"] == "confirmed" and d["confirmed"],
                          "%s: one disable request, confirmed (%s)" % (label, d["synrm"]))
                else:
                    check(alarm is not None and "SynRM drive still reports stopping" in alarm["detail"],
                          "%s: the alarm names the drive (%s)" % (label, alarm))
                    check(2 <= d["synrm"]["attempts"] <= 16,
                          "%s: the disable repeated at a bounded rate: %d requests" % (label, d["synrm"]["attempts"]))
            finally:
                serve.stop()
    finally:
        far.close()
        emu.stop()


def run(*args, timeout=180):
    p = subprocess.run([BIN, *args], capture_output=True, text=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def run_cli(tmp):
    """The command line on the same drives, without the daemon: `bench status|reset`, `sweep
    --bench` and `point --bench` under the supervisor, each judged from the far side."""
    print("--- the command line over Modbus TCP")
    emu = fs.Emulator(BIN, os.path.join(tmp, "cli_emulate.log"),
                      args=["--watchdog-timeout-ms", str(WATCHDOG_MS), "--duration-s", "900"])
    far = fs.ModbusTcp(emu.port)
    try:
        cfg = fs.write_bench_config(os.path.join(tmp, "cli_bench.json"), fs.tcp_link(emu.port))
        code, out, err = run("bench", "status", "--bench", cfg, "--json")
        doc = json.loads(out) if code == 0 else {}
        check(code == 0 and doc.get("synrm", {}).get("state") == "disabled" and doc.get("load", {}).get("state") == "disabled",
              "cli: bench status reads both drives disabled (%s %s)" % (code, out.strip() or err.strip()))

        # A drive running behind everybody's back: reset is refused, and nothing is cleared.
        far.write_coil(2, 0, True)
        time.sleep(0.2)
        code, out, err = run("bench", "reset", "--bench", cfg)
        check(code == 1 and "running" in err, "cli: bench reset refused while a drive runs (%s: %s)" % (code, err.strip()))
        # Its watchdog trips (nobody sends heartbeats): faulted, then reset clears it.
        deadline = time.time() + WATCHDOG_MS / 1000 + SLOW_S
        while time.time() < deadline and far.state(2)[0] != fs.FAULTED:
            time.sleep(0.1)
        check(far.state(2) == (fs.FAULTED, 6), "cli: the load drive's watchdog trips: %s" % fs.describe(far.states()))
        code, out, err = run("bench", "reset", "--bench", cfg)
        check(code == 0 and far.states() == ((0, 0), (0, 0)),
              "cli: bench reset clears the latched watchdog fault, read over Modbus: %s (%s %s)"
              % (fs.describe(far.states()), code, err.strip()))

        # A short sweep on the drives, into SQLite; they end disabled.
        plan = os.path.join(tmp, "cli_plan.json")
        with open(plan, "w") as f:
            json.dump({"name": "cli sweep", "dimensions": {"speed_rpm": [500], "load_Nm": [0.5], "angle_deg": [50, 54],
                                                           "configurations": [{"estimator": "encoder", "pwm": "capwm"}]},
                       "window_s": 0.5}, f)
        db = os.path.join(tmp, "cli.db")
        points = os.path.join(tmp, "cli_points.json")
        code, out, err = run("sweep", plan, "--bench", cfg, "--db", db, "--quiet", "--export-json", points, timeout=300)
        stored = json.load(open(points)) if os.path.exists(points) else []
        check(code == 0 and len(stored) == 2 and all(abs(p["speed_meas_rpm"] - 500) < 25 for p in stored),
              "cli: sweep --bench measures 2 points at 500 rpm on the drives (%s, %d points; %s)"
              % (code, len(stored), err.strip()[-200:]))
        check(far.states() == ((0, 0), (0, 0)), "cli: after the sweep both drives read disabled: %s" % fs.describe(far.states()))

        # The bench config's limits bind `point`: 0.3 A trips overcurrent, and the drives are stopped.
        strict = json.load(open(cfg))
        strict["limits"] = {"max_current_A": 0.3}
        strict_cfg = os.path.join(tmp, "cli_strict.json")
        json.dump(strict, open(strict_cfg, "w"))
        code, out, err = run("point", "--speed-rpm", "500", "--load-Nm", "1", "--angle-deg", "50", "--bench", strict_cfg)
        check(code == 3 and "overcurrent" in err, "cli: point --bench trips on the config's 0.3 A limit (%s: %s)"
              % (code, err.strip()[-200:]))
        states = far.states()
        check(all(s != fs.RUNNING for s, _ in states),
              "cli: after the trip neither drive runs, read over Modbus: %s" % fs.describe(states))
    finally:
        far.close()
        emu.stop()


def run_slow(tmp):
    """Drives that answer every request 150 ms late (inside the link's 200 ms timeout): the bench
    thread's ticks take a second, but nothing that reads the status waits for them, and a command
    still gets its answer once the slow drives have acted."""
    print("--- a slow device: every reply 150 ms late")
    emu = fs.Emulator(BIN, os.path.join(tmp, "slow_emulate.log"),
                      args=["--watchdog-timeout-ms", str(WATCHDOG_MS), "--duration-s", "900",
                            "--fault-delay-pct", "100", "--fault-delay-ms", "150"])
    serve = None
    try:
        cfg = fs.write_bench_config(os.path.join(tmp, "slow_bench.json"), fs.tcp_link(emu.port))
        serve = Daemon(BIN, os.path.join(tmp, "slow_data"), ["--bench", cfg],
                       log_path=os.path.join(tmp, "slow_serve.log"), start_timeout_s=SLOW_S)
        time.sleep(1.0)  # the bench thread is now in its slow ticks
        worst = {}
        for path in ("/api/health", "/api/bench/status", "/metrics"):
            times = []
            for _ in range(20):
                t0 = time.perf_counter()
                status, _ = serve.request("GET", path)
                times.append(time.perf_counter() - t0)
                if status != 200:
                    check(False, "slow: GET %s -> %s" % (path, status))
            worst[path] = max(times) * 1000
        check(all(ms < 100 for ms in worst.values()),
              "slow: reads never wait for the drives (worst of 20 each: %s)"
              % ", ".join("%s %.1f ms" % (p, ms) for p, ms in worst.items()))
        t0 = time.perf_counter()
        status, body = serve.request("POST", "/api/bench/setpoints", {"speed_rpm": 200})
        took = time.perf_counter() - t0
        check(status == 200 and isinstance(body, dict) and body.get("setpoints", {}).get("speed_rpm") == 200,
              "slow: a command is still answered once acted on (%s in %.2f s)" % (status, took))
    finally:
        if serve:
            serve.stop()
        emu.stop()


def main():
    tmp = tempfile.mkdtemp(prefix="synbench_serve_bench_")
    try:
        for kind in LINKS:
            try:
                {"cli": run_cli, "slow": run_slow, "cut": run_cut, "ramp": run_ramp}.get(kind, lambda t: run_link(kind, t))(tmp)
            except (RuntimeError, OSError, fs.ModbusError) as e:
                check(False, "%s: %s" % (kind, e))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    check.finish("all checks passed")


if __name__ == "__main__":
    main()
