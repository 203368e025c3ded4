#!/usr/bin/env python3
"""`synbench serve` over real HTTP on loopback: health, the OpenAPI document, every route of the
table enumerated from it (mutating routes: 401 without a token, 403 with a viewer token), the
Host check, body limit, JSON errors, the twin following a speed setpoint, E-stop, the token
subcommand, and SIGTERM -> ordered stop, exit 0. Standard library only.

usage: serve_test.py path/to/synbench
"""
import http.client
import json
import os
import re
import shutil
import socket
import stat
import subprocess
import sys
import tempfile
import time

from checks import Checks
from daemon import Daemon, run_sweep, send_raw

BIN = sys.argv[1]
check = Checks(verbose=False)


def error_of(data):
    doc = json.loads(data)
    return doc["error"]["code"], doc["error"]["message"]


def main():
    tmp = tempfile.mkdtemp(prefix="synbench-serve-")
    data_dir = os.path.join(tmp, "data")
    # A small sweep in the daemon's store, for the sweep routes.
    os.makedirs(data_dir)
    r = run_sweep(BIN, {"name": "tiny", "window_s": 0.5,
                        "dimensions": {"speed_rpm": [500], "load_Nm": [1.0], "angle_deg": [48, 52]}},
                  os.path.join(data_dir, "synbench.db"), tmp)
    check(r.returncode == 0, "tiny sweep into the data dir (%s)" % r.stderr[-300:])
    d = Daemon(BIN, data_dir)
    try:
        token_file = os.path.join(data_dir, "operator.token")
        check(os.path.exists(token_file), "first start writes operator.token")
        check(stat.S_IMODE(os.stat(token_file).st_mode) == 0o600, "operator.token is 0600")
        op = open(token_file).read().strip()
        tokens_json = open(os.path.join(data_dir, "tokens.json")).read()
        check(op not in tokens_json, "tokens.json holds no token in clear")
        viewer = subprocess.run([BIN, "token", "create", "--role", "viewer", "--data-dir", data_dir],
                                capture_output=True, text=True)
        check(viewer.returncode == 0, "token create exits 0")
        viewer = viewer.stdout.strip()
        bad = subprocess.run([BIN, "token", "create", "--role", "admin", "--data-dir", data_dir], capture_output=True, text=True)
        check(bad.returncode == 2 and "--role" in bad.stderr, "token create --role admin: exit 2 naming --role")

        status, data, _ = d.http("GET", "/api/health")
        check(status == 200 and json.loads(data)["status"] == "ok", "health 200")
        check(len(json.loads(data)["instance"]) == 16, "health names the daemon's instance")

        status, data, _ = d.http("GET", "/api/openapi.json")
        check(status == 200, "openapi 200")
        doc = json.loads(data)
        check(doc["openapi"].startswith("3."), "OpenAPI 3")
        routes = [(m.upper(), p, op_["x-synbench-role"]) for p, ms in doc["paths"].items() for m, op_ in ms.items()]
        for expected in [("GET", "/api/health"), ("GET", "/api/sweeps"), ("GET", "/api/sweeps/{id}/points"), ("GET", "/api/bench/status"), ("POST", "/api/bench/estop"),
                         ("POST", "/api/bench/reset"), ("POST", "/api/bench/setpoints"), ("POST", "/api/bench/enable"),
                         ("GET", "/metrics"), ("GET", "/api/openapi.json")]:
            check(any(r[0] == expected[0] and r[1] == expected[1] for r in routes), "openapi lists %s %s" % expected)

        # Every route of the table, enumerated from the document.
        for method, path, role in routes:
            concrete = re.sub(r"\{[^}]+\}", "1", path)
            if method != "GET" and role == "viewer":
                # Validation without side effects (POST /api/sweeps/estimate): any token reads.
                s, _, _ = d.http(method, concrete, body={})
                check(s == 401, "%s %s without token -> 401 (got %d)" % (method, path, s))
                s, data, _ = d.http(method, concrete, body={}, token=viewer)
                check(s in (200, 400), "%s %s with viewer -> answered (got %d)" % (method, path, s))
                if path == "/api/bench/estop":
                    # Every signed-in role may E-stop; the trip names the viewer; an operator resets.
                    detail = json.loads(data)["supervisor"]["trip"]["detail"]
                    check(s == 200 and detail.startswith("E-stop by token-") and detail.endswith("(viewer)"),
                          "a viewer's E-stop latches, naming the viewer (%s)" % detail)
                    s, _, _ = d.http("POST", "/api/bench/reset", body={}, token=viewer)
                    check(s == 403, "a viewer cannot reset the E-stop (got %d)" % s)
                    s, _, _ = d.http("POST", "/api/bench/reset", body={}, token=op)
                    check(s == 200, "an operator resets the viewer's E-stop (got %d)" % s)
            elif method != "GET":
                check(role == "operator", "%s %s needs operator" % (method, path))
                s, data, r = d.http(method, concrete, body={})
                check(s == 401, "%s %s without token -> 401 (got %d)" % (method, path, s))
                check(error_of(data)[0] == "unauthorized", "%s %s 401 is a JSON error" % (method, path))
                check(r.getheader("WWW-Authenticate", "").startswith("Bearer"), "401 carries WWW-Authenticate")
                s, _, _ = d.http(method, concrete, body={}, token="sbt_" + "0" * 64)
                check(s == 401, "%s %s with an unknown token -> 401" % (method, path))
                s, data, _ = d.http(method, concrete, body={}, token=viewer)
                check(s == 403, "%s %s with viewer -> 403 (got %d)" % (method, path, s))
                check(error_of(data)[0] == "forbidden", "%s %s 403 is a JSON error" % (method, path))
            else:
                s, _, _ = d.http(method, concrete, token=viewer if role != "anyone" else None)
                check(s == 200, "%s %s as %s -> 200 (got %d)" % (method, path, role, s))
                if role != "anyone":
                    s, _, _ = d.http(method, concrete)
                    check(s == 401, "%s %s without token -> 401" % (method, path))

        # Sweeps from the store.
        s, data, _ = d.http("GET", "/api/sweeps", token=viewer)
        sweeps = json.loads(data)
        check(s == 200 and len(sweeps) == 1 and sweeps[0]["name"] == "tiny" and sweeps[0]["points_stored"] == 2,
              "GET /api/sweeps lists the tiny sweep")
        s, data, _ = d.http("GET", "/api/sweeps/1", token=viewer)
        check(s == 200 and json.loads(data)["state"] == "completed" and "plan" in json.loads(data), "GET /api/sweeps/1")
        s, data, _ = d.http("GET", "/api/sweeps/1/points", token=viewer)
        check(s == 200 and len(json.loads(data)) == 2 and json.loads(data)[0]["point_index"] == 0, "points as JSON")
        s, data, r = d.http("GET", "/api/sweeps/1/points?format=csv", token=viewer)
        lines = data.decode().splitlines()
        check(s == 200 and r.getheader("Content-Type").startswith("text/csv") and lines[0].startswith("point_index")
              and len(lines) == 3, "points as CSV")
        # Pages: ?offset=&limit=, the total in X-Total-Count; without them the whole (small) sweep.
        s, data, r = d.http("GET", "/api/sweeps/1/points", token=viewer)
        check(r.getheader("X-Total-Count") == "2", "points: X-Total-Count without paging")
        s, data, r = d.http("GET", "/api/sweeps/1/points?offset=1&limit=1", token=viewer)
        page = json.loads(data) if s == 200 else []
        check(s == 200 and len(page) == 1 and page[0]["point_index"] == 1 and r.getheader("X-Total-Count") == "2",
              "points ?offset=1&limit=1: the second point, total 2")
        s, data, _ = d.http("GET", "/api/sweeps/1/points?offset=5", token=viewer)
        check(s == 200 and json.loads(data) == [], "points past the end: an empty page")
        s, data, r = d.http("GET", "/api/sweeps/1/points?format=csv&limit=1", token=viewer)
        check(s == 200 and len(data.decode().splitlines()) == 2, "a CSV page: header and one row")
        for q in ("limit=0", "limit=10001", "offset=-1", "limit=x", "offset=%ff"):
            s, data, _ = d.http("GET", "/api/sweeps/1/points?" + q, token=viewer)
            check(s == 400 and error_of(data)[0] == "bad_field", "points ?%s -> 400 bad_field (got %d)" % (q, s))
        # Analysis of the stored sweep, JSON and CSV.
        s, data, _ = d.http("GET", "/api/sweeps/1/analysis", token=viewer)
        an = json.loads(data)
        check(s == 200 and an["schema"] == "synbench.analysis/1", "analysis as JSON (%s)" % data[:200])
        curves = an["curves"]["entries"]
        check(len(curves) == 1 and curves[0]["speed_rpm"] == 500 and 48 <= curves[0]["mtpa"]["angle_deg"] <= 52,
              "analysis: one curve at 500 rpm, MTPA within the two angles measured (%s)" % curves[:1])
        s, data, r = d.http("GET", "/api/sweeps/1/analysis?format=csv", token=viewer)
        lines = data.decode().splitlines()
        check(s == 200 and r.getheader("Content-Type").startswith("text/csv") and lines[0].startswith("estimator,pwm,speed_rpm")
              and len(lines) == 2 and lines[1].startswith("encoder,capwm,500,1,2,"), "analysis as CSV (%s)" % lines[:2])
        s, data, _ = d.http("GET", "/api/sweeps/1/analysis?reference=nothing", token=viewer)
        check(s == 400 and error_of(data)[1].startswith("reference"), "bad reference -> 400 naming reference")
        s, data, _ = d.http("GET", "/api/sweeps/1/analysis?reference=ekf-rs/aspwm", token=viewer)
        check(s == 200 and json.loads(data)["deltas"]["reference"]["estimator"] == "ekf-rs", "analysis with another reference")
        # Presets and estimates.
        s, data, _ = d.http("GET", "/api/presets", token=viewer)
        presets = {p["name"]: p for p in json.loads(data)}
        check(s == 200 and set(presets) == {"thesis-grid", "iec-61800-9-2"}, "presets listed")
        check(presets["thesis-grid"]["estimate"]["points"] == 5 * 7 * 19 * 8 - 2 * 3 * 7 * 19 - 3 * 7 * 19,
              "thesis grid: 5 x 7 x 19 points per configuration, EEMF variants from 500 rpm, HFI to 300 rpm (%s)"
              % presets["thesis-grid"]["estimate"]["points"])
        s, data, _ = d.http("POST", "/api/sweeps/estimate", token=viewer,
                               body={"dimensions": {"speed_rpm": [300, 600], "load_Nm": [1, 2], "angle_deg": {"from": 44, "to": 64, "step": 10}}})
        est = json.loads(data)
        check(s == 200 and est["points"] == 12 and est["duration_s"] > 12 and est["plan"]["dimensions"]["angle_deg"] == [44, 54, 64],
              "estimate of a 2 x 2 x 3 plan (%s)" % data[:200])
        s, data, _ = d.http("POST", "/api/sweeps/estimate", token=viewer, body={"dimensions": {"speed_rpm": {"from": 1, "to": 2, "step": 0}}})
        check(s == 400 and error_of(data)[0] == "bad_plan" and "/dimensions/speed_rpm" in error_of(data)[1], "bad estimate -> 400 at the pointer")
        # Who am I, estimators, devices, profiles.
        s, data, _ = d.http("GET", "/api/whoami", token=viewer)
        check(s == 200 and json.loads(data)["role"] == "viewer" and viewer not in data.decode(), "whoami as viewer")
        s, data, _ = d.http("GET", "/api/whoami", token=op)
        check(json.loads(data)["role"] == "operator", "whoami as operator")
        s, data, _ = d.http("GET", "/api/estimators", token=viewer)
        est = {e["name"]: e for e in json.loads(data)}
        check(len(est) == 7 and not est["encoder"]["sensorless"] and est["eemf-lut"]["min_speed_rpm"] == 500, "estimators listed")
        s, data, _ = d.http("GET", "/api/devices", token=viewer)
        check(s == 200 and {x["role"] for x in json.loads(data)} >= {"synrm", "load", "meter"}
              and json.loads(data)[0]["backend"] == "twin", "devices of the twin")
        s, data, _ = d.http("GET", "/api/profiles", token=viewer)
        profs = json.loads(data)
        check(s == 200 and len(profs) == 3 and all(p["valid"] for p in profs), "default profiles listed, valid")
        tiny = {"name": "rest", "window_s": 0.5, "dimensions": {"speed_rpm": [500], "load_Nm": [1.0], "angle_deg": [48, 52]}}
        s, data, _ = d.http("POST", "/api/sweeps", body=tiny, token=op)
        created = json.loads(data)
        check(s == 201 and created["state"] == "created" and created["total_points"] == 2, "POST /api/sweeps -> 201 created")
        s, data, _ = d.http("POST", "/api/sweeps", body={"dimensions": {"speed_rpm": [-5]}}, token=op)
        check(s == 400 and error_of(data)[0] == "bad_plan" and "/dimensions/speed_rpm" in error_of(data)[1],
              "bad plan -> 400 naming the JSON pointer (%s)" % data[:200])
        r = subprocess.run([BIN, "sweep", "--resume", str(created["id"]), "--db", os.path.join(data_dir, "synbench.db"), "--quiet"],
                           capture_output=True, text=True)
        check(r.returncode == 0, "a sweep created over REST runs with synbench sweep --resume")
        s, data, _ = d.http("GET", "/api/sweeps/%d" % created["id"], token=viewer)
        check(s == 200 and json.loads(data)["state"] == "completed" and json.loads(data)["points_stored"] == 2,
              "the daemon sees the sweep completed")
        # A sweep run by the daemon's own bench, in real time.
        s, data, _ = d.http("POST", "/api/sweeps", body=tiny, token=op)
        sid = json.loads(data)["id"]
        s, data, _ = d.http("POST", "/api/sweeps/%d/start" % sid, token=op)
        check(s == 202, "start a sweep on the daemon -> 202 (%s)" % data[:200])
        s, data, _ = d.http("POST", "/api/bench/enable", body={"enabled": True}, token=op)
        check(s == 409 and error_of(data)[0] == "sweep_running", "manual enable refused during a sweep")
        s, data, _ = d.http("POST", "/api/sweeps/%d/start" % sid, token=op)
        check(s == 409, "a second start is refused")
        state = None
        deadline = time.time() + 60
        while time.time() < deadline:
            _, data, _ = d.http("GET", "/api/sweeps/%d" % sid, token=viewer)
            sw = json.loads(data)
            state = sw["state"]
            if state not in ("created", "running"):
                break
            time.sleep(0.5)
        check(state == "completed" and sw["points_stored"] == 2, "the daemon's sweep completes with 2 points (%s)" % state)
        _, data, _ = d.http("GET", "/api/bench/status", token=viewer)
        check(json.loads(data)["sweep"]["state"] == "completed", "status shows the last sweep")
        s, data, _ = d.http("POST", "/api/sweeps", body=tiny, token=op)
        sid = json.loads(data)["id"]
        d.http("POST", "/api/sweeps/%d/start" % sid, token=op)
        s, data, _ = d.http("POST", "/api/sweeps/%d/abort" % sid, body={"reason": 5}, token=op)
        check(s == 400 and "/reason" in data.decode(), "an abort reason that is not text -> 400 at /reason")
        s, data, _ = d.http("POST", "/api/sweeps/%d/abort" % sid, body={"reason": "  rest test  "}, token=op)
        check(s == 200, "abort a running sweep (with a reason)")
        deadline = time.time() + 30
        while time.time() < deadline:
            _, data, _ = d.http("GET", "/api/sweeps/%d" % sid, token=viewer)
            state = json.loads(data)["state"]
            if state != "running":
                break
            time.sleep(0.3)
        check(state == "aborted", "the aborted sweep is recorded aborted (%s)" % state)
        check(json.loads(data)["last_error"] == "rest test", "the abort's reason is its last_error (%r)" % json.loads(data)["last_error"])
        too_fast = dict(tiny, dimensions={"speed_rpm": [500, 1600], "load_Nm": [1.0], "angle_deg": [48]})
        for route in ("/api/sweeps/estimate", "/api/sweeps"):
            s, data, _ = d.http("POST", route, body=too_fast, token=op)
            check(s == 400 and "/dimensions/speed_rpm: 1600 rpm exceeds the bench's max_speed_rpm (1500 rpm" in data.decode(),
                  "%s refuses a speed above the drive's limit at its pointer: %s" % (route, data[:200]))
        s, data, _ = d.http("POST", "/api/sweeps/%d/pause" % sid, token=op)
        check(s == 409 and error_of(data)[0] == "not_running", "pause of a sweep not running -> 409")

        s, data, _ = d.http("GET", "/api/sweeps/99", token=viewer)
        check(s == 404 and error_of(data)[0] == "not_found", "unknown sweep -> 404")
        s, data, _ = d.http("GET", "/api/sweeps/abc", token=viewer)
        check(s == 400 and error_of(data)[1].startswith("id"), "bad sweep id -> 400 naming id")
        s, data, _ = d.http("GET", "/api/sweeps/1/points?format=xml", token=viewer)
        check(s == 400 and error_of(data)[1].startswith("format"), "bad format -> 400 naming format")

        # Limits and errors.
        s, data, _ = d.http("GET", "/api/health", host="evil.example:%d" % d.port)
        check(s == 403 and error_of(data)[0] == "host_not_allowed", "foreign Host -> 403")
        s, _, _ = d.http("GET", "/api/health", host="localhost:%d" % d.port)
        check(s == 200, "Host localhost:PORT accepted")
        s, _, _ = d.http("GET", "/api/health", host="127.0.0.1:1")
        check(s == 403, "Host with another port -> 403")
        # Two Host headers (both allowed or not): 400, never a pick of one.
        for second in ("127.0.0.1:%d" % d.port, "evil.example"):
            reply = send_raw(d.port, ("GET /api/health HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nHost: %s\r\nConnection: close\r\n\r\n"
                                      % (d.port, second)).encode())
            check(reply.startswith(b"HTTP/1.1 400") and b"more than one Host" in reply, "duplicate Host (%s) -> 400" % second)
        # A path or parameter that is not UTF-8: a JSON answer, never a crash.
        for path, status in (("/api/\xff", 404), ("/\xff.js", 404), ("/api/sweeps/%ff", 400), ("/api/sweeps/1/points?format=%ff", 400)):
            reply = send_raw(d.port, b"GET " + path.encode("latin-1") + (
                " HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nAuthorization: Bearer %s\r\nConnection: close\r\n\r\n" % (d.port, viewer)).encode())
            head, _, body = reply.partition(b"\r\n\r\n")
            try:
                doc = json.loads(body.decode("utf-8"))
            except ValueError:
                doc = None
            check(head.startswith(b"HTTP/1.1 %d" % status) and doc is not None and "error" in doc,
                  "GET %r -> %d with a JSON error (got %r)" % (path, status, reply[:120]))
            check(d.proc.poll() is None, "the daemon survives GET %r" % path)
        s, data, _ = d.http("POST", "/api/bench/setpoints", body="x" * (65 * 1024), token=op)
        check(s == 413 and error_of(data)[0] == "body_too_large", "body over the limit -> 413")
        s, data, _ = d.http("POST", "/api/bench/setpoints", body='{"speed_rpm": ', token=op)
        check(s == 400 and error_of(data)[0] == "bad_json" and "column" in error_of(data)[1], "bad JSON -> 400 naming the position")
        s, data, _ = d.http("POST", "/api/bench/setpoints", body={"speed_rpm": 99999}, token=op)
        check(s == 400 and error_of(data)[1].startswith("/speed_rpm: 99999 is outside"), "out-of-range setpoint names the field at its pointer")
        s, data, _ = d.http("GET", "/api/nowhere", token=viewer)
        check(s == 404 and error_of(data)[0] == "not_found", "unknown route -> 404 JSON")
        s, _, r = d.http("DELETE", "/api/bench/status", token=op)
        check(s == 405 and r.getheader("Allow") == "GET", "wrong method -> 405 with Allow")
        s, _, _ = d.http("GET", "/api/health", headers={"X-Big": "y" * 10000})
        check(s == 431, "header over the limit -> 431 (got %d)" % s)

        # Connection limit: 64 idle connections that never showed a token fill the house; the
        # 65th is served all the same, and the oldest idle one is closed to make room for it.
        held = [socket.create_connection(("127.0.0.1", d.port), timeout=10) for _ in range(64)]
        time.sleep(0.2)
        conn = http.client.HTTPConnection("127.0.0.1", d.port, timeout=10)
        conn.request("GET", "/api/health", headers={"Host": "127.0.0.1:%d" % d.port})
        resp = conn.getresponse()
        resp.read()
        conn.close()
        check(resp.status == 200, "connection 65 is served while 64 idle ones are held (%s)" % resp.status)
        held[0].settimeout(2)
        try:
            oldest_closed = held[0].recv(1) == b""
        except OSError:
            oldest_closed = True
        check(oldest_closed, "... and the oldest idle connection was closed to make room")
        for c in held:
            c.close()
        time.sleep(0.3)

        # Keep-alive: two requests on one connection.
        conn = http.client.HTTPConnection("127.0.0.1", d.port, timeout=10)
        for _ in range(2):
            conn.request("GET", "/api/health")
            resp = conn.getresponse()
            resp.read()
            check(resp.status == 200, "keep-alive request")
        conn.close()

        # Manual mode: estimator and PWM, refused while enabled.
        s, data, _ = d.http("POST", "/api/bench/mode", body={"estimator": "ekf-rs", "pwm": "aspwm"}, token=op)
        check(s == 200 and json.loads(data)["mode"] == {"estimator": "ekf-rs", "pwm": "aspwm"}, "mode -> ekf-rs/aspwm")
        s, data, _ = d.http("POST", "/api/bench/mode", body={"estimator": "magic"}, token=op)
        check(s == 400 and error_of(data)[1].startswith("/estimator: must be one of"), "unknown estimator -> 400 at /estimator")
        s, data, _ = d.http("POST", "/api/bench/mode", body={"estimator": "encoder", "pwm": "capwm"}, token=op)
        check(s == 200, "mode back to encoder/capwm")
        # The twin follows the operator's setpoint in real time.
        s, _, _ = d.http("POST", "/api/bench/setpoints", body={"speed_rpm": 400, "load_Nm": 0.5, "angle_deg": 50}, token=op)
        check(s == 200, "setpoints as operator -> 200")
        s, data, _ = d.http("POST", "/api/bench/enable", body={"enabled": True}, token=op)
        check(s == 200, "enable -> 200 (%s)" % data)
        speed = 0.0
        deadline = time.time() + 15
        while time.time() < deadline:
            _, data, _ = d.http("GET", "/api/bench/status", token=viewer)
            st = json.loads(data)
            speed = st["synrm"]["speed_rpm"] if st["synrm"] else 0.0
            if abs(speed - 400) < 20:
                break
            time.sleep(0.2)
        check(abs(speed - 400) < 20, "twin speed follows the setpoint (%.1f rpm)" % speed)
        s, data, _ = d.http("POST", "/api/bench/mode", body={"pwm": "aspwm"}, token=op)
        check(s == 409 and error_of(data)[0] == "bench_enabled", "mode change refused while enabled")
        check(st["synrm"]["pos_err_deg"] is None, "no live position error with the encoder")
        s, data, _ = d.http("GET", "/metrics")
        m = re.search(r"^synbench_synrm_speed_revolutions_per_minute (\S+)$", data.decode(), re.M)
        check(s == 200 and m and abs(float(m.group(1)) - 400) < 20, "metrics has the speed (%s)" % (m and m.group(1)))
        # Prometheus's own linter on the exposition (Debian's prometheus package).
        promtool = shutil.which("promtool")
        if promtool:
            lint = subprocess.run([promtool, "check", "metrics"], input=data, capture_output=True)
            check(lint.returncode == 0 and not lint.stdout.strip() and not lint.stderr.strip(),
                  "promtool check metrics passes, no warning (%r %r)" % (lint.stdout[-300:], lint.stderr[-300:]))
        else:
            check(not os.environ.get("CI"), "promtool is installed (scripts/install-deps.sh installs prometheus)")
            print("SKIP: promtool check metrics (no promtool)")
        check("synbench_ws_clients 0" in data.decode() and "synbench_ws_dropped_total 0" in data.decode(),
              "metrics counts WebSocket clients and drops")

        # The control lock: op holds it since its first command; another operator is refused,
        # but may always E-stop.
        op2 = subprocess.run([BIN, "token", "create", "--role", "operator", "--data-dir", data_dir],
                             capture_output=True, text=True).stdout.strip()
        s, data, _ = d.http("POST", "/api/bench/setpoints", body={"speed_rpm": 100}, token=op2)
        check(s == 409 and error_of(data)[0] == "locked", "another operator is refused while op holds the lock")
        s, data, _ = d.http("GET", "/api/bench/lock", token=viewer)
        check(s == 200 and json.loads(data)["holder"], "GET /api/bench/lock names the holder")
        check(op not in data.decode(), "the lock holder label is not the token")

        s, data, _ = d.http("POST", "/api/bench/estop", token=op2)
        st = json.loads(data)
        check(s == 200 and st["supervisor"]["phase"] == "estopped" and st["supervisor"]["tripped"], "E-stop latches")
        s, data, _ = d.http("POST", "/api/bench/enable", body={"enabled": True}, token=op)
        check(s == 409 and error_of(data)[0] == "tripped", "enable refused while tripped")
        s, _, _ = d.http("POST", "/api/bench/reset", token=op)
        check(s == 200, "reset after E-stop")
        s, _, _ = d.http("DELETE", "/api/bench/lock", token=op2)
        check(s == 409, "op2 cannot release op's lock")
        s, _, _ = d.http("DELETE", "/api/bench/lock", token=op)
        check(s == 200, "op releases the lock")

        # Sensorless: the live telemetry carries the estimator's position error.
        # (EKF-BASIC with ASPWM, the thesis configuration.)
        s, data, _ = d.http("POST", "/api/bench/mode", body={"estimator": "ekf-basic", "pwm": "aspwm"}, token=op)
        check(s == 200, "mode ekf-basic (%s)" % data[:200])
        d.http("POST", "/api/bench/setpoints", body={"speed_rpm": 500, "load_Nm": 1.0, "angle_deg": 50}, token=op)
        d.http("POST", "/api/bench/enable", body={"enabled": True}, token=op)
        errs = []
        deadline = time.time() + 15
        while time.time() < deadline and len(errs) < 5:
            _, data, _ = d.http("GET", "/api/bench/status", token=viewer)
            st = json.loads(data)
            if st["synrm"] and abs(st["synrm"]["speed_rpm"] - 500) < 25:
                errs.append(st["synrm"]["pos_err_deg"])
            time.sleep(0.2)
        check(len(errs) == 5 and all(e is not None and abs(e) < 10 for e in errs),
              "EKF-BASIC at 500 rpm: live position error within 10 deg (%s)" % errs)
        # Run again, then SIGTERM: ordered stop, exit 0.
        d.http("POST", "/api/bench/enable", body={"enabled": True}, token=op)
        time.sleep(1)
        rc, err = d.stop()
        check(rc == 0, "SIGTERM -> exit 0 (got %s)" % rc)
        check(op not in err.split("first start")[-1].split("\n", 1)[-1], "the token is logged only at first start")
        check(viewer not in err, "a created token is never logged")
    finally:
        d.kill()

    # SIGTERM during a sweep: the sweep is aborted with its committed points kept, exit 0.
    data_dir2 = os.path.join(tmp, "data2")
    d = Daemon(BIN, data_dir2)
    try:
        op = open(os.path.join(data_dir2, "operator.token")).read().strip()
        s, data, _ = d.http("POST", "/api/sweeps", token=op, body={
            "preset": "thesis-grid", "dimensions": {"configurations": [{"estimator": "encoder", "pwm": "capwm"}]}})
        sid = json.loads(data)["id"]
        s, _, _ = d.http("POST", "/api/sweeps/%d/start" % sid, token=op)
        check(s == 202, "start the thesis grid")
        time.sleep(3)
        rc, _ = d.stop()
        check(rc == 0, "SIGTERM during a sweep -> exit 0 (got %s)" % rc)
        import sqlite3
        con = sqlite3.connect(os.path.join(data_dir2, "synbench.db"))
        state = con.execute("select state from sweeps where id = ?", (sid,)).fetchone()[0]
        con.close()
        check(state == "aborted", "the interrupted sweep is recorded aborted (%s)" % state)
    finally:
        d.kill()

    # Bad flags.
    r = subprocess.run([BIN, "serve", "--listen", "nonsense"], capture_output=True, text=True)
    check(r.returncode == 2 and "--listen" in r.stderr, "serve --listen nonsense: exit 2 naming --listen")

    check.finish("serve test ok")


if __name__ == "__main__":
    main()
