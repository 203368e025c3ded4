#!/usr/bin/env python3
"""E-stop latency of `synbench serve --bench` on `synbench emulate`, measured from the far side,
and the daemon's GET /api/bench/status throughput against nginx serving the same bytes.

E-stop latency: from sending POST /api/bench/estop to both drives' state registers reading
disabled (input register 0 of units 1 and 2), polled over a Modbus TCP connection of the
benchmark's own to the emulator, as fast as it answers (tests/server/far_side.py). Each trial:
reset (after the previous trial's E-stop), enable (or start a sweep), wait until the shaft turns at the setpoint, a random pause of
0..50 ms (so trials sample every phase of the daemon's 10 ms bench tick), E-stop. p50 and p99 per
link (the daemon on Modbus TCP, or on RTU at 115200 baud through a socat pty pair while the
benchmark reads over the emulator's TCP link) and condition:
  idle    the drives enabled by hand, nothing else happening;
  sweep   a sweep running (the E-stop pre-empts the point in flight);
  polled  the drives enabled by hand while another client (wrk, one connection) polls
          GET /api/bench/status in a loop.
Targets (issue "Real drives under the daemon"): p99 <= 50 ms over TCP, <= 100 ms over RTU.
p99 is the nearest rank: with 50 trials, the largest.

Throughput: wrk on GET /api/bench/status (a viewer token) against the daemon of the TCP link
after its trials (drives disabled), and against nginx (Debian's; one worker, started here on a free loopback port
with a config written to a temp dir, as this user, not as a daemon) serving one status body the
daemon returned, saved to a file; printed side by side with their ratio.

usage: estop_latency_bench.py path/to/synbench [--trials 50] [--links tcp,rtu]
         [--conditions idle,sweep,polled] [--connections 50] [--threads 2] [--seconds 10] [--smoke]
         [--before path/to/other/synbench]
  --before: also measure the status throughput of another build's daemon (its own emulator), in
  the same run: e.g. the build before the status snapshot.
  --smoke: 3 trials per link and condition, wrk 1 s with 4 connections; checks that every trial
  ends with both drives disabled, that every E-stop's answer says per drive what became of its
  disable (supervisor.disable), and that both servers answer (no latency target is asserted). A
  trial whose drives still run prints the daemon's account of its disable beside the registers.
Exit 77 without wrk, nginx or socat; 1 when a trial or a server failed (the figures are then not
a measurement of the daemon's E-stop). A condition gives up after 3 trials in a row fail.
"""
import json
import math
import os
import pwd
import random
import re
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "server"))
import far_side as fs  # noqa: E402
from daemon import Daemon, PendingRequest, wait_for  # noqa: E402
from script_args import flag, option  # noqa: E402

SPEED, LOAD_NM, ANGLE = 600.0, 0.5, 50.0
WATCHDOG_MS = 3000     # the emulator's: a loaded machine may stall the daemon a fraction of a second
GIVE_UP_S = 2.0        # a trial whose drives are not both disabled by then has failed
SLOW_S = 30.0          # starting processes, spinning up
TARGET_MS = {"tcp": 50.0, "rtu": 100.0}
LOCAL = urllib.request.build_opener(urllib.request.ProxyHandler({}))  # loopback: never through a proxy
PLAN = {"name": "estop latency", "window_s": 1.0,
        "dimensions": {"speed_rpm": [SPEED], "load_Nm": [LOAD_NM], "angle_deg": [46, 50, 54, 58]}}


class TrialError(Exception):
    pass


def percentile(sorted_values, p):
    """Nearest rank."""
    return sorted_values[max(0, math.ceil(p / 100 * len(sorted_values)) - 1)]


class Bench:
    """The emulator (TCP, and RTU when asked), the daemon on it, and a far-side Modbus connection."""

    def __init__(self, binary, kind, tmp):
        self.kind = kind
        self.pair = fs.SocatPair(tmp, kind) if kind == "rtu" else None
        self.emu = fs.Emulator(binary, os.path.join(tmp, kind + "_emulate.log"), rtu=self.pair.a if self.pair else None,
                               args=["--watchdog-timeout-ms", str(WATCHDOG_MS)])
        self.far = fs.ModbusTcp(self.emu.port)
        link = fs.rtu_link(self.pair.b) if self.pair else fs.tcp_link(self.emu.port)
        cfg = fs.write_bench_config(os.path.join(tmp, kind + "_bench.json"), link)
        self.serve = Daemon(binary, os.path.join(tmp, kind + "_data"), ["--bench", cfg],
                            log_path=os.path.join(tmp, kind + "_serve.log"), start_timeout_s=SLOW_S)
        self.viewer = self.serve.token("viewer")
        self.latched = False  # an E-stop was sent since the last successful reset

    def close(self):
        rc, _ = self.serve.stop()
        self.far.close()
        self.emu.stop()
        if self.pair:
            self.pair.stop()
        return rc

    def running(self):
        (s1, _), (s2, _) = self.far.states()
        return s1 == fs.RUNNING and s2 == fs.RUNNING and self.far.speed_rpm() >= 0.9 * SPEED

    def trial(self, condition):
        """One E-stop: (latency s, reply s)."""
        if self.latched:
            # Refused while the daemon has not yet read both drives back stopped (a slow line):
            # an operator tries again a moment later.
            for _ in range(20):
                status, body = self.serve.request("POST", "/api/bench/reset")
                if status == 200 or not (isinstance(body, dict) and body.get("error", {}).get("code") == "drive_running"):
                    break
                time.sleep(0.1)
            if status != 200:
                raise TrialError("reset -> %s %s" % (status, str(body)[:160]))
            self.latched = False
        if not wait_for(lambda: all(s == fs.DISABLED and f == 0 for s, f in self.far.states()), 2.0, 0.005):
            raise TrialError("drives not disabled and clear before the trial: %s" % fs.describe(self.far.states()))
        sid = None
        if condition == "sweep":
            status, body = self.serve.request("POST", "/api/sweeps", PLAN)
            if status != 201:
                raise TrialError("POST /api/sweeps -> %s %s" % (status, str(body)[:160]))
            sid = body["id"]
            status, body = self.serve.request("POST", "/api/sweeps/%d/start" % sid)
            if status != 202:
                raise TrialError("sweep start -> %s %s" % (status, str(body)[:160]))
        else:
            # An E-stop zeroes the held speed and load: an operator sets them again before Enable.
            status, body = self.serve.request("POST", "/api/bench/setpoints",
                                              {"speed_rpm": SPEED, "load_Nm": LOAD_NM, "angle_deg": ANGLE})
            if status != 200:
                raise TrialError("setpoints -> %s %s" % (status, str(body)[:160]))
            status, body = self.serve.request("POST", "/api/bench/enable", {"enabled": True})
            if status != 200:
                raise TrialError("enable -> %s %s" % (status, str(body)[:160]))
        if not wait_for(self.running, SLOW_S, 0.02):
            raise TrialError("not at speed: %s, %.0f rpm" % (fs.describe(self.far.states()), self.far.speed_rpm()))
        time.sleep(random.uniform(0, 0.05))
        pending = PendingRequest(self.serve.port, self.serve.raw_request_bytes("POST", "/api/bench/estop"))
        self.latched = True
        latency = None
        while True:
            states = self.far.states()
            now = time.monotonic()
            pending.poll()
            if all(s == fs.DISABLED for s, _ in states):
                latency = now - pending.sent_at
                break
            if now - pending.sent_at > GIVE_UP_S:
                break
        pending.wait(10)
        if latency is None:
            # Whose fault: the daemon's own account (its answer, then its read-back) against the
            # registers. A disable it says was acknowledged and confirmed while the far side still
            # reads running points at the emulator, not the bench.
            status, body = self.serve.request("GET", "/api/bench/status")
            now = (body.get("supervisor") or {}).get("disable") if status == 200 and isinstance(body, dict) else None
            raise TrialError("drives not disabled %.0f s after the E-stop: %s (E-stop answered %s; its disable: %s; "
                             "the daemon's status now: %s)" % (GIVE_UP_S, fs.describe(states), pending.status,
                                                               describe_disable(answered_disable(pending)),
                                                               describe_disable(now)))
        if pending.status != 200:
            raise TrialError("E-stop -> %s %s" % (pending.status, pending.body[:160] if pending.body else ""))
        if answered_disable(pending) is None:
            raise TrialError("the E-stop's answer has no supervisor.disable: %s" % (pending.body or b"")[:160])
        if sid is not None and not wait_for(lambda: self.sweep_state(sid) != "running", 10, 0.05):
            raise TrialError("sweep %d still running after the E-stop" % sid)
        return latency, pending.answered_at - pending.sent_at

    def sweep_state(self, sid):
        status, body = self.serve.request("GET", "/api/sweeps/%d" % sid)
        return body.get("state") if status == 200 and isinstance(body, dict) else None


def answered_disable(pending):
    """supervisor.disable of the E-stop's answer (what each drive made of its disable), or None."""
    try:
        return json.loads(pending.body)["supervisor"]["disable"]
    except (TypeError, ValueError, KeyError):
        return None


def describe_disable(d):
    if not d:
        return "none"
    return ", ".join("%s %s after %s request(s)%s" % (k, d[k]["state"], d[k]["attempts"],
                                                     " (%s)" % d[k]["error"] if d[k].get("error") else "")
                     for k in ("synrm", "load"))


def start_status_poller(bench):
    """Another client: wrk, one connection, one thread, GET /api/bench/status in a loop."""
    return subprocess.Popen(["wrk", "-t1", "-c1", "-d3600s", "-H", "Authorization: Bearer " + bench.viewer,
                             "http://%s/api/bench/status" % bench.serve.host],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def stop_status_poller(p):
    p.send_signal(signal.SIGINT)  # wrk prints its summary on SIGINT
    try:
        out, _ = p.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        p.kill()
        out, _ = p.communicate()
    m = re.search(r"Requests/sec:\s+([\d.]+)", out)
    return float(m.group(1)) if m else None


def run_wrk(url, token, connections, threads, seconds):
    cmd = ["wrk", "-t%d" % threads, "-c%d" % connections, "-d%ds" % seconds, "--latency",
           "-H", "Authorization: Bearer " + token, url]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    rps = float(re.search(r"Requests/sec:\s+([\d.]+)", out).group(1))
    pct = dict(re.findall(r"^\s+(50|90|99)%\s+(\S+)", out, re.M))
    non2xx = re.search(r"Non-2xx or 3xx responses:\s+(\d+)", out)
    errors = re.search(r"Socket errors:.*", out)
    return {"rps": rps, "pct": pct, "non2xx": int(non2xx.group(1)) if non2xx else 0,
            "errors": errors.group(0) if errors else "", "out": out}


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


class Nginx:
    """Debian's nginx in the foreground, as this user, one worker, on a loopback port: serves
    `body` at /api/bench/status as application/json."""

    def __init__(self, tmp, body):
        self.dir = os.path.join(tmp, "nginx")
        www = os.path.join(self.dir, "www", "api", "bench")
        os.makedirs(www)
        with open(os.path.join(www, "status"), "wb") as f:
            f.write(body)
        self.port = free_port()
        # A master started as root would hand its worker to "nobody", who cannot read a 0700
        # temp dir: the worker runs as whoever runs this.
        user = "user %s;\n" % pwd.getpwuid(os.geteuid()).pw_name if os.geteuid() == 0 else ""
        d = self.dir
        conf = os.path.join(d, "nginx.conf")
        with open(conf, "w") as f:
            f.write(f"""{user}worker_processes 1;
daemon off;
pid {d}/nginx.pid;
error_log {d}/error.log warn;
events {{ worker_connections 1024; }}
http {{
  access_log off;
  client_body_temp_path {d}/client_body;
  proxy_temp_path {d}/proxy;
  fastcgi_temp_path {d}/fastcgi;
  uwsgi_temp_path {d}/uwsgi;
  scgi_temp_path {d}/scgi;
  keepalive_requests 1000000;
  server {{
    listen 127.0.0.1:{self.port};
    root {d}/www;
    location = /api/bench/status {{
      default_type application/json;
      add_header Cache-Control no-store;
    }}
  }}
}}
""")
        self.proc = subprocess.Popen(["nginx", "-p", d + "/", "-c", conf], stdout=subprocess.DEVNULL,
                                     stderr=open(os.path.join(d, "stderr.log"), "w"))
        self.url = "http://127.0.0.1:%d/api/bench/status" % self.port
        ok = False
        deadline = time.time() + 10
        while time.time() < deadline and self.proc.poll() is None:
            try:
                with LOCAL.open(self.url, timeout=2) as r:
                    ok = r.status == 200 and r.read() == body
                break
            except OSError:
                time.sleep(0.05)
        if not ok:
            self.stop()
            raise RuntimeError("nginx did not serve the body: %s" % open(os.path.join(d, "error.log")).read()[-500:])
        v = subprocess.run(["nginx", "-v"], capture_output=True, text=True)
        self.version = (v.stderr or v.stdout).strip().split("/")[-1]

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGQUIT)  # graceful
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


def status_vs_nginx(bench, tmp, connections, threads, seconds, before=None):
    raw = LOCAL.open(urllib.request.Request(
        "http://%s/api/bench/status" % bench.serve.host,
        headers={"Authorization": "Bearer " + bench.viewer}), timeout=10).read()
    nginx = Nginx(tmp, raw)
    old = None
    try:
        ours = run_wrk("http://%s/api/bench/status" % bench.serve.host, bench.viewer, connections, threads, seconds)
        theirs = run_wrk(nginx.url, bench.viewer, connections, threads, seconds)
        if before:
            # Another build's daemon (e.g. the commit before the snapshot) on an emulator of its own,
            # measured in the same run, under the same load.
            old = Bench(before, "tcp_before", tmp)
            prior = run_wrk("http://%s/api/bench/status" % old.serve.host, old.viewer, connections, threads, seconds)
    finally:
        nginx.stop()
        if old:
            old.close()
    print()
    print("GET /api/bench/status under wrk: %d connections, %d threads, %d s, a %d-byte body (the daemon on the "
          "Modbus TCP bench after its trials)" % (connections, threads, seconds, len(raw)))
    print("  %-22s %10s %9s %9s %9s" % ("server", "req/s", "p50", "p90", "p99"))
    servers = [("synbench serve", ours), ("nginx %s, 1 worker" % nginx.version, theirs)]
    if before:
        servers.insert(0, ("before: " + os.path.basename(os.path.dirname(os.path.dirname(os.path.dirname(
            os.path.abspath(before))))), prior))
    for name, r in servers:
        print("  %-22s %10.0f %9s %9s %9s%s" % (name, r["rps"], r["pct"].get("50"), r["pct"].get("90"),
                                               r["pct"].get("99"), "  " + r["errors"] if r["errors"] else ""))
    print("  ratio synbench / nginx: %.2f" % (ours["rps"] / theirs["rps"] if theirs["rps"] else float("nan")))
    if before:
        print("  ratio before / nginx: %.2f; after / before: %.2f"
              % (prior["rps"] / theirs["rps"] if theirs["rps"] else float("nan"),
                 ours["rps"] / prior["rps"] if prior["rps"] else float("nan")))
    ok = True
    for name, r in (("synbench", ours), ("nginx", theirs)):
        if r["non2xx"] or r["rps"] <= 0:
            print("FAIL: %s: %d non-2xx, %.0f req/s\n%s" % (name, r["non2xx"], r["rps"], r["out"]))
            ok = False
    return ok


def main():
    for tool in ("wrk", "nginx", "socat"):
        if not shutil.which(tool):
            print("SKIP: %s is not installed (scripts/debian-packages.txt)" % tool)
            sys.exit(77)
    binary = sys.argv[1]
    smoke = flag("--smoke")
    trials = option("--trials", 3 if smoke else 50)
    links = option("--links", "tcp,rtu").split(",")
    conditions = option("--conditions", "idle,sweep,polled").split(",")
    connections = option("--connections", 4 if smoke else 50)
    threads = option("--threads", 2)
    seconds = option("--seconds", 1 if smoke else 10)
    random.seed(1)
    tmp = tempfile.mkdtemp(prefix="synbench_estop_bench_")
    rows = []
    ok = True
    try:
        for kind in links:
            bench = Bench(binary, kind, tmp)
            try:
                for condition in conditions:
                    poller = start_status_poller(bench) if condition == "polled" else None
                    latencies, replies, errors, in_a_row = [], [], [], 0
                    for i in range(trials):
                        try:
                            lat, rep = bench.trial(condition)
                            latencies.append(lat)
                            replies.append(rep)
                            in_a_row = 0
                        except (TrialError, fs.ModbusError, OSError) as e:
                            errors.append(str(e))
                            print("  %s %s trial %d: %s" % (kind, condition, i + 1, e))
                            in_a_row += 1
                            if in_a_row == 3:
                                print("  %s %s: 3 trials in a row failed, giving up" % (kind, condition))
                                break
                    poll_rps = stop_status_poller(poller) if poller else None
                    rows.append((kind, condition, trials, latencies, replies, errors, poll_rps))
                    ok = ok and not errors
                    print_row(rows[-1])
                if kind == "tcp":
                    try:
                        ok = status_vs_nginx(bench, tmp, connections, threads, seconds, option("--before", "")) and ok
                    except (RuntimeError, OSError, subprocess.CalledProcessError) as e:
                        print("FAIL: status vs nginx: %s" % e)
                        ok = False
            finally:
                rc = bench.close()
                if rc != 0:
                    print("FAIL: the %s daemon exited %s on SIGTERM" % (kind, rc))
                    ok = False
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print()
    print("E-stop latency: POST /api/bench/estop sent -> both drives read disabled over Modbus (ms); "
          "load average now %.1f %.1f %.1f" % os.getloadavg())
    print("  %-4s %-7s %6s %9s %9s %9s %9s %9s %7s  %s" % ("link", "cond.", "ok", "p50", "p99", "max", "reply p50",
                                                        "reply p99", "target", "verdict"))
    for row in rows:
        print_row(row, table=True)
    if not ok:
        print("FAIL: some trials failed; the figures above do not measure the daemon's E-stop")
    sys.exit(0 if ok else 1)


def print_row(row, table=False):
    kind, condition, trials, lat, rep, errors, poll_rps = row
    target = TARGET_MS[kind]
    if lat:
        ls, rs = sorted(lat), sorted(rep)
        p50, p99, mx = 1e3 * statistics.median(ls), 1e3 * percentile(ls, 99), 1e3 * ls[-1]
        r50, r99 = 1e3 * statistics.median(rs), 1e3 * percentile(rs, 99)
        verdict = "meets" if p99 <= target and not errors else "misses" if not errors else "incomplete"
        figures = "%9.1f %9.1f %9.1f %9.1f %9.1f" % (p50, p99, mx, r50, r99)
    else:
        verdict, figures = "no trial succeeded", "%9s %9s %9s %9s %9s" % ("-", "-", "-", "-", "-")
    extra = ", status polled at %.0f req/s" % poll_rps if poll_rps else ""
    if table:
        print("  %-4s %-7s %6s %s %7.0f  %s%s" % (kind, condition, "%d/%d" % (len(lat), trials), figures, target,
                                                verdict, extra))
    else:
        print("%s %s: %d/%d trials; ms p50 p99 max, reply p50 p99: %s%s" % (kind, condition, len(lat), trials,
                                                                         " ".join(figures.split()), extra))


if __name__ == "__main__":
    main()
