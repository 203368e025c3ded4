"""The bench seen from the far side, for tests and benchmarks of `synbench serve --bench` on
`synbench emulate`: a small Modbus TCP master of its own (standard library only) that reads the
drives' registers straight from the emulator, the emulator as a process, socat pseudo-terminal
pairs, bench configs (the daemon itself: daemon.py). What the daemon says about the drives is
never taken as evidence here; the registers are.

Register addresses and scalings: drivers/profiles/*.json, docs/register-map.md (0-based
protocol addresses; f32 and u32 big-endian words, high word first)."""
import json
import os
import re
import signal
import socket
import struct
import subprocess
import time

from daemon import Lines

SYNRM, LOAD = 1, 2  # unit ids of the default profiles
STATES = {0: "disabled", 1: "running", 2: "stopping", 3: "faulted"}
FAULTS = {0: "none", 1: "overcurrent", 2: "overvoltage", 3: "undervoltage", 4: "overspeed",
          5: "overtemperature", 6: "watchdog", 7: "estop", 8: "link_loss", 9: "load_drive"}
DISABLED, RUNNING, STOPPING, FAULTED = 0, 1, 2, 3
WATCHDOG = 6

# (function code, address, words) of the signals read here, both drives unless noted.
STATE = 0             # input 0, u16 (0 disabled, 1 running, 2 stopping, 3 faulted); input 1: fault_code
HEARTBEAT = 0         # holding 0, u16 (write-only for the bench; the firmware reads it back)
ENABLE_COIL = 0       # coil 0
SPEED_SETPOINT = 16   # SynRM holding 16-17, f32 rpm
ANGLE_SETPOINT = 18   # SynRM holding 18, i16, 0.01 deg
TORQUE_SETPOINT = 16  # load holding 16-17, f32 N m
SPEED = 16            # SynRM input 16-17, f32 rpm
TORQUE = 16           # load input 16-17, f32 N m
UDC = 30              # SynRM input 30, u16, 0.1 V


class ModbusError(Exception):
    pass


def f32(hi, lo):
    return struct.unpack(">f", struct.pack(">HH", hi, lo))[0]


def f32_words(value):
    return list(struct.unpack(">HH", struct.pack(">f", value)))


class ModbusTcp:
    """One Modbus TCP connection: function codes 1, 2, 3, 4 (reads), 5 and 16 (writes)."""

    def __init__(self, port, host="127.0.0.1", timeout=2.0):
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.tid = 0

    def close(self):
        self.sock.close()

    def _recv(self, n):
        data = b""
        while len(data) < n:
            chunk = self.sock.recv(n - len(data))
            if not chunk:
                raise ModbusError("connection closed")
            data += chunk
        return data

    def _call(self, unit, pdu):
        self.tid = (self.tid + 1) & 0xFFFF
        self.sock.sendall(struct.pack(">HHHB", self.tid, 0, len(pdu) + 1, unit) + pdu)
        tid, pid, length, u = struct.unpack(">HHHB", self._recv(7))
        body = self._recv(length - 1)
        if tid != self.tid or pid != 0 or u != unit:
            raise ModbusError("reply of transaction %d unit %d to %d unit %d" % (tid, u, self.tid, unit))
        if body[0] & 0x80:
            raise ModbusError("exception %d to function %d" % (body[1], pdu[0]))
        return body

    def read_bits(self, fn, unit, address, count=1):
        body = self._call(unit, struct.pack(">BHH", fn, address, count))
        return [(body[2 + i // 8] >> (i % 8)) & 1 for i in range(count)]

    def read_words(self, fn, unit, address, count=1):
        body = self._call(unit, struct.pack(">BHH", fn, address, count))
        return list(struct.unpack(">%dH" % count, body[2:2 + 2 * count]))

    def coils(self, unit, address, count=1):
        return self.read_bits(1, unit, address, count)

    def discrete_inputs(self, unit, address, count=1):
        return self.read_bits(2, unit, address, count)

    def holding(self, unit, address, count=1):
        return self.read_words(3, unit, address, count)

    def input(self, unit, address, count=1):
        return self.read_words(4, unit, address, count)

    def write_coil(self, unit, address, on):
        self._call(unit, struct.pack(">BHH", 5, address, 0xFF00 if on else 0))

    def write_words(self, unit, address, words):
        self._call(unit, struct.pack(">BHHB", 16, address, len(words), 2 * len(words))
                   + struct.pack(">%dH" % len(words), *words))

    # The signals, decoded.
    def state(self, unit):
        """(state, fault_code) of a drive."""
        s, f = self.input(unit, STATE, 2)
        return s, f

    def states(self):
        """((SynRM state, fault), (load state, fault))."""
        return self.state(SYNRM), self.state(LOAD)

    def heartbeats(self):
        return self.holding(SYNRM, HEARTBEAT)[0], self.holding(LOAD, HEARTBEAT)[0]

    def speed_rpm(self):
        return f32(*self.input(SYNRM, SPEED, 2))

    def torque_Nm(self):
        return f32(*self.input(LOAD, TORQUE, 2))

    def speed_setpoint_rpm(self):
        return f32(*self.holding(SYNRM, SPEED_SETPOINT, 2))

    def angle_setpoint_deg(self):
        raw = self.holding(SYNRM, ANGLE_SETPOINT)[0]
        return (raw - 65536 if raw >= 32768 else raw) * 0.01

    def torque_setpoint_Nm(self):
        return f32(*self.holding(LOAD, TORQUE_SETPOINT, 2))

    def udc_V(self):
        return self.input(SYNRM, UDC)[0] * 0.1


def describe(states):
    (s1, f1), (s2, f2) = states
    return "synrm %s/%s, load %s/%s" % (STATES.get(s1, s1), FAULTS.get(f1, f1), STATES.get(s2, s2), FAULTS.get(f2, f2))


class Emulator:
    """`synbench emulate` with its TCP link on a free loopback port (and RTU when asked)."""

    def __init__(self, binary, log_path, rtu=None, args=(), start_timeout_s=60):
        cmd = [binary, "emulate", "--tcp", "127.0.0.1:0", *args]
        if rtu:
            cmd += ["--rtu", rtu, "--baud", "115200"]
        self.log = open(log_path, "w")
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=self.log, text=True)
        self.lines = Lines(self.proc.stdout)
        self.port = None
        self.banner = []
        want = 2 if rtu else 1
        deadline = time.time() + start_timeout_s
        while len(self.banner) < want and time.time() < deadline:
            line = self.lines.get(max(0.1, deadline - time.time()))
            if line is None:
                break
            self.banner.append(line)
            m = re.match(r"listening on tcp 127\.0\.0\.1:(\d+)$", line)
            if m:
                self.port = int(m.group(1))
        if self.port is None or (rtu and "listening on rtu " + rtu not in self.banner):
            self.stop()
            raise RuntimeError("emulate did not start: %s (%s)" % (self.banner, open(log_path).read()[-500:]))

    def stop(self):
        """SIGTERM; returns the exit status and the rest of its stdout."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        out = []
        while True:
            line = self.lines.get(2)
            if line is None:
                break
            out.append(line)
        self.log.close()
        return self.proc.returncode, out


class SocatPair:
    def __init__(self, directory, name="rtu"):
        self.a, self.b = os.path.join(directory, name + "_a"), os.path.join(directory, name + "_b")
        self.proc = subprocess.Popen(["socat", "pty,raw,echo=0,link=" + self.a, "pty,raw,echo=0,link=" + self.b],
                                     stderr=subprocess.DEVNULL)
        deadline = time.time() + 10
        while time.time() < deadline and not (os.path.exists(self.a) and os.path.exists(self.b)):
            time.sleep(0.01)
        if not (os.path.exists(self.a) and os.path.exists(self.b)):
            self.stop()
            raise RuntimeError("socat made no pty pair")

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            self.proc.wait(timeout=10)


def write_bench_config(path, link):
    """A bench config on one link, real time (the emulator runs at 1x too)."""
    with open(path, "w") as f:
        json.dump({"_comment": "written by tests/server/far_side.py", "time_scale": 1,
                   "links": {"emu": link},
                   "devices": {k: {"profile": "default", "link": "emu"} for k in ("synrm_drive", "load_drive", "vfc_meter")}},
                  f, indent=2)
    return path


def tcp_link(port):
    return {"transport": "tcp", "host": "127.0.0.1", "port": port, "response_timeout_ms": 200}


def rtu_link(device):
    # A timeout is followed by a drain until the line is quiet: tens of ms, not the default 200
    # (docs/modbus.md), or two lost replies in a tick cost the 0.5 s telemetry deadline.
    return {"transport": "rtu", "device": device, "baud": 115200, "response_timeout_ms": 200, "quiet_ms": 20}
