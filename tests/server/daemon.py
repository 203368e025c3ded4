"""`synbench serve` as a process, for the Python tests (tests/server) and benchmarks (tests/perf):
the daemon on a free loopback port with its data directory and tokens, HTTP requests to it (JSON
or raw bytes), wait_for, a stored sweep to serve. Standard library only, so a test that needs no
WebSocket client does not need python3-websocket (the WebSocket helpers are in ws_util.py).

tests/perf scripts find this module with sys.path.insert(0, <their dir>/../server)."""
import http.client
import json
import os
import queue
import re
import signal
import socket
import subprocess
import threading
import time


def wait_for(pred, timeout_s, period_s=0.02):
    """Polls pred() until it returns a true value (returned) or the time is up (the last value)."""
    deadline = time.monotonic() + timeout_s
    while True:
        v = pred()
        if v or time.monotonic() > deadline:
            return v
        time.sleep(period_s)


class Lines:
    """A process's stdout lines on a queue (read by a thread, so the pipe never fills)."""

    def __init__(self, stream):
        self.q = queue.Queue()
        threading.Thread(target=self._pump, args=(stream,), daemon=True).start()

    def _pump(self, stream):
        for line in stream:
            self.q.put(line.rstrip("\n"))
        self.q.put(None)

    def get(self, timeout):
        try:
            return self.q.get(timeout=timeout)
        except queue.Empty:
            return None


def http_request(port, method, path, body=None, token=None, host=None, headers=None, timeout=10):
    """One request on a connection of its own: (status, body bytes, http.client response). A body
    that is not bytes or str is sent as JSON. Raises OSError / HTTPException when nothing answers."""
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    h = {"Host": host or "127.0.0.1:%d" % port}
    if token:
        h["Authorization"] = "Bearer " + token
    if body is not None and not isinstance(body, (bytes, str)):
        body = json.dumps(body)
    if body is not None:
        h["Content-Type"] = "application/json"
    h.update(headers or {})
    try:
        conn.request(method, path, body=body, headers=h)
        r = conn.getresponse()
        data = r.read()
    finally:
        conn.close()
    return r.status, data, r


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


def send_raw(port, data, timeout=10):
    """Sends raw bytes on a connection of its own; the reply, read until the server closes it."""
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    try:
        s.sendall(data)
        reply = b""
        while True:
            chunk = s.recv(4096)
            if not chunk:
                return reply
            reply += chunk
    finally:
        s.close()


def upgrade_lines(host, origin=None, path="/ws"):
    """The lines of a WebSocket upgrade request (for raw_request or a socket of one's own)."""
    lines = ["GET %s HTTP/1.1" % path]
    if host is not None:
        lines.append("Host: " + host)
    lines += ["Upgrade: websocket", "Connection: Upgrade", "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
              "Sec-WebSocket-Version: 13"]
    if origin is not None:
        lines.append("Origin: " + origin)
    return lines


def run_sweep(binary, plan, db, work_dir, *args, timeout=None):
    """`synbench sweep PLAN --db DB ARGS` with `plan` (a dict) written to work_dir/plan.json: the
    completed process (stdout, stderr as text)."""
    path = os.path.join(work_dir, "plan.json")
    with open(path, "w") as f:
        json.dump(plan, f)
    return subprocess.run([binary, "sweep", path, "--db", db, *args], capture_output=True, text=True, timeout=timeout)


class Daemon:
    """`synbench serve --listen 127.0.0.1:0 --data-dir DATA_DIR EXTRA_ARGS`, its port read from its
    first line. Its stderr: a pipe (default; stop() returns what it wrote), `log_path` (a file
    this object opens and closes), or any `stderr` Popen takes (a file object, DEVNULL).

    port, host ("127.0.0.1:PORT"), url (the WebSocket's), operator (the operator token the first
    start writes to DATA_DIR/operator.token)."""

    def __init__(self, binary, data_dir, extra_args=(), env=None, log_path=None, stderr=subprocess.PIPE,
                 start_timeout_s=60):
        self.binary, self.data_dir, self.extra_args, self.env = binary, data_dir, list(extra_args), env
        self.log = open(log_path, "w") if log_path else None
        self.log_path = log_path
        self.stderr = self.log if self.log else stderr
        self.start_timeout_s = start_timeout_s
        self.start()

    def start(self):
        """Starts (or, after a crash, restarts) the process; raises RuntimeError if it says no port."""
        cmd = [self.binary, "serve", "--listen", "127.0.0.1:0", "--data-dir", self.data_dir, *self.extra_args]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=self.stderr, text=True, env=self.env)
        self.lines = Lines(self.proc.stdout)
        line = self.lines.get(self.start_timeout_s)
        m = re.match(r"listening on http://127\.0\.0\.1:(\d+)", line or "")
        if not m:
            self.kill()
            err = self.proc.stderr.read() if self.stderr == subprocess.PIPE else ""
            if self.log_path:
                err = open(self.log_path, errors="replace").read()[-800:]
            raise RuntimeError("serve did not start: %r %s" % (line, err))
        self.port = int(m.group(1))
        self.host = "127.0.0.1:%d" % self.port
        self.url = "ws://%s/ws" % self.host
        self.operator = open(os.path.join(self.data_dir, "operator.token")).read().strip()

    def token(self, role):
        """A new token of `role` (`synbench token create`)."""
        r = subprocess.run([self.binary, "token", "create", "--role", role, "--data-dir", self.data_dir],
                           capture_output=True, text=True, check=True)
        return r.stdout.strip()

    def http(self, method, path, body=None, token=None, host=None, headers=None, timeout=10):
        """http_request to this daemon: (status, body bytes, response); no token unless given."""
        return http_request(self.port, method, path, body, token, host, headers, timeout)

    def request(self, method, path, body=None, token=None, timeout=30):
        """As the operator unless `token`: (status, parsed JSON or raw bytes); (0, reason) when the
        daemon does not answer."""
        try:
            status, raw, _ = self.http(method, path, body, token or self.operator, timeout=timeout)
        except (OSError, http.client.HTTPException) as e:
            return 0, str(e)
        try:
            return status, json.loads(raw)
        except ValueError:
            return status, raw

    def raw_request_bytes(self, method, path, body=None):
        """The bytes of one operator request, for a caller that sends it on its own socket and times it."""
        data = json.dumps(body).encode() if body is not None else b""
        head = "%s %s HTTP/1.1\r\nHost: %s\r\nAuthorization: Bearer %s\r\nContent-Length: %d\r\n" % (
            method, path, self.host, self.operator, len(data))
        if body is not None:
            head += "Content-Type: application/json\r\n"
        return head.encode() + b"\r\n" + data

    def rss_kB(self):
        with open("/proc/%d/status" % self.proc.pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
        return 0

    def alive(self, settle=False):
        """`settle`: a connection just ended without an answer, which a dying daemon also does:
        give the kernel a moment to report its exit."""
        for _ in range(10 if settle else 1):
            if self.proc.poll() is not None:
                return False
            if settle:
                time.sleep(0.02)
        return True

    def stop(self, read_stderr=True, timeout_s=40):
        """SIGTERM, wait (killed after timeout_s); (exit status, its stderr when that is a pipe
        nobody else reads, else "")."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=timeout_s)
            except subprocess.TimeoutExpired:
                self.kill()
        err = self.proc.stderr.read() if read_stderr and self.stderr == subprocess.PIPE else ""
        if self.log and not self.log.closed:
            self.log.close()
        return self.proc.returncode, err

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        if self.log and not self.log.closed:
            self.log.close()


class PendingRequest:
    """An HTTP request sent on a socket of its own; `poll()` is non-blocking, so a caller can keep
    reading Modbus while the daemon works on it. sent_at: time.monotonic() just before sending."""

    def __init__(self, port, request_bytes):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=10)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.buf = b""
        self.status = None
        self.body = None
        self.answered_at = None
        self.sent_at = time.monotonic()
        self.sock.sendall(request_bytes)
        self.sock.setblocking(False)

    def poll(self):
        """True once the whole response is in."""
        if self.status is not None:
            return True
        try:
            chunk = self.sock.recv(65536)
        except (BlockingIOError, InterruptedError):
            return False
        if chunk:
            self.buf += chunk
        head, sep, body = self.buf.partition(b"\r\n\r\n")
        if sep:
            m = re.search(rb"content-length:\s*(\d+)", head, re.I)
            length = int(m.group(1)) if m else 0
            if len(body) >= length or not chunk:
                self.answered_at = time.monotonic()
                self.status = int(head.split(b" ", 2)[1])
                self.body = body[:length]
                self.sock.close()
                return True
        elif not chunk:
            self.answered_at = time.monotonic()
            self.status = 0
            self.sock.close()
            return True
        return False

    def wait(self, timeout_s):
        deadline = time.monotonic() + timeout_s
        while not self.poll():
            if time.monotonic() > deadline:
                self.sock.close()
                self.status = 0
                return False
            time.sleep(0.001)
        return True
