#!/usr/bin/env python3
"""`synbench serve`'s WebSocket /ws and the dashboard's static files, over real sockets on
loopback: the Host and Origin checks on the upgrade, auth (1008 on a bad, missing or late
token), roles through `request` (a viewer 403 on reset and enable; its E-stop, as an operator's, stops the bench), telemetry pacing
(20, 50 and the default 10 Hz: the messages' mean spacing in bench time), the protocol's errors (bad_message naming the field, connection kept),
oversized messages (1009), events and state pushes, a client that never reads dropped by its stalled write; static files: index, content types, caching,
HEAD, ETag, traversal attempts and symlinks out (never a file outside the directory), and the
"not built" page.

usage: ws_test.py path/to/synbench
"""
import http.client
import gzip
import json
import os
import socket
import sys
import tempfile
import time

from checks import Checks
from daemon import Daemon, raw_request, upgrade_lines
from ws_util import close_code, connect, recv_until, websocket

BIN = sys.argv[1]
check = Checks(verbose=True)


def http_get(d, path, method="GET", host=None, headers=None):
    conn = http.client.HTTPConnection("127.0.0.1", d.port, timeout=10)
    conn.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
    conn.putheader("Host", host or d.host)
    for k, v in (headers or {}).items():
        conn.putheader(k, v)
    conn.endheaders()
    r = conn.getresponse()
    body = r.read()
    conn.close()
    return r.status, r, body


def telemetry_times(ws, seconds):
    """The bench times (t_s) of the telemetry messages received within `seconds` of wall time."""
    times = []
    deadline = time.time() + seconds
    while time.time() < deadline:
        ws.settimeout(max(0.05, deadline - time.time()))
        try:
            m = json.loads(ws.recv())
        except websocket.WebSocketTimeoutException:
            break
        if m["type"] == "telemetry":
            times.append(m["t_s"])
    return times


def count_telemetry(ws, seconds):
    return len(telemetry_times(ws, seconds))


def check_paced(times, rate, seconds, what):
    """The daemon paces a subscription at its rate. Asserted on the bench times the messages carry
    (their mean spacing, so a message the test's process was late to read does not count against
    the daemon; the hub sends on its own 20 ms tick, so single gaps alternate around 1/rate), and
    as a bound: never more messages than the rate allows. The delivered wall-clock rate is a
    figure of tests/perf/ws_fanout_bench.py, not a functional check."""
    check(len(times) >= rate * seconds / 4, "%s: telemetry flows (%d messages in %.0f s)" % (what, len(times), seconds))
    if len(times) < 2:
        return
    mean = (times[-1] - times[0]) / (len(times) - 1)
    check(0.85 <= mean * rate <= 1.25, "%s: mean spacing %.1f ms of bench time (1/rate %.1f ms)"
          % (what, mean * 1e3, 1e3 / rate))
    check(len(times) <= 1.15 * rate * seconds + 2, "%s: never faster than subscribed (%d messages in %.0f s)"
          % (what, len(times), seconds))


def test_upgrade_checks(d):
    s, _, _ = raw_request(d.port, upgrade_lines(d.host))
    check(s == 101, "upgrade without Origin (not a browser) -> 101 (got %d)" % s)
    s, _, _ = raw_request(d.port, upgrade_lines(d.host, origin="http://%s" % d.host))
    check(s == 101, "upgrade from Origin http://HOST:PORT -> 101 (got %d)" % s)
    s, _, _ = raw_request(d.port, upgrade_lines(d.host, origin="http://localhost:%d" % d.port))
    check(s == 101, "upgrade from Origin http://localhost:PORT -> 101 (got %d)" % s)
    s, _, _ = raw_request(d.port, upgrade_lines(d.host, origin="http://dash.example:5173"))
    check(s == 101, "upgrade from an --allow-origin origin -> 101 (got %d)" % s)
    for origin in ["http://evil.example", "https://%s" % d.host, "http://127.0.0.1:1", "null",
                   "http://%s.evil.example" % d.host]:
        s, _, body = raw_request(d.port, upgrade_lines(d.host, origin=origin))
        check(s == 403 and b"origin_not_allowed" in body, "upgrade from Origin %s -> 403, never 101 (got %d)" % (origin, s))
    s, _, body = raw_request(d.port, upgrade_lines("evil.example:%d" % d.port))
    check(s == 403 and b"host_not_allowed" in body, "upgrade with a foreign Host -> 403 (got %d)" % s)
    s, _, _ = raw_request(d.port, upgrade_lines(None))
    check(s in (400, 403), "upgrade without Host -> 400/403, never 101 (got %d)" % s)
    s, _, _ = raw_request(d.port, ["GET /ws HTTP/1.1", "Host: " + d.host])
    check(s == 426, "plain GET /ws -> 426 (got %d)" % s)
    # websocket-client itself, with a foreign origin.
    try:
        websocket.create_connection(d.url, timeout=5, origin="http://evil.example")
        check(False, "websocket-client with a foreign origin is refused")
    except websocket.WebSocketBadStatusException as e:
        check(e.status_code == 403, "websocket-client with a foreign origin -> 403")


def test_auth(d, viewer):
    ws, _ = connect(d)
    ws.send(json.dumps({"op": "auth", "token": "sbt_" + "0" * 64}))
    m = recv_until(ws, lambda m: True)
    check(m and m["type"] == "error" and m["code"] == "unauthorized", "bad token -> error unauthorized")
    check(close_code(ws) == 1008, "bad token -> close 1008")

    ws, _ = connect(d)
    ws.send(json.dumps({"op": "subscribe", "channel": "telemetry"}))
    m = recv_until(ws, lambda m: True)
    check(m and m["code"] == "unauthorized", "a first message other than auth -> unauthorized")
    check(close_code(ws) == 1008, "... and close 1008")

    ws, _ = connect(d)
    ws.send("not json")
    check(close_code(ws) == 1008, "non-JSON before auth -> close 1008")

    t0 = time.time()
    ws, _ = connect(d)
    m = recv_until(ws, lambda m: True, timeout_s=15)
    code = close_code(ws)
    took = time.time() - t0
    check(m and m["code"] == "unauthorized" and "auth" in m["message"] and code == 1008 and 4.5 <= took <= 8,
          "no auth message -> unauthorized and close 1008 after 5 s (%.1f s, %s)" % (took, code))

    ws, hello = connect(d, viewer)
    check(hello["type"] == "hello" and hello["role"] == "viewer" and hello["id"].startswith("token-") and hello["version"],
          "viewer auth -> hello with role, id, version (%s)" % hello)
    _, _, health = http_get(d, "/api/health")
    check(len(hello.get("instance", "")) == 16 and hello["instance"] == json.loads(health)["instance"],
          "hello carries the daemon's instance id, as GET /api/health does (%s)" % hello.get("instance"))
    check(viewer not in json.dumps(hello), "hello does not echo the token")
    ws.send(json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": 20}))
    m = recv_until(ws, lambda m: m["type"] == "telemetry")
    check(m is not None, "viewer receives telemetry")
    keys = {"t_s", "enabled", "phase", "speed_rpm", "torque_Nm", "im_A", "id_A", "iq_A", "udc_V", "pac_W", "temp_C",
            "pos_err_deg", "voltage_limited", "fault", "sent_unix_ms"}
    check(m and keys <= set(m), "telemetry has every field (missing %s)" % (keys - set(m or {})))
    ws.send(json.dumps({"op": "request", "id": "e1", "method": "POST", "path": "/api/bench/reset"}))
    r = recv_until(ws, lambda m: m["type"] == "reply")
    check(r and r["id"] == "e1" and r["status"] == 403 and r["body"]["error"]["code"] == "forbidden",
          "viewer request POST /api/bench/reset -> reply status 403 (%s)" % r)
    ws.send(json.dumps({"op": "request", "id": "e2", "method": "POST", "path": "/api/bench/enable", "body": {"enabled": True}}))
    r = recv_until(ws, lambda m: m["type"] == "reply")
    check(r and r["id"] == "e2" and r["status"] == 403, "viewer request POST /api/bench/enable -> reply status 403 (%s)" % r)
    ws.send(json.dumps({"op": "request", "id": {"n": [1]}, "method": "GET", "path": "/api/bench/status"}))
    r = recv_until(ws, lambda m: m["type"] == "reply")
    check(r and r["id"] == {"n": [1]} and r["status"] == 200 and r["body"]["supervisor"]["tripped"] is False,
          "viewer request GET /api/bench/status -> 200 with the parsed body, id echoed")
    ws.send(json.dumps({"op": "request", "id": 3, "method": "GET", "path": "/metrics"}))
    r = recv_until(ws, lambda m: m["type"] == "reply")
    check(r and r["status"] == 200 and isinstance(r["body"], str) and "synbench_" in r["body"], "a text reply body is a string")
    ws.send(json.dumps({"op": "auth", "token": viewer}))
    m = recv_until(ws, lambda m: m["type"] == "error")
    check(m and m["code"] == "bad_message" and m["message"].startswith("op"), "a second auth -> bad_message")
    ws.close()


def test_protocol_errors(d, viewer):
    ws, _ = connect(d, viewer)
    cases = [
        ("{", "message"),
        ("[1]", "message"),
        (json.dumps({"channel": "telemetry"}), "op"),
        (json.dumps({"op": "dance"}), "op"),
        (json.dumps({"op": "subscribe"}), "channel"),
        (json.dumps({"op": "subscribe", "channel": "gossip"}), "channel"),
        (json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": 80}), "rate_hz"),
        (json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": 0}), "rate_hz"),
        (json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": "fast"}), "rate_hz"),
        (json.dumps({"op": "subscribe", "channel": "events", "rate_hz": 5}), "rate_hz"),
        (json.dumps({"op": "subscribe", "channel": "telemetry", "rate": 5}), "rate"),
        (json.dumps({"op": "request", "path": "/api/health"}), "method"),
        (json.dumps({"op": "request", "method": "GET", "path": "api/health"}), "path"),
    ]
    for text, field in cases:
        ws.send(text)
        m = recv_until(ws, lambda m: m["type"] == "error")
        check(m and m["code"] == "bad_message" and m["message"].startswith(field + ":"),
              "%s -> bad_message naming %s (%s)" % (text[:60], field, m and m["message"]))
    ws.send(json.dumps({"op": "request", "id": 1, "method": "GET", "path": "/api/health"}))
    r = recv_until(ws, lambda m: m["type"] == "reply")
    check(r and r["status"] == 200, "the connection stays open after errors")
    ws.send("x" * (70 * 1024))
    check(close_code(ws) == 1009, "a message over 64 KiB -> close 1009")


def test_never_reads(d, viewer):
    # Requests whose replies the client never reads: the session reads no further request while 8
    # are unanswered (docs/api.md, "Slow clients"), so its queue never fills with replies; the
    # reply the socket cannot take stalls its write, and the client is dropped after 5 s,
    # whatever the socket buffers hold.
    ws, _ = connect(d, viewer, sockopt=((socket.SOL_SOCKET, socket.SO_RCVBUF, 4096),))
    request = json.dumps({"op": "request", "method": "GET", "path": "/api/openapi.json"})
    try:
        for _ in range(600):
            ws.send(request)
    except (OSError, websocket.WebSocketConnectionClosedException):
        pass  # dropped while still sending
    time.sleep(7)  # reads nothing for longer than the write stall
    ws.sock.settimeout(10)
    ended = False
    try:
        while ws.sock.recv(65536):
            pass
        ended = True
    except (ConnectionResetError, BrokenPipeError):
        ended = True
    except socket.timeout:
        pass
    check(ended, "a client that sends but never reads is dropped (its write stalls)")
    ws2, hello = connect(d, viewer)
    check(hello["type"] == "hello", "the daemon serves new clients after the drop")
    ws2.close()


def test_rates(d, viewer):
    for rate in (20, 50):
        ws, _ = connect(d, viewer)
        ws.send(json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": rate}))
        m = recv_until(ws, lambda m: m["type"] == "subscribed")
        check(m and m["channel"] == "telemetry" and m["rate_hz"] == rate, "subscribed at %d Hz" % rate)
        recv_until(ws, lambda m: m["type"] == "telemetry")
        check_paced(telemetry_times(ws, 3.0), rate, 3.0, "telemetry at %d Hz" % rate)
        ws.send(json.dumps({"op": "unsubscribe", "channel": "telemetry"}))
        recv_until(ws, lambda m: m["type"] == "unsubscribed")
        n = count_telemetry(ws, 0.5)
        check(n == 0, "no telemetry after unsubscribe (%d)" % n)
        ws.close()
    ws, _ = connect(d, viewer)
    ws.send(json.dumps({"op": "subscribe", "channel": "telemetry"}))
    recv_until(ws, lambda m: m["type"] == "telemetry")
    check_paced(telemetry_times(ws, 2.0), 10, 2.0, "default rate 10 Hz")
    ws.close()


def test_operator(d, viewer):
    op = d.operator
    watcher, _ = connect(d, viewer)
    watcher.send(json.dumps({"op": "subscribe", "channel": "events"}))
    st = recv_until(watcher, lambda m: m["type"] == "state")
    check(st and st["supervisor"]["phase"] == "normal" and "enabled" in st, "events subscription starts with the state")
    watcher.send(json.dumps({"op": "subscribe", "channel": "sweep"}))
    sw = recv_until(watcher, lambda m: m["type"] == "sweep")
    check(sw and {"id", "state", "done", "total", "eta_s"} <= set(sw), "sweep subscription starts with the sweep (%s)" % sw)

    ws, hello = connect(d, op)
    check(hello["role"] == "operator", "operator hello")
    for i, (path, body) in enumerate([("/api/bench/setpoints", {"speed_rpm": 300, "load_Nm": 0.2, "angle_deg": 50}),
                                      ("/api/bench/enable", {"enabled": True})]):
        ws.send(json.dumps({"op": "request", "id": i, "method": "POST", "path": path, "body": body}))
        r = recv_until(ws, lambda m: m["type"] == "reply" and m["id"] == i)
        check(r and r["status"] == 200, "operator POST %s over WS -> 200" % path)
    ws.send(json.dumps({"op": "request", "id": "bad", "method": "POST", "path": "/api/bench/setpoints", "body": {"speed_rpm": -1}}))
    r = recv_until(ws, lambda m: m["type"] == "reply" and m["id"] == "bad")
    check(r and r["status"] == 400 and r["body"]["error"]["message"].startswith("/speed_rpm"), "REST validation applies over WS")
    seen = {}
    recv_until(watcher, lambda m: seen.setdefault(m["type"] + str(m.get("kind", m.get("enabled"))), m) and False, timeout_s=2)
    check("stateTrue" in seen, "a state message when the bench is enabled")
    ev = seen.get("eventenable")
    check(ev and ev["message"] and ev["seq"] >= 1, "an event message for the enable (%s)" % ev)
    ws.send(json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": 50}))
    m = recv_until(ws, lambda m: m["type"] == "telemetry" and m["speed_rpm"] is not None and m["speed_rpm"] > 100, timeout_s=10)
    check(m and m["enabled"], "operator sees the bench run (%s)" % (m and m["speed_rpm"]))

    ws.send(json.dumps({"op": "request", "id": "stop", "method": "POST", "path": "/api/bench/estop"}))
    r = recv_until(ws, lambda m: m["type"] == "reply" and m["id"] == "stop")
    check(r and r["status"] == 200 and r["body"]["supervisor"]["tripped"] and r["body"]["supervisor"]["phase"] == "estopped",
          "operator E-stop over WS -> 200, tripped, estopped")
    m = recv_until(ws, lambda m: m["type"] == "telemetry" and m["phase"] == "estopped" and not m["enabled"])
    check(m is not None, "telemetry shows the E-stop")
    st = recv_until(watcher, lambda m: m["type"] == "state" and m["supervisor"]["tripped"])
    check(st and st["supervisor"]["phase"] == "estopped", "a state message on the trip")
    s, _, body = http_get(d, "/api/bench/status", headers={"Authorization": "Bearer " + viewer})
    check(s == 200 and json.loads(body)["supervisor"]["tripped"], "REST status shows the trip")
    seqs = []
    while True:
        ev = recv_until(watcher, lambda m: m["type"] == "event", timeout_s=1)
        if not ev:
            break
        seqs.append(ev["seq"])
    check(len(seqs) == len(set(seqs)) and seqs == sorted(seqs), "each event once, in order (%s)" % seqs)
    ws.send(json.dumps({"op": "request", "id": "r", "method": "POST", "path": "/api/bench/reset"}))
    r = recv_until(ws, lambda m: m["type"] == "reply" and m["id"] == "r")
    check(r and r["status"] in (200, 409), "reset over WS answers (%s)" % (r and r["status"]))
    reset_ok = r and r["status"] == 200
    # A viewer may E-stop over the socket too (every signed-in role may), and is named in the trip.
    vws, vhello = connect(d, viewer)
    vws.send(json.dumps({"op": "request", "id": "vstop", "method": "POST", "path": "/api/bench/estop"}))
    r = recv_until(vws, lambda m: m["type"] == "reply" and m["id"] == "vstop")
    check(r and r["status"] == 200 and r["body"]["supervisor"]["phase"] == "estopped",
          "viewer E-stop over WS -> 200, estopped (%s)" % (r and r["status"]))
    detail = r and (r["body"]["supervisor"].get("trip") or {}).get("detail", "")
    if reset_ok:
        check(detail == "E-stop by %s (viewer)" % vhello["id"], "the trip names the viewer who pressed it (%s)" % detail)
    vws.close()
    ws.send(json.dumps({"op": "request", "id": "r2", "method": "POST", "path": "/api/bench/reset"}))
    recv_until(ws, lambda m: m["type"] == "reply" and m["id"] == "r2")
    ws.close()
    watcher.close()


def test_static(d, web):
    s, r, body = http_get(d, "/")
    check(s == 200 and body == open(os.path.join(web, "index.html"), "rb").read(), "GET / -> index.html")
    check(r.getheader("Content-Type") == "text/html; charset=utf-8" and r.getheader("Cache-Control") == "no-store",
          "index.html: text/html, no-store")
    s, r, body = http_get(d, "/assets/app-1a2b3c.js")
    check(s == 200 and r.getheader("Content-Type").startswith("text/javascript"), "a .js asset: text/javascript")
    check("immutable" in r.getheader("Cache-Control", ""), "a hashed asset is cached immutable")
    etag = r.getheader("ETag")
    check(etag is not None, "assets carry an ETag")
    s, r, body = http_get(d, "/assets/app-1a2b3c.js", headers={"If-None-Match": etag})
    check(s == 304 and body == b"", "If-None-Match -> 304")
    for path, ctype in [("/assets/style-9f.css", "text/css"), ("/favicon.svg", "image/svg+xml"), ("/data.json", "application/json"),
                        ("/blob.bin", "application/octet-stream")]:
        s, r, _ = http_get(d, path)
        check(s == 200 and r.getheader("Content-Type", "").startswith(ctype), "%s -> %s" % (path, ctype))
    s, r, _ = http_get(d, "/favicon.svg")
    check(r.getheader("Cache-Control") == "no-cache", "files outside assets/ are revalidated")
    # The build's gzip beside a file: sent to a client that accepts gzip, the plain file otherwise.
    s, r, body = http_get(d, "/assets/app-1a2b3c.js", headers={"Accept-Encoding": "gzip, deflate"})
    check(s == 200 and r.getheader("Content-Encoding") == "gzip" and r.getheader("Vary") == "Accept-Encoding"
          and gzip.decompress(body) == b"console.log(1)\n", "Accept-Encoding gzip -> the .gz, Content-Encoding gzip, Vary")
    s, r, body = http_get(d, "/assets/app-1a2b3c.js", headers={"Accept-Encoding": "identity"})
    check(s == 200 and r.getheader("Content-Encoding") is None and r.getheader("Vary") == "Accept-Encoding"
          and body == b"console.log(1)\n", "no gzip accepted -> the plain file, Vary")
    s, r, body = http_get(d, "/assets/app-1a2b3c.js", method="HEAD")
    check(s == 200 and body == b"" and int(r.getheader("Content-Length")) > 0, "HEAD: no body, Content-Length of GET")
    s, _, body = http_get(d, "/sweeps/3")
    check(s == 200 and b"<html" in body, "a client-side route without extension -> index.html")
    s, _, _ = http_get(d, "/assets/missing.js")
    check(s == 404, "missing asset -> 404")
    s, _, _ = http_get(d, "/assets/app-1a2b3c.js", method="POST")
    check(s == 405, "POST to a static file -> 405")
    s, _, _ = http_get(d, "/", host="evil.example:%d" % d.port)
    check(s == 403, "static files keep the Host check")
    s, _, body = http_get(d, "/api/nowhere")
    check(s == 404 and b"not_found" in body, "/api/... stays the router's (JSON 404)")
    secret = open(os.path.join(os.path.dirname(web), "secret.txt"), "rb").read()
    index = open(os.path.join(web, "index.html"), "rb").read()
    for path in ["/../secret.txt", "/assets/../../secret.txt", "/%2e%2e/secret.txt", "/%2E%2E/%2e%2e/secret.txt",
                 "/assets/%2e%2e/%2e%2e/secret.txt", "/..%2fsecret.txt", "/assets%2f..%2f..%2fsecret.txt",
                 "/..%5csecret.txt", "/..\\secret.txt", "/link-out.txt", "/link-dir/secret.txt", "/%00", "/%zz",
                 "//etc/passwd", "/etc/passwd"]:
        s, _, body = raw_request(d.port, ["GET %s HTTP/1.1" % path, "Host: " + d.host, "Connection: close"])
        # A path without an extension may get index.html (a client-side route), never more.
        check((s in (400, 404) or (s == 200 and body == index)) and secret not in body and b"root:" not in body,
              "%s -> 400/404, never a file outside the web dir (got %d)" % (path, s))
    s, _, body = http_get(d, "/link-in.txt")
    check(s == 200 and body == b"inside\n", "a symlink inside the web dir is served")


def make_web(tmp):
    web = os.path.join(tmp, "web")
    os.makedirs(os.path.join(web, "assets"))
    files = {"index.html": "<!doctype html><html><body>dashboard</body></html>\n", "assets/app-1a2b3c.js": "console.log(1)\n",
             "assets/style-9f.css": "body{}\n", "favicon.svg": "<svg/>\n", "data.json": "{}\n", "blob.bin": "\x00\x01",
             "inside.txt": "inside\n"}
    for name, text in files.items():
        with open(os.path.join(web, name), "w") as f:
            f.write(text)
    with open(os.path.join(tmp, "secret.txt"), "w") as f:
        f.write("TOP-SECRET-OUTSIDE\n")
    with open(os.path.join(web, "assets/app-1a2b3c.js.gz"), "wb") as f:
        f.write(gzip.compress(b"console.log(1)\n"))
    os.symlink(os.path.join(tmp, "secret.txt"), os.path.join(web, "link-out.txt"))
    os.symlink(tmp, os.path.join(web, "link-dir"))
    os.symlink("inside.txt", os.path.join(web, "link-in.txt"))
    return web


def main():
    tmp = tempfile.mkdtemp(prefix="synbench-ws-")
    web = make_web(tmp)
    d = Daemon(BIN, os.path.join(tmp, "data"), ["--web-dir", web, "--allow-origin", "http://dash.example:5173",
                                                "--allow-origin", "http://other.example"])
    try:
        viewer = d.token("viewer")
        test_upgrade_checks(d)
        test_static(d, web)
        test_protocol_errors(d, viewer)
        test_rates(d, viewer)
        test_auth(d, viewer)
        test_operator(d, viewer)
        test_never_reads(d, viewer)
        rc, err = d.stop()
        check("dropped: one write has been in flight for more than 5000 ms" in err and "send queue is full" not in err,
              "the daemon logs the drop by the write stall, not the queue bound")
        check(rc == 0, "SIGTERM with WebSocket clients -> exit 0 (%s)" % rc)
        check(viewer not in err and d.operator not in err.split("first start")[-1].split("\n", 1)[-1],
              "tokens never logged")
    finally:
        d.stop()

    # No dashboard built: the hint page; env SYNBENCH_WEB_DIR and SYNBENCH_ALLOW_ORIGINS.
    env = dict(os.environ, SYNBENCH_WEB_DIR=os.path.join(tmp, "no-such-dir"), SYNBENCH_ALLOW_ORIGINS="http://a.example, http://b.example:8")
    d = Daemon(BIN, os.path.join(tmp, "data2"), env=env)
    try:
        s, r, body = http_get(d, "/")
        check(s == 404 and b"not built" in body and b"scripts/build.sh" in body and r.getheader("Content-Type").startswith("text/html"),
              "missing web dir: GET / -> the 'not built' page")
        s, _, body = http_get(d, "/sweeps")
        check(b"not built" in body, "missing web dir: a route -> the 'not built' page")
        s, _, _ = http_get(d, "/api/health")
        check(s == 200, "the API answers without a dashboard")
        s, _, _ = raw_request(d.port, upgrade_lines(d.host, origin="http://b.example:8"))
        check(s == 101, "SYNBENCH_ALLOW_ORIGINS origin -> 101 (got %d)" % s)
        s, _, _ = raw_request(d.port, upgrade_lines(d.host, origin="http://dash.example:5173"))
        check(s == 403, "an origin not listed -> 403 (got %d)" % s)
    finally:
        d.stop()
    import subprocess
    r = subprocess.run([BIN, "serve", "--allow-origin", "evil.example/path"], capture_output=True, text=True)
    check(r.returncode == 2 and "--allow-origin" in r.stderr, "a bad --allow-origin: exit 2 naming the flag")

    check.finish("ws test ok")


if __name__ == "__main__":
    main()
