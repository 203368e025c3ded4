"""Helpers shared by the WebSocket, static-file and perf tests of `synbench serve`: a daemon on
a free loopback port, tokens, raw HTTP and the websocket-client module (Debian's
python3-websocket; a pyenv interpreter is pointed at the system's dist-packages)."""
import json
import os
import re
import socket
import subprocess
import sys
import time

try:
    import websocket  # noqa: F401
except ImportError:
    sys.path.append("/usr/lib/python3/dist-packages")
    try:
        import websocket  # noqa: F401
    except ImportError:
        # CI installs it (scripts/debian-packages.txt): there a missing module is a failure.
        print("SKIP: python3-websocket is not installed")
        sys.exit(1 if os.environ.get("CI") else 77)


class Daemon:
    def __init__(self, binary, data_dir, extra_args=(), env=None):
        self.data_dir = data_dir
        self.binary = binary
        self.proc = subprocess.Popen([binary, "serve", "--listen", "127.0.0.1:0", "--data-dir", data_dir, *extra_args],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        line = self.proc.stdout.readline()
        m = re.match(r"listening on http://127\.0\.0\.1:(\d+)", line)
        if not m:
            self.proc.kill()
            raise SystemExit("serve did not start: %r %s" % (line, self.proc.stderr.read()))
        self.port = int(m.group(1))
        self.host = "127.0.0.1:%d" % self.port
        self.url = "ws://%s/ws" % self.host
        self.operator = open(os.path.join(data_dir, "operator.token")).read().strip()

    def token(self, role):
        r = subprocess.run([self.binary, "token", "create", "--role", role, "--data-dir", self.data_dir],
                           capture_output=True, text=True, check=True)
        return r.stdout.strip()

    def rss_kB(self):
        with open("/proc/%d/status" % self.proc.pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
        return 0

    def stop(self, read_stderr=True):
        """SIGTERM, wait; returns (exit status, stderr or "" when someone else reads it)."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        return self.proc.returncode, self.proc.stderr.read() if read_stderr else ""


def raw_request(port, lines, timeout=5):
    """Sends a raw HTTP/1.1 request (a list of lines, without the blank line); returns
    (status, headers dict lower-cased, body bytes read so far)."""
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
    data = b""
    while b"\r\n\r\n" not in data:
        chunk = s.recv(65536)
        if not chunk:
            break
        data += chunk
    head, _, body = data.partition(b"\r\n\r\n")
    status_line, *header_lines = head.decode(errors="replace").split("\r\n")
    headers = {}
    for h in header_lines:
        k, _, v = h.partition(":")
        headers[k.strip().lower()] = v.strip()
    length = int(headers.get("content-length", "0") or 0)
    while len(body) < length:
        chunk = s.recv(65536)
        if not chunk:
            break
        body += chunk
    s.close()
    parts = status_line.split(" ")
    return (int(parts[1]) if len(parts) > 1 and parts[1].isdigit() else 0), headers, body


def upgrade_lines(host, origin=None, path="/ws"):
    lines = ["GET %s HTTP/1.1" % path]
    if host is not None:
        lines.append("Host: " + host)
    lines += ["Upgrade: websocket", "Connection: Upgrade", "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
              "Sec-WebSocket-Version: 13"]
    if origin is not None:
        lines.append("Origin: " + origin)
    return lines


def connect(daemon, token=None, timeout=10, **kw):
    """A websocket-client connection, authenticated when `token` is given (returns it and hello)."""
    ws = websocket.create_connection(daemon.url, timeout=timeout, **kw)
    hello = None
    if token is not None:
        ws.send(json.dumps({"op": "auth", "token": token}))
        hello = json.loads(ws.recv())
    return ws, hello


def recv_until(ws, pred, timeout_s=5):
    """Messages until one satisfies pred (returned); None on timeout or close."""
    deadline = time.time() + timeout_s
    while time.time() < deadline:
        ws.settimeout(max(0.05, deadline - time.time()))
        try:
            raw = ws.recv()
        except websocket.WebSocketTimeoutException:
            return None
        except (websocket.WebSocketConnectionClosedException, ConnectionError):
            return None
        if not raw:
            return None
        m = json.loads(raw)
        if pred(m):
            return m
    return None


def close_code(ws, timeout_s=15):
    """Reads until the server's close frame; its status code, or None if the socket just ended."""
    ws.settimeout(timeout_s)
    deadline = time.time() + timeout_s
    try:
        while time.time() < deadline:
            # recv_frame, not recv_data_frame: the latter answers the close and can fail doing so
            # (the server may already have torn the connection down) before returning it.
            frame = ws.recv_frame()
            if frame.opcode == websocket.ABNF.OPCODE_CLOSE:
                data = frame.data
                return int.from_bytes(data[:2], "big") if len(data) >= 2 else 1005
    except (websocket.WebSocketConnectionClosedException, ConnectionError, OSError):
        return None
    return None
