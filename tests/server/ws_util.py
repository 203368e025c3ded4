"""WebSocket helpers for the tests and benchmarks of `synbench serve` (the daemon itself, tokens
and raw HTTP: daemon.py): the websocket-client module (Debian's python3-websocket; a pyenv
interpreter is pointed at the system's dist-packages; exit 77, skipped, without it), a connection
signed in, messages until one matches, the server's close code, a client that stalls and one
that keeps reading telemetry."""
import json
import os
import socket
import sys
import threading
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


def stalled_client(daemon, token, rate_hz=50):
    """A client that subscribes to telemetry at rate_hz and to events, then reads nothing more: its
    receive buffer is a few KiB, so the daemon's side of the connection fills quickly."""
    ws, hello = connect(daemon, token, sockopt=((socket.SOL_SOCKET, socket.SO_RCVBUF, 4096),))
    ws.send(json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": rate_hz}))
    ws.send(json.dumps({"op": "subscribe", "channel": "events"}))
    recv_until(ws, lambda m: m["type"] == "state")
    return ws, hello


class TelemetryReader:
    """A client that reads telemetry at rate_hz on a thread of its own. times: the arrival of each
    message (time.time()); errors: what ended the connection, if anything did."""

    def __init__(self, daemon, token, rate_hz):
        self.ws, _ = connect(daemon, token)
        self.ws.send(json.dumps({"op": "subscribe", "channel": "telemetry", "rate_hz": rate_hz}))
        recv_until(self.ws, lambda m: m["type"] == "telemetry")
        self.times, self.errors = [], []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def _read(self):
        self.ws.settimeout(1.0)
        while not self._stop.is_set():
            try:
                m = json.loads(self.ws.recv())
            except websocket.WebSocketTimeoutException:
                continue
            except Exception as e:  # noqa: BLE001 - the caller reports it
                self.errors.append(str(e))
                return
            if m["type"] == "telemetry":
                self.times.append(time.time())

    def stop(self):
        self._stop.set()
        self._thread.join(timeout=3)
        self.ws.close()
