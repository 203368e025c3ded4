#!/usr/bin/env python3
"""Hostile input against `synbench serve` over real HTTP on loopback: 10,000 malformed requests
(bad JSON, wrong types, out-of-range values, unknown fields, invalid plans, huge bodies, huge
headers, foreign Host, foreign Origin on a WebSocket upgrade, unknown routes, wrong methods,
garbage request lines, bad percent-encoding), from a seeded generator so a failure reproduces.
Must hold: zero 5xx, zero dropped answers where the server should answer, the daemon never
dies, no sweep is created by an invalid plan, and /api/health answers afterwards.

usage: hostile_test.py path/to/synbench [count]
"""
import collections
import http.client
import json
import os
import random
import re
import socket
import subprocess
import sys
import tempfile
import time

from checks import Checks
from daemon import Daemon

BIN = sys.argv[1]
COUNT = int(sys.argv[2]) if len(sys.argv) > 2 else 10000
rng = random.Random(20261122)
check = Checks(verbose=False)
failures = check.failures


BAD_JSON = ['{', '{"speed_rpm": }', '[1, 2', '{"a": 1,}', 'null', '"text"', '42', '[]', 'true', '{"x": NaN}',
            '\x00\x01\x02', '{"speed_rpm": 1e999}', '{' * 200 + '}' * 200, '{"k": "\\ud800"}', 'nul', '{"a":1}{"b":2}']
WRONG_TYPES = [{"speed_rpm": "fast"}, {"speed_rpm": None}, {"load_Nm": [1]}, {"angle_deg": {"v": 45}}, {"angle_deg": True},
               {"speed_rpm": -1}, {"speed_rpm": 1e12}, {"angle_deg": 0}, {"angle_deg": 90}, {"load_Nm": -0.5},
               {"enabled": "yes"}, {"enabled": 1}, {"bogus": 1}, {"speed": 100}, {"estimator": 7}, {"estimator": "magic"},
               {"pwm": "svm"}, {}]
BAD_PLANS = [
    {"dimensions": {"speed_rpm": [-5]}},
    {"dimensions": {"speed_rpm": {"from": 100, "to": 50, "step": 10}, "load_Nm": [1], "angle_deg": [45]}},
    {"dimensions": {"speed_rpm": {"from": 1, "to": 2, "step": 0}}},
    {"dimensions": {"speed_rpm": [100], "load_Nm": [1], "angle_deg": [95]}},
    {"dimensions": {"speed_rpm": [100], "load_Nm": [1], "angle_deg": [45],
                    "configurations": [{"estimator": "magic", "pwm": "capwm"}]}},
    {"dimensions": {"speed_rpm": {"from": 1, "to": 1e9, "step": 1e-3}, "load_Nm": [1], "angle_deg": [45]}},
    {"preset": "nope"},
    {"preset": 5},
    {"window_s": -1, "dimensions": {"speed_rpm": [100], "load_Nm": [1], "angle_deg": [45]}},
    {"order": "angle-angle", "dimensions": {"speed_rpm": [100], "load_Nm": [1], "angle_deg": [45]}},
    {"mode": "adaptive", "dimensions": {"speed_rpm": [100], "load_Nm": [1], "angle_deg": [45]}},
    {"unknown_key": 1},
    {"gate": {"timeout_s": "long"}, "dimensions": {"speed_rpm": [100], "load_Nm": [1], "angle_deg": [45]}},
    {"dimensions": []},
]
BODY_ROUTES = ["/api/bench/setpoints", "/api/bench/enable", "/api/bench/mode"]
PLAN_ROUTES = ["/api/sweeps", "/api/sweeps/estimate"]


def random_path():
    pieces = ["api", "sweeps", "bench", "..", "%2e%2e", "%2F", "%", "%zz", "%00", "x" * rng.randint(1, 300),
              "{id}", "1", "-1", "999999999999999999999", "points", "analysis", "ws", "metrics", "%C3%A9", "%FF"]
    path = "/" + "/".join(rng.choice(pieces) for _ in range(rng.randint(1, 6)))
    if rng.random() < 0.3:
        path += "?" + "&".join("%s=%s" % (rng.choice(["format", "reference", "a", "%", "="]),
                                          rng.choice(["csv", "xml", "%", "%zz", "", "a/b"])) for _ in range(rng.randint(1, 4)))
    return path


class Client:
    """One keep-alive connection, reopened whenever the server closes it."""

    def __init__(self, port):
        self.port = port
        self.conn = None

    def request(self, method, path, body=None, headers=None):
        for attempt in range(2):
            if self.conn is None:
                self.conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=10)
            try:
                self.conn.request(method, path, body=body, headers=headers or {})
                r = self.conn.getresponse()
                r.read()
                if r.getheader("Connection", "").lower() == "close":
                    self.conn.close()
                    self.conn = None
                return r.status
            except (http.client.HTTPException, ConnectionError, socket.timeout, BrokenPipeError) as e:
                self.conn.close()
                self.conn = None
                if attempt == 1:
                    return "no answer: %s" % type(e).__name__
        return "no answer"


def raw_exchange(port, data):
    """Sends raw bytes, returns the status line's code or None if the server closed silently."""
    s = socket.create_connection(("127.0.0.1", port), timeout=10)
    try:
        s.sendall(data)
        reply = b""
        while b"\r\n" not in reply:
            chunk = s.recv(4096)
            if not chunk:
                break
            reply += chunk
    except (ConnectionError, socket.timeout):
        return None
    finally:
        s.close()
    m = re.match(rb"HTTP/1\.[01] (\d{3})", reply)
    return int(m.group(1)) if m else None


def main():
    tmp = tempfile.mkdtemp(prefix="synbench-hostile-")
    data_dir = os.path.join(tmp, "data")
    d = Daemon(BIN, data_dir, stderr=subprocess.DEVNULL)
    proc, port, op, host = d.proc, d.port, d.operator, d.host
    auth = {"Host": host, "Authorization": "Bearer " + op, "Content-Type": "application/json"}
    client = Client(port)
    statuses = collections.Counter()
    by_kind = collections.defaultdict(collections.Counter)
    t0 = time.time()
    try:
        kinds = ["bad_json", "wrong_type", "bad_plan", "huge_body", "huge_header", "foreign_host", "foreign_origin",
                 "unknown_route", "wrong_method", "garbage", "bad_token", "bad_query"]
        for i in range(COUNT):
            kind = kinds[i % len(kinds)]
            expect = None  # the set of acceptable statuses; None = any non-5xx answer
            if kind == "bad_json":
                st = client.request("POST", rng.choice(BODY_ROUTES + PLAN_ROUTES), rng.choice(BAD_JSON), auth)
                expect = {400}
            elif kind == "wrong_type":
                st = client.request("POST", rng.choice(BODY_ROUTES), json.dumps(rng.choice(WRONG_TYPES)), auth)
                expect = {400}
            elif kind == "bad_plan":
                st = client.request("POST", rng.choice(PLAN_ROUTES), json.dumps(rng.choice(BAD_PLANS)), auth)
                expect = {400}
            elif kind == "huge_body":
                size = rng.choice([64 * 1024 + 1, 200 * 1024, 1 << 20])
                st = raw_exchange(port, ("POST /api/sweeps HTTP/1.1\r\nHost: %s\r\nAuthorization: Bearer %s\r\n"
                                         "Content-Type: application/json\r\nContent-Length: %d\r\n\r\n" % (host, op, size)).encode()
                                  + b"x" * min(size, 70 * 1024))
                expect = {413}
            elif kind == "huge_header":
                st = client.request("GET", "/api/health", None, {"Host": host, "X-Pad": "p" * rng.choice([9000, 20000, 60000])})
                expect = {431}
            elif kind == "foreign_host":
                st = client.request("GET", rng.choice(["/api/health", "/api/bench/status", "/", "/ws"]), None,
                                    {"Host": rng.choice(["evil.example", "evil.example:%d" % port, "127.0.0.1:1", "", "localhost"])})
                expect = {403}
            elif kind == "foreign_origin":
                st = client.request("GET", "/ws", None, {
                    "Host": host, "Connection": "Upgrade", "Upgrade": "websocket", "Sec-WebSocket-Version": "13",
                    "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ==",
                    "Origin": rng.choice(["http://evil.example", "https://attacker.test:%d" % port, "null", "http://127.0.0.1:1"])})
                expect = {403}
            elif kind == "unknown_route":
                st = client.request(rng.choice(["GET", "POST"]), random_path(), None, auth)
            elif kind == "wrong_method":
                st = client.request(rng.choice(["PUT", "PATCH", "DELETE", "OPTIONS", "TRACE", "FOO"]),
                                    rng.choice(["/api/health", "/api/sweeps", "/api/bench/setpoints", "/api/sweeps/1/points"]), None, auth)
                expect = {400, 404, 405, 501}
            elif kind == "garbage":
                data = rng.choice([b"\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03" + os.urandom(64),
                                   b"GET\r\n\r\n", b"GET / HTTP/9.9\r\n\r\n", b"G\x00T / HTTP/1.1\r\nHost: %s\r\n\r\n" % host.encode(),
                                   b"POST /api/sweeps HTTP/1.1\r\nHost: %s\r\nContent-Length: -5\r\n\r\n" % host.encode(),
                                   b"POST /api/sweeps HTTP/1.1\r\nHost: %s\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n" % host.encode(),
                                   os.urandom(rng.randint(1, 512)) + b"\r\n\r\n"])
                st = raw_exchange(port, data)
                expect = {400, None}  # an answer or a clean close, never a 5xx
            elif kind == "bad_token":
                st = client.request("POST", rng.choice(BODY_ROUTES), "{}", {
                    "Host": host, "Authorization": rng.choice(["Bearer", "Bearer ", "Basic abc", "Bearer sbt_" + "z" * 64,
                                                               "Bearer " + op[:-1], "bearer\t" + op + "x", "x" * 4000])})
                expect = {401}
            else:  # bad_query
                st = client.request("GET", rng.choice(["/api/sweeps/1/points", "/api/sweeps/1/analysis", "/api/sweeps/0",
                                                       "/api/sweeps/abc", "/api/sweeps/1/analysis?reference=%zz"])
                                    + "?" + rng.choice(["format=xml", "format=", "reference=a/b", "%%%", "format=csv&format=x"]),
                                    None, auth)
            statuses[st] += 1
            by_kind[kind][st] += 1
            is_5xx = isinstance(st, int) and st >= 500
            if is_5xx or (expect is not None and st not in expect) or (expect is None and not isinstance(st, int)):
                if len(failures) < 20:
                    check(False, "%s request %d -> %s (expected %s)" % (kind, i, st, sorted(map(str, expect or ["non-5xx"]))))
                else:
                    failures.append(kind)
            if proc.poll() is not None:
                check(False, "the daemon died at request %d (%s), exit %s" % (i, kind, proc.returncode))
                break
        elapsed = time.time() - t0
        print("%d hostile requests in %.1f s" % (COUNT, elapsed))
        for kind in sorted(by_kind):
            print("  %-15s %s" % (kind, dict(sorted(by_kind[kind].items(), key=lambda kv: str(kv[0])))))
        check(not any(isinstance(s, int) and s >= 500 for s in statuses), "zero 5xx (%s)" % dict(statuses))
        check(proc.poll() is None, "the daemon still runs")
        c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        c.request("GET", "/api/health", headers={"Host": host})
        r = c.getresponse()
        check(r.status == 200 and json.loads(r.read())["status"] == "ok", "/api/health answers afterwards")
        c.request("GET", "/api/sweeps", headers={"Host": host, "Authorization": "Bearer " + op})
        r = c.getresponse()
        check(r.status == 200 and json.loads(r.read()) == [], "no invalid plan created a sweep")
        c.close()
    finally:
        rc, _ = d.stop()
        check(rc == 0, "SIGTERM after the storm -> exit 0 (got %s)" % rc)
    check.finish("hostile test ok")


if __name__ == "__main__":
    main()
