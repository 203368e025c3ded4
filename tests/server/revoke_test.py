#!/usr/bin/env python3
"""A revoked token (removed from DATA_DIR/tokens.json while the daemon runs) ends its open
WebSocket session within a couple of seconds and is refused over HTTP at once; failed sign-ins
are logged on stderr with the client's address, rate-limited (50 bad tokens: one or two lines).
Exit 77 without python3-websocket (ws_util.py; 1 under CI)."""
import http.client
import json
import os
import shutil
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402
from daemon import Daemon  # noqa: E402
from ws_util import close_code, connect, recv_until  # noqa: E402

BIN = sys.argv[1]
check = Checks(verbose=True)


def main():
    tmp = tempfile.mkdtemp(prefix="synbench_revoke_")
    d = Daemon(BIN, os.path.join(tmp, "data"))
    try:
        viewer = d.token("viewer")
        ws, hello = connect(d, viewer)
        check(hello and hello.get("type") == "hello" and hello.get("role") == "viewer", "the viewer signs in (%s)" % hello)
        ws.send(json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": 10}))
        check(recv_until(ws, lambda m: m.get("type") == "telemetry", 5) is not None, "telemetry streams")

        # Revoke: keep every token but the viewer's in the file, as an operator would by hand.
        path = os.path.join(d.data_dir, "tokens.json")
        doc = json.load(open(path))
        doc["tokens"] = [t for t in doc["tokens"] if t["role"] != "viewer"]
        with open(path + ".new", "w") as f:
            json.dump(doc, f)
        os.replace(path + ".new", path)
        t0 = time.time()
        m = recv_until(ws, lambda m: m.get("type") == "error", 5)
        code = close_code(ws, 5)
        took = time.time() - t0
        check(m is not None and m.get("code") == "unauthorized" and "revoked" in m.get("message", "") and code == 1008
              and took < 3, "the revoked token's WebSocket is told and closed 1008 (%.1f s, %s, %s)" % (took, m, code))
        conn = http.client.HTTPConnection("127.0.0.1", d.port, timeout=10)
        conn.request("GET", "/api/bench/status", headers={"Host": d.host, "Authorization": "Bearer " + viewer})
        r = conn.getresponse()
        r.read()
        check(r.status == 401, "... and refused over HTTP (%s)" % r.status)
        for i in range(50):
            conn.request("GET", "/api/bench/status", headers={"Host": d.host, "Authorization": "Bearer sbt_wrong%d" % i})
            conn.getresponse().read()
        conn.close()
    finally:
        code, err = d.stop()
        shutil.rmtree(tmp, ignore_errors=True)
    lines = [line for line in err.splitlines() if "failed sign-in" in line]
    check(1 <= len(lines) <= 2 and "127.0.0.1" in lines[0],
          "failed sign-ins logged with the client's address, rate-limited: %d lines for 51 (%s)" % (len(lines), lines[:2]))
    check(code == 0, "SIGTERM -> exit 0")
    check.finish("all checks passed")


if __name__ == "__main__":
    main()
