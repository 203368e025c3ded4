// The bench seen from the far side, for the browser tests of `synbench serve --bench` on
// `synbench emulate`: a tiny Modbus TCP master over a node socket (functions 3 and 4 only) that
// reads the drives' registers straight from the emulator, and the emulator as a process. What the
// daemon or the page says about the drives is never the evidence here; the registers are.
// Addresses as tests/server/far_side.py (drivers/profiles/*.json, docs/register-map.md: 0-based,
// f32 big-endian words, high word first).
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import net from 'node:net';
import readline from 'node:readline';

export const SYNRM = 1;
export const LOAD = 2;                 // unit ids of the default profiles
export const STATES = ['disabled', 'running', 'stopping', 'faulted'];
const STATE = 0;                       // input 0, u16; input 1: fault code
const SPEED_SETPOINT = 16;             // SynRM holding 16-17, f32 rpm
const TORQUE_SETPOINT = 16;            // load holding 16-17, f32 N m
const SPEED = 16;                      // SynRM input 16-17, f32 rpm

export class ModbusTcp {
  constructor(socket) {
    this.sock = socket;
    this.tid = 0;
    this.buf = Buffer.alloc(0);
    this.waiting = null;
    socket.on('data', (d) => { this.buf = Buffer.concat([this.buf, d]); this.pump(); });
    socket.on('error', (e) => { if (this.waiting) this.waiting.reject(e); });
  }

  static connect(port, host = '127.0.0.1') {
    return new Promise((resolve, reject) => {
      const s = net.createConnection({ port, host }, () => { s.setNoDelay(true); resolve(new ModbusTcp(s)); });
      s.once('error', reject);
    });
  }

  close() { this.sock.destroy(); }

  pump() {
    if (!this.waiting || this.buf.length < 7) return;
    const length = this.buf.readUInt16BE(4);
    if (this.buf.length < 6 + length) return;
    const frame = this.buf.subarray(0, 6 + length);
    this.buf = this.buf.subarray(6 + length);
    const w = this.waiting;
    this.waiting = null;
    clearTimeout(w.timer);
    if (frame.readUInt16BE(0) !== w.tid || frame[6] !== w.unit) w.reject(new Error(`reply to another request (${frame.readUInt16BE(0)})`));
    else if (frame[7] & 0x80) w.reject(new Error(`modbus exception ${frame[8]} to function ${frame[7] & 0x7f}`));
    else w.resolve(frame.subarray(7));
  }

  // Function 3 (holding) or 4 (input): `count` words from `address` of unit `unit`.
  readWords(fn, unit, address, count = 1) {
    if (this.waiting) return Promise.reject(new Error('one request at a time'));
    this.tid = (this.tid + 1) & 0xffff;
    const adu = Buffer.alloc(12);
    adu.writeUInt16BE(this.tid, 0);
    adu.writeUInt16BE(0, 2);
    adu.writeUInt16BE(6, 4);
    adu[6] = unit;
    adu[7] = fn;
    adu.writeUInt16BE(address, 8);
    adu.writeUInt16BE(count, 10);
    return new Promise((resolve, reject) => {
      const timer = setTimeout(() => { this.waiting = null; reject(new Error('no reply within 2 s')); }, 2000);
      this.waiting = { tid: this.tid, unit, resolve, reject, timer };
      this.sock.write(adu);
      this.pump();
    }).then((pdu) => {
      const words = [];
      for (let i = 0; i < pdu[1] / 2; ++i) words.push(pdu.readUInt16BE(2 + 2 * i));
      return words;
    });
  }

  holding(unit, address, count) { return this.readWords(3, unit, address, count); }
  input(unit, address, count) { return this.readWords(4, unit, address, count); }

  async f32(fn, unit, address) {
    const [hi, lo] = await this.readWords(fn, unit, address, 2);
    const b = Buffer.alloc(4);
    b.writeUInt16BE(hi, 0);
    b.writeUInt16BE(lo, 2);
    return b.readFloatBE(0);
  }

  speedSetpointRpm() { return this.f32(3, SYNRM, SPEED_SETPOINT); }
  torqueSetpointNm() { return this.f32(3, LOAD, TORQUE_SETPOINT); }
  speedRpm() { return this.f32(4, SYNRM, SPEED); }
  // [state, fault code] of a drive; state 0 disabled, 1 running, 2 stopping, 3 faulted.
  state(unit) { return this.input(unit, STATE, 2); }
  async states() { return [await this.state(SYNRM), await this.state(LOAD)]; }
}

// `synbench emulate` on a free loopback TCP port; resolves once it listens.
export async function startEmulator(bin, logPath, args = []) {
  const proc = spawn(bin, ['emulate', '--tcp', '127.0.0.1:0', ...args], { stdio: ['ignore', 'pipe', fs.openSync(logPath, 'w')] });
  const rl = readline.createInterface({ input: proc.stdout });
  const port = await new Promise((resolve) => {
    const timer = setTimeout(() => resolve(null), 60000);
    rl.on('line', (l) => {
      const m = /^listening on tcp 127\.0\.0\.1:(\d+)$/.exec(l);
      if (m) { clearTimeout(timer); resolve(Number(m[1])); }
    });
    proc.once('exit', () => { clearTimeout(timer); resolve(null); });
  });
  if (!port) { proc.kill('SIGKILL'); throw new Error(`synbench emulate did not start: ${fs.readFileSync(logPath, 'utf8').slice(-500)}`); }
  return {
    port,
    stop: () => new Promise((resolve) => {
      if (proc.exitCode !== null) { resolve(proc.exitCode); return; }
      proc.once('exit', (code) => resolve(code));
      proc.kill('SIGTERM');
    }),
  };
}

// A bench config of the three default devices on the emulator's TCP port, real time.
export function writeBenchConfig(file, port) {
  const link = { transport: 'tcp', host: '127.0.0.1', port, response_timeout_ms: 200 };
  fs.writeFileSync(file, JSON.stringify({
    _comment: 'written by tests/web/far_side.mjs', time_scale: 1, links: { emu: link },
    devices: Object.fromEntries(['synrm_drive', 'load_drive', 'vfc_meter'].map((k) => [k, { profile: 'default', link: 'emu' }])),
  }, null, 2));
  return file;
}
