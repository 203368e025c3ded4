"""HTTP framing and the store's files, from the far side of `synbench serve` (issue 43; raw
sockets on loopback, no HTTP library in the way):

1. a Transfer-Encoding that does not end in chunked (xchunked, "chunked, identity", gzip), one on
   an HTTP/1.0 request, or beside a Content-Length is answered 400 and the connection closed:
   the body smuggled behind it is never read as a second request; "gzip, chunked" is a 501;
2. Authorization and Host come from the header section only: a chunked trailer's Authorization
   does not sign the request in, a Host only in the trailer is refused, and two Authorization
   headers are a 400 (never "the first wins");
3. a data directory that held a store but lost its database: serve says so loudly at start;
   the database, its -wal and -shm, the telemetry history are created 0600, like the tokens;
4. a WebSocket burst of 4,000 requests for the 40 KB OpenAPI document, sent at once while not
   reading: the session reads on only as its replies are written, so the io thread builds a few
   at a time (GET /api/health answers meanwhile; its worst latency is printed), and a client
   that then reads gets all 4,000 replies instead of being dropped for a full queue.

usage: framing_test.py path/to/synbench"""
import json
import os
import shutil
import socket
import stat
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402
from daemon import Daemon, http_request  # noqa: E402

check = Checks(verbose=True)


def exchange(port, data, timeout=5):
    """Sends `data` on a connection of its own; every byte the daemon answers until it closes the
    connection (or the time is up): (the responses' status codes in order, closed by the daemon)."""
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    s.sendall(data)
    reply, closed = b"", False
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline:
            s.settimeout(max(0.05, deadline - time.monotonic()))
            chunk = s.recv(65536)
            if not chunk:
                closed = True
                break
            reply += chunk
    except socket.timeout:
        pass
    finally:
        s.close()
    codes = []
    for part in reply.split(b"HTTP/1.1 ")[1:]:
        code = part[:3]
        if code.isdigit():
            codes.append(int(code))
    return codes, closed, reply


def smuggling(d, viewer):
    inner = "GET /api/whoami HTTP/1.1\r\nHost: %s\r\nAuthorization: Bearer %s\r\n\r\n" % (d.host, viewer)
    for te, want in (("xchunked", 400), ("chunked, identity", 400), ("gzip", 400), ("identity", 400),
                     ("gzip, chunked", 501)):
        req = "POST /api/health HTTP/1.1\r\nHost: %s\r\nTransfer-Encoding: %s\r\n\r\n%s" % (d.host, te, inner)
        codes, closed, reply = exchange(d.port, req.encode())
        check(codes == [want] and closed and b'"viewer"' not in reply,
              "Transfer-Encoding: %s: one %d and the connection closed, the smuggled request unread (%s, closed %s)"
              % (te, want, codes, closed))
    # Two Transfer-Encoding lines are one list: "chunked" then "identity" ends in identity.
    req = ("POST /api/health HTTP/1.1\r\nHost: %s\r\nTransfer-Encoding: chunked\r\nTransfer-Encoding: identity\r\n\r\n%s"
           % (d.host, inner))
    codes, closed, _ = exchange(d.port, req.encode())
    check(codes == [400] and closed, "two Transfer-Encoding lines ending in identity: 400, closed (%s)" % codes)
    req = "POST /api/health HTTP/1.0\r\nHost: %s\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n%s" % (d.host, inner)
    codes, closed, _ = exchange(d.port, req.encode())
    check(codes == [400] and closed, "Transfer-Encoding on an HTTP/1.0 request: 400, closed (%s)" % codes)
    req = ("POST /api/health HTTP/1.1\r\nHost: %s\r\nTransfer-Encoding: chunked\r\nContent-Length: 5\r\n\r\n0\r\n\r\n%s"
           % (d.host, inner))
    codes, closed, _ = exchange(d.port, req.encode())
    check(codes == [400] and closed, "Transfer-Encoding beside Content-Length: 400, closed (%s)" % codes)
    # A correct chunked request still works, and its connection stays usable for the next one.
    req = ("GET /api/whoami HTTP/1.1\r\nHost: %s\r\nAuthorization: Bearer %s\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n%s"
           % (d.host, viewer, inner))
    codes, _, reply = exchange(d.port, req.encode(), timeout=2)
    check(codes == [200, 200] and reply.count(b'"viewer"') == 2,
          "a chunked request and one after it on the same connection are both answered (%s)" % codes)


def trailers(d, viewer):
    op = d.operator
    req = ("GET /api/whoami HTTP/1.1\r\nHost: %s\r\nTransfer-Encoding: chunked\r\nConnection: close\r\n\r\n"
           "0\r\nAuthorization: Bearer %s\r\n\r\n" % (d.host, op))
    codes, _, reply = exchange(d.port, req.encode())
    check(codes == [401] and b"operator" not in reply,
          "an Authorization only in the chunked trailer signs nothing in: 401 (%s %r)" % (codes, reply[-80:]))
    req = ("GET /api/whoami HTTP/1.1\r\nHost: %s\r\nAuthorization: Bearer %s\r\nTransfer-Encoding: chunked\r\n"
           "Connection: close\r\n\r\n0\r\nAuthorization: Bearer %s\r\n\r\n" % (d.host, viewer, op))
    codes, _, reply = exchange(d.port, req.encode())
    check(codes == [200] and b'"viewer"' in reply and b'"operator"' not in reply,
          "a trailer's Authorization does not replace the header's: still the viewer (%s)" % codes)
    req = ("GET /api/whoami HTTP/1.1\r\nAuthorization: Bearer %s\r\nTransfer-Encoding: chunked\r\nConnection: close\r\n\r\n"
           "0\r\nHost: %s\r\n\r\n" % (viewer, d.host))
    codes, _, reply = exchange(d.port, req.encode())
    check(codes and codes[0] in (400, 403) and b'"viewer"' not in reply,
          "a Host only in the trailer does not pass the Host check (%s)" % codes)
    for first, second in ((viewer, op), (op, viewer)):
        req = ("GET /api/whoami HTTP/1.1\r\nHost: %s\r\nAuthorization: Bearer %s\r\nAuthorization: Bearer %s\r\n\r\n"
               % (d.host, first, second))
        codes, closed, reply = exchange(d.port, req.encode())
        check(codes == [400] and closed and b"more than one Authorization" in reply,
              "two Authorization headers: 400 naming them, closed (%s)" % codes)
    req = "GET /api/whoami HTTP/1.1\r\nHost: %s\r\nHost: %s\r\nAuthorization: Bearer %s\r\n\r\n" % (d.host, d.host, viewer)
    codes, closed, _ = exchange(d.port, req.encode())
    check(codes == [400] and closed, "two Host headers: 400, closed (%s)" % codes)


def store_files(binary, root):
    data = os.path.join(root, "files")
    def file_modes():
        modes = {}
        for name in ("synbench.db", "synbench.db-wal", "synbench.db-shm", "telemetry-history.bin", "tokens.json"):
            p = os.path.join(data, name)
            if os.path.exists(p):
                modes[name] = stat.S_IMODE(os.stat(p).st_mode)
        return modes

    d = Daemon(binary, data)
    try:
        # A stored sweep makes the store's WAL work; the telemetry history is written at the stop.
        st, created = d.request("POST", "/api/sweeps", {"name": "files", "dimensions": {
            "speed_rpm": [300], "load_Nm": [0.5], "angle_deg": [50]}, "window_s": 0.2})
        check(st == 201, "a sweep is stored (%s)" % st)
        running = file_modes()
    finally:
        rc, err = d.stop()
    check("synbench.db-wal" in running and "synbench.db-shm" in running,
          "while serving, the store has its -wal and -shm (%s)" % sorted(running))
    check(all(m == 0o600 for m in running.values()), "while serving, every file is 0600: %s"
          % {k: oct(v) for k, v in running.items()})
    check(rc == 0, "the first daemon stops cleanly (%s)" % rc)
    check("WARNING" not in err, "a new data directory starts without a warning (%r)" % err[-300:])
    modes = file_modes()
    check("synbench.db" in modes and "telemetry-history.bin" in modes, "the store and the history were written (%s)" % sorted(modes))
    check(all(m == 0o600 for m in modes.values()), "every file of the data directory is 0600: %s"
          % {k: oct(v) for k, v in modes.items()})
    # A file an earlier version left 0644 is tightened at the next start.
    os.chmod(os.path.join(data, "synbench.db"), 0o644)
    os.remove(os.path.join(data, "telemetry-history.bin"))
    d = Daemon(binary, data)
    rc, err = d.stop()
    check(stat.S_IMODE(os.stat(os.path.join(data, "synbench.db")).st_mode) == 0o600, "a 0644 database is made 0600 at start")
    check("WARNING" not in err, "a restart with the database in place says nothing (%r)" % err[-300:])
    # The database is lost (deleted, moved): the restart says so, naming what it found.
    os.remove(os.path.join(data, "synbench.db"))
    d = Daemon(binary, data)
    rc, err = d.stop()
    check("WARNING" in err and "synbench.db is missing" in err and "tokens.json" in err,
          "a data directory that lost its database: a loud warning naming the traces (%r)" % err[:400])


def ws_burst(d, viewer):
    import ws_util  # needs python3-websocket; imported here so the rest runs without it
    ws, hello = ws_util.connect(d, viewer)
    check(hello and hello.get("type") == "hello", "the viewer's socket is signed in (%s)" % (hello or {}).get("type"))
    n = 4000
    frames = [json.dumps({"op": "request", "id": i, "method": "GET", "path": "/api/openapi.json"}) for i in range(n)]
    sent = threading.Event()

    # At once, as one write: the daemon finds thousands of whole messages in one read.
    burst_bytes = b"".join(ws_util.websocket.ABNF.create_frame(f, ws_util.websocket.ABNF.OPCODE_TEXT).format() for f in frames)

    def burst():
        ws.sock.sendall(burst_bytes)
        sent.set()

    threading.Thread(target=burst, daemon=True).start()
    # /api/health while the burst is read: the io thread must not be held by building replies.
    worst_ms, probes = 0.0, 0
    end = time.monotonic() + 1.5
    while time.monotonic() < end:
        t0 = time.monotonic()
        st, _, _ = http_request(d.port, "GET", "/api/health")
        worst_ms = max(worst_ms, (time.monotonic() - t0) * 1000)
        probes += st == 200
        time.sleep(0.01)
    print("health under the burst: worst %.1f ms over %d probes" % (worst_ms, probes), flush=True)
    check(probes > 20 and worst_ms < 100, "GET /api/health answers during the burst (worst %.1f ms of %d)" % (worst_ms, probes))
    # Now read: every request is answered, and the session was not dropped for a full queue.
    got, ids = 0, set()
    ws.settimeout(20)
    deadline = time.monotonic() + 60
    try:
        while got < n and time.monotonic() < deadline:
            m = json.loads(ws.recv())
            if m.get("type") == "reply":
                got += 1
                ids.add(m.get("id"))
                if m.get("status") != 200:
                    check(False, "reply %s: status %s" % (m.get("id"), m.get("status")))
                    break
    except Exception as e:  # noqa: BLE001 (a drop shows as a closed socket)
        print("reading replies ended: %r" % e, flush=True)
    check(sent.is_set(), "the client's 4,000 messages were all sent")
    check(got == n and len(ids) == n, "all %d requests were answered, the session kept (%d replies)" % (n, got))
    ws.close()


def main():
    binary = sys.argv[1]
    root = tempfile.mkdtemp(prefix="synbench-framing-")
    try:
        d = Daemon(binary, os.path.join(root, "data"))
        try:
            viewer = d.token("viewer")
            smuggling(d, viewer)
            trailers(d, viewer)
            ws_burst(d, viewer)
            st, _, _ = http_request(d.port, "GET", "/api/health")
            check(st == 200 and d.alive(), "the daemon still answers after all of it")
        finally:
            d.stop()
        store_files(binary, root)
    finally:
        shutil.rmtree(root, ignore_errors=True)
    check.finish("framing test ok")


if __name__ == "__main__":
    main()
