#!/usr/bin/env python3
"""Fuzz test of `synbench serve` over raw sockets: mutated paths (bytes that are not UTF-8,
percent-encoding, dot segments), query parameters, JSON bodies (1e309, 400-digit integers, deep
nesting, bad bytes, wrong types) and headers (a duplicate Host, bytes in values, odd framing), then
WebSocket messages mutated the same way, from a fixed seed within a time budget. Counts crashes
(the daemon died: it is restarted and the input printed) and 5xx answers, and checks that every
JSON error body parses, that a duplicate Host is a 400, and that a WebSocket request whose reply
is too large answers 413 `reply_too_large` and keeps the connection. Prints "inputs tried N,
crashes N, 5xx N" for HTTP and for WebSocket; fails on any crash or 5xx.

usage: fuzz_test.py path/to/synbench [seconds]
"""
import base64
import json
import os
import random
import re
import socket
import struct
import sys
import tempfile
import time

from checks import Checks
from daemon import Daemon, run_sweep

BIN = sys.argv[1]
SECONDS = float(sys.argv[2]) if len(sys.argv) > 2 else 40
rng = random.Random(20261122)
check = Checks(verbose=False)
failures = check.failures

HOSTILE = [b"1e309", b"-1e309", b"9" * 400, b"-" + b"7" * 400, b"1e-400", b"18446744073709551616", b"-1", b"0", b"null",
           b"true", b'""', b"[]", b"{}", b"[" * 100 + b"]" * 100, b"[" * 3000, b'"\xff"', b'"\xc3"', b'"\\ud800"',
           b'"\\u0000"', b'"' + b"a" * 5000 + b'"', b"\xff", b"\xc3\x28", b"\xed\xa0\x80", b"\x80", b"NaN", b"{", b"]", b","]
PATH_BITS = [b"\xff", b"\xc3", b"\xc3\x28", b"%ff", b"%c3%28", b"%C3%A9", b"%00", b"%", b"%zz", b"..", b"%2e%2e", b"%2f",
             b"%5c", b"\x80", b"\xed\xa0\x80", b"x" * 300, b"1", b"0", b"-1", b"99999999999999999999", b"{id}", b"api",
             b"sweeps", b"bench", b"points", b"analysis", b"metrics", b"ws", b"assets", b"index.html", b"a.js", b""]
QUERY_KEYS = [b"format", b"reference", b"offset", b"limit", b"id", b"x", b"%ff", b"\xff", b""]
QUERY_VALUES = [b"csv", b"json", b"xml", b"encoder/capwm", b"a/b", b"%ff", b"%c3%28", b"\xff", b"\xc3", b"0", b"1", b"-1",
                b"10000", b"10001", b"99999999999999999999999", b"1e3", b"", b"%", b"%zz", b"+", b"%20"]
ROUTES = [(b"GET", b"/api/health"), (b"GET", b"/api/openapi.json"), (b"GET", b"/metrics"), (b"GET", b"/api/bench/status"),
          (b"GET", b"/api/bench/config"), (b"GET", b"/api/bench/lock"), (b"GET", b"/api/sweeps"), (b"GET", b"/api/sweeps/1"),
          (b"GET", b"/api/sweeps/1/points"), (b"GET", b"/api/sweeps/1/analysis"), (b"GET", b"/api/presets"),
          (b"GET", b"/api/whoami"), (b"GET", b"/api/estimators"), (b"GET", b"/api/devices"), (b"GET", b"/api/profiles"),
          (b"GET", b"/"), (b"GET", b"/sweeps/3"), (b"GET", b"/assets/x.js"), (b"HEAD", b"/api/health"), (b"GET", b"/ws")]
BODY_ROUTES = [b"/api/bench/setpoints", b"/api/bench/mode", b"/api/bench/enable", b"/api/sweeps", b"/api/sweeps/estimate",
               b"/api/bench/lock", b"/api/sweeps/1/pause"]
SMALL_PLAN = {"name": "f", "window_s": 0.5, "dimensions": {"speed_rpm": [500], "load_Nm": [1], "angle_deg": [48, 52]}}
BODIES = [{"speed_rpm": 500, "load_Nm": 0.5, "angle_deg": 50}, {"enabled": False}, {"estimator": "encoder", "pwm": "capwm"},
          SMALL_PLAN, {"preset": "thesis-grid", "mode": "adaptive"},
          {"dimensions": {"speed_rpm": {"from": 100, "to": 900, "step": 200}, "load_Nm": [0.5], "angle_deg": [40, 50],
                          "configurations": [{"estimator": "ekf-rs", "pwm": "aspwm"}]}}]


def pick(seq):
    return seq[rng.randrange(len(seq))]


# --- mutations -------------------------------------------------------------------------------

def mutate_bytes(data):
    data = bytearray(data)
    for _ in range(rng.randint(1, 3)):
        if not data:
            data += pick(HOSTILE)
            continue
        at = rng.randrange(len(data))
        op = rng.randrange(5)
        if op == 0:
            data[at] = rng.randrange(256)
        elif op == 1:
            data[at:at] = pick(HOSTILE)
        elif op == 2:
            del data[at:at + rng.randint(1, 16)]
        elif op == 3:
            start = rng.randrange(len(data))
            data[at:at] = data[start:start + rng.randint(1, 64)]
        else:
            m = re.search(rb"-?\d+(\.\d+)?([eE][+-]?\d+)?", bytes(data[at:]))
            if m:
                data[at + m.start():at + m.end()] = pick(HOSTILE[:8])
    return bytes(data)


def leaves(doc, at=()):
    out = [at] if at else []
    if isinstance(doc, dict):
        for k, v in doc.items():
            out += leaves(v, at + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            out += leaves(v, at + (i,))
    return out


def mutate_json(doc):
    """A value of `doc` swapped for hostile raw text (or its JSON text mutated byte-wise)."""
    if rng.random() < 0.4:
        return mutate_bytes(json.dumps(doc).encode())
    doc = json.loads(json.dumps(doc))
    paths = leaves(doc)
    marker = "@@fuzz@@"
    if not paths:
        return pick(HOSTILE)
    path = pick(paths)
    parent = doc
    for k in path[:-1]:
        parent = parent[k]
    if isinstance(parent, dict) and rng.random() < 0.3:
        parent[pick(["unknown", "_c", "\u00e9t\u00e9", "x" * 200])] = marker
    else:
        parent[path[-1]] = marker
    return json.dumps(doc).encode().replace(b'"' + marker.encode() + b'"', pick(HOSTILE), 1)


def mutate_path(path):
    segs = path.split(b"/")
    for _ in range(rng.randint(1, 3)):
        op = rng.randrange(4)
        at = rng.randrange(len(segs))
        if op == 0:
            segs[at] = pick(PATH_BITS)
        elif op == 1:
            segs.insert(at, pick(PATH_BITS))
        elif op == 2:
            segs[at] = segs[at] + pick(PATH_BITS)
        else:
            segs[at] = mutate_bytes(segs[at]).replace(b" ", b"").replace(b"\r", b"").replace(b"\n", b"")
    out = b"/".join(segs)
    if not out.startswith(b"/"):
        out = b"/" + out
    return out


def random_query():
    return b"?" + b"&".join(pick(QUERY_KEYS) + b"=" + pick(QUERY_VALUES) for _ in range(rng.randint(1, 4)))


# --- the daemon ------------------------------------------------------------------------------

def exchange(port, data, timeout=5):
    """Sends raw bytes; returns (status, headers, body) of the answer, or (None, {}, b"") when the
    server closed without one."""
    try:
        s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    except OSError:
        return None, {}, b""
    try:
        s.sendall(data)
        s.shutdown(socket.SHUT_WR)
        reply = b""
        while True:
            chunk = s.recv(65536)
            if not chunk:
                break
            reply += chunk
            head, sep, body = reply.partition(b"\r\n\r\n")
            if sep:
                m = re.search(rb"(?i)\r\ncontent-length:\s*(\d+)", head)
                if m and len(body) >= int(m.group(1)):
                    break
    except (ConnectionError, socket.timeout, OSError):
        pass
    finally:
        s.close()
    head, _, body = reply.partition(b"\r\n\r\n")
    m = re.match(rb"HTTP/1\.[01] (\d{3})", head)
    if not m:
        return None, {}, b""
    headers = {}
    for line in head.split(b"\r\n")[1:]:
        k, _, v = line.partition(b":")
        headers[k.strip().lower()] = v.strip()
    # Only this answer's body: a request cut short may be followed by the answer to the rest.
    length = headers.get(b"content-length", b"")
    if length.isdigit():
        body = body[:int(length)]
    return int(m.group(1)), headers, body


def auth_headers(d):
    """Host and Authorization as the daemon wants them, as bytes (the raw requests here are bytes)."""
    return [(b"Host", d.host.encode()), (b"Authorization", b"Bearer " + d.operator.encode())]


def request_bytes(d, method, target, body=None, headers=None):
    lines = [method + b" " + target + b" HTTP/1.1"]
    hs = headers if headers is not None else auth_headers(d)
    for k, v in hs:
        lines.append(k + b": " + v)
    if body is not None:
        lines.append(b"Content-Type: application/json")
        lines.append(b"Content-Length: %d" % len(body))
    lines.append(b"Connection: close")
    return b"\r\n".join(lines) + b"\r\n\r\n" + (body or b"")


def http_input(d):
    """One mutated request: (label, raw bytes, check(status, headers, body) -> problem or None)."""
    kind = rng.randrange(5)
    if kind == 0:
        method, path = pick(ROUTES)
        target = mutate_path(path) + (random_query() if rng.random() < 0.3 else b"")
        return "path", request_bytes(d, method, target), None
    if kind == 1:
        method, path = pick(ROUTES)
        return "query", request_bytes(d, method, path.replace(b"{id}", b"1") + random_query()), None
    if kind == 2:
        body = mutate_json(pick(BODIES))
        return "body", request_bytes(d, b"POST", pick(BODY_ROUTES), body), None
    if kind == 3:
        method, path = pick(ROUTES)
        hs = auth_headers(d)
        host, token = hs[0][1], d.operator.encode()
        op = rng.randrange(6)
        expect_400 = False
        if op == 0:
            hs.append((b"Host", pick([host, b"evil.example", b"\xff"])))
            expect_400 = True
        elif op == 1:
            hs[0] = (b"Host", mutate_bytes(host).replace(b"\r", b"").replace(b"\n", b""))
        elif op == 2:
            hs[1] = (b"Authorization", pick([b"Bearer \xff", b"Bearer " + token + b"\xc3", b"\xff\xfe", b"Bearer " + b"%ff" * 40]))
        elif op == 3:
            hs.append((pick([b"If-None-Match", b"Origin", b"X-\xff", b"Accept"]), pick(PATH_BITS + [b"W/\"\xff\""])))
        elif op == 4:
            hs += [(b"Upgrade", b"websocket"), (b"Connection", b"Upgrade"), (b"Sec-WebSocket-Version", pick([b"13", b"\xff", b"8"])),
                   (b"Sec-WebSocket-Key", pick([b"dGhlIHNhbXBsZSBub25jZQ==", b"\xff", b""])),
                   (b"Origin", pick([b"http://" + host, b"http://\xff", b"null"]))]
            path = b"/ws"
        else:
            hs += [(b"X-Pad-%d" % i, b"v") for i in range(rng.randint(1, 60))]
        raw = request_bytes(d, method, path, None, hs)

        def dup_host(status, headers, body):
            return None if status == 400 else "duplicate Host answered %s" % status
        return "header", raw, dup_host if expect_400 else None
    # Odd framing: chunked with bad sizes, a short Content-Length, garbage.
    raw = pick([b"POST /api/sweeps/estimate HTTP/1.1\r\nHost: " + d.host.encode() + b"\r\nTransfer-Encoding: chunked\r\n\r\n" +
                pick([b"zz\r\n", b"ffffffffffffffffff\r\n", b"5\r\n{\"a\":\r\n0\r\n\r\n"]),
                request_bytes(d, b"POST", b"/api/bench/setpoints", b'{"speed_rpm": 5}')[:-3],
                mutate_bytes(request_bytes(d, b"GET", b"/api/health")), os.urandom(rng.randint(1, 300)) + b"\r\n\r\n"])
    return "framing", raw, None


def json_body_problem(status, headers, body):
    """A JSON answer must parse (as UTF-8)."""
    ctype = headers.get(b"content-type", b"")
    if status is None or not ctype.startswith(b"application/json") or not body:
        return None
    try:
        json.loads(body.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as e:
        return "status %s with a body that is not JSON (%s): %r" % (status, e, body[:100])
    return None


# --- WebSocket -------------------------------------------------------------------------------

class RawWs:
    """A minimal client: any frame (text that is not UTF-8 included), replies read as frames."""

    def __init__(self, d):
        self.s = socket.create_connection(("127.0.0.1", d.port), timeout=5)
        key = base64.b64encode(os.urandom(16))
        self.s.sendall(b"GET /ws HTTP/1.1\r\nHost: " + d.host.encode() + b"\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                       b"Sec-WebSocket-Key: " + key + b"\r\nSec-WebSocket-Version: 13\r\n\r\n")
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.s.recv(4096)
            if not chunk:
                raise ConnectionError("no upgrade answer")
            head += chunk
        if not head.startswith(b"HTTP/1.1 101"):
            raise ConnectionError("upgrade refused: %r" % head[:60])
        self.buf = head.partition(b"\r\n\r\n")[2]
        self.closed = False

    def send(self, payload, opcode=1):
        mask = os.urandom(4)
        n = len(payload)
        head = bytes([0x80 | opcode])
        head += bytes([0x80 | n]) if n < 126 else (bytes([0x80 | 126]) + struct.pack("!H", n) if n < 65536
                                                   else bytes([0x80 | 127]) + struct.pack("!Q", n))
        self.s.sendall(head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload)))

    def _read(self, n):
        while len(self.buf) < n:
            chunk = self.s.recv(1 << 20)
            if not chunk:
                raise ConnectionError("closed")
            self.buf += chunk
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def recv(self, timeout):
        """The next text message (str), or None on timeout; raises ConnectionError once closed."""
        self.s.settimeout(timeout)
        try:
            message = b""
            while True:
                b0, b1 = self._read(2)
                n = b1 & 0x7F
                if n == 126:
                    n = struct.unpack("!H", self._read(2))[0]
                elif n == 127:
                    n = struct.unpack("!Q", self._read(8))[0]
                data = self._read(n)
                opcode = b0 & 0x0F
                if opcode == 8:
                    self.closed = True
                    raise ConnectionError("close %s" % (struct.unpack("!H", data[:2])[0] if len(data) >= 2 else "-"))
                if opcode == 9:
                    self.send(data, 10)
                    continue
                if opcode in (1, 2, 0):
                    message += data
                    if b0 & 0x80:
                        return message.decode("utf-8")
        except socket.timeout:
            return None
        except OSError as e:
            self.closed = True
            raise ConnectionError(str(e))

    def close(self):
        try:
            self.s.close()
        except OSError:
            pass


def ws_messages(token):
    request = {"op": "request", "id": 1, "method": "GET", "path": "/api/bench/status"}
    return [{"op": "subscribe", "channel": "sweep"}, {"op": "subscribe", "channel": "telemetry", "rate_hz": 5},
            {"op": "unsubscribe", "channel": "telemetry"}, request,
            {"op": "request", "id": "p", "method": "GET", "path": "/api/sweeps/1/points?limit=3"},
            {"op": "request", "id": [1, {"a": None}], "method": "POST", "path": "/api/bench/setpoints", "body": {"speed_rpm": 400}},
            {"op": "request", "id": 2, "method": "POST", "path": "/api/sweeps/estimate", "body": SMALL_PLAN},
            {"op": "request", "id": 3, "method": "GET", "path": "/api/sweeps/1/analysis?format=csv"},
            {"op": "auth", "token": token}]


def ws_connect(d):
    ws = RawWs(d)
    ws.send(json.dumps({"op": "auth", "token": d.operator}).encode())
    hello = ws.recv(5)
    if not hello or json.loads(hello).get("type") != "hello":
        raise ConnectionError("no hello: %r" % hello)
    return ws


def ws_answers(ws, timeout):
    """Messages until `timeout` passes quietly; telemetry and progress pushes are skipped."""
    out = []
    while True:
        m = ws.recv(timeout)
        if m is None:
            return out
        doc = json.loads(m)
        if doc.get("type") in ("reply", "error"):
            out.append(doc)
            timeout = 0.05


# --- main ------------------------------------------------------------------------------------

def main():
    tmp = tempfile.mkdtemp(prefix="synbench-fuzz-")
    data_dir = os.path.join(tmp, "data")
    os.makedirs(data_dir)
    # A stored sweep whose points make a WebSocket reply over the limit (570 points, about 1 kB
    # each: 0.59 MB against 0.5 MiB; 5 s on the twin).
    plan = {"name": "fuzz", "window_s": 0.2,
            "dimensions": {"speed_rpm": [100, 300, 500, 700, 900], "load_Nm": {"from": 0.5, "to": 3.0, "step": 0.5},
                           "angle_deg": {"from": 40, "to": 76, "step": 2}}}
    r = run_sweep(BIN, plan, os.path.join(data_dir, "synbench.db"), tmp, "--quiet", timeout=600)
    check(r.returncode == 0, "a sweep of 570 points into the data dir (%s)" % r.stderr[-300:])
    log = open(os.path.join(tmp, "serve.log"), "w")
    d = Daemon(BIN, data_dir, stderr=log)
    counts = {"http": [0, 0, 0], "ws": [0, 0, 0]}  # inputs, crashes, 5xx
    shown = 0

    def report(kind, label, raw, what):
        nonlocal shown
        if shown < 15:
            print("FAIL: %s %s: %s; input %r" % (kind, label, what, raw[:300]))
        shown += 1

    def after(kind, label, raw, answered=True):
        if not d.alive(settle=not answered):
            counts[kind][1] += 1
            report(kind, label, raw, "the daemon died (exit %s)" % d.proc.returncode)
            d.start()
            return True
        return False

    t0 = time.time()
    try:
        # HTTP: about 60 % of the budget.
        while time.time() - t0 < SECONDS * 0.6:
            label, raw, extra = http_input(d)
            counts["http"][0] += 1
            status, headers, body = exchange(d.port, raw)
            if after("http", label, raw, answered=status is not None):
                continue
            if status is not None and status >= 500:
                counts["http"][2] += 1
                report("http", label, raw, "status %d: %r" % (status, body[:200]))
            for problem in (json_body_problem(status, headers, body), extra(status, headers, body) if extra else None):
                if problem:
                    failures.append(problem)
                    report("http", label, raw, problem)

        # The reply over the WebSocket limit: 413 reply_too_large, and the connection stays.
        ws = ws_connect(d)
        ws.send(json.dumps({"op": "request", "id": "all", "method": "GET", "path": "/api/sweeps/1/points"}).encode())
        try:
            big = ws_answers(ws, 10)
            ws.send(json.dumps({"op": "request", "id": "page", "method": "GET", "path": "/api/sweeps/1/points?limit=5"}).encode())
            page = ws_answers(ws, 10)
        except ConnectionError as e:
            big, page = [{"dropped": str(e)}], []
        check(len(big) == 1 and big[0].get("status") == 413 and big[0]["body"]["error"]["code"] == "reply_too_large",
              "WebSocket points of 570 points -> 413 reply_too_large (%s)" % str(big)[:300])
        check(len(page) == 1 and page[0].get("status") == 200 and len(page[0]["body"]) == 5
              and page[0].get("headers", {}).get("X-Total-Count") == "570",
              "then ?limit=5 on the same connection -> 5 points, X-Total-Count 570 (%s)" % str(page)[:300])
        ws.close()

        # WebSocket messages: the rest of the budget.
        seeds = ws_messages(d.operator)
        ws = None
        while time.time() - t0 < SECONDS:
            if ws is None or ws.closed:
                try:
                    ws = ws_connect(d)
                except (ConnectionError, OSError) as e:
                    if after("ws", "connect", b""):
                        continue
                    check(False, "WebSocket connect: %s" % e)
                    break
            r = rng.random()
            if r < 0.05:
                raw, opcode = mutate_bytes(b'{"op": "subscribe"}') + b"\xff", 1  # not UTF-8: Beast closes 1007
            elif r < 0.1:
                raw, opcode = os.urandom(rng.randint(1, 100)), 2
            else:
                # Frames must be UTF-8 to reach the daemon's parser; other bytes become escapes.
                raw, opcode = mutate_json(pick(seeds)).decode("utf-8", "backslashreplace").encode(), 1
            counts["ws"][0] += 1
            try:
                ws.send(raw, opcode)
                answers = ws_answers(ws, 0.15)
            except (ConnectionError, OSError):
                answers = []
                ws.closed = True
            except ValueError as e:  # a message that is not JSON or UTF-8
                answers = []
                failures.append("ws: unparsable message: %s" % e)
                report("ws", "message", raw, "unparsable message: %s" % e)
            if after("ws", "message", raw, answered=bool(answers)):
                ws = None
                continue
            for a in answers:
                if a.get("type") == "reply" and isinstance(a.get("status"), int) and a["status"] >= 500:
                    counts["ws"][2] += 1
                    report("ws", "message", raw, "reply status %d: %s" % (a["status"], str(a)[:200]))
        if ws is not None:
            ws.close()
    finally:
        rc, _ = d.stop()
        log.close()
    check(rc == 0, "SIGTERM after the fuzz -> exit 0 (got %s)" % rc)
    caught = [line for line in open(os.path.join(tmp, "serve.log"), errors="replace") if "internal error" in line or "caught" in line]
    for line in caught[:5]:
        print("daemon log: " + line.rstrip())

    for kind, name in (("http", "HTTP"), ("ws", "WebSocket")):
        n, crashes, five = counts[kind]
        print("%s: inputs tried %d, crashes %d, 5xx %d" % (name, n, crashes, five))
        check(crashes == 0 and five == 0, "%s: no crash, no 5xx" % name)
    check.finish("fuzz test ok")


if __name__ == "__main__":
    main()
