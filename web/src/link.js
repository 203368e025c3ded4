// The live link to the daemon: the /ws WebSocket (auth, subscribe telemetry/sweep/events, request
// replies), reconnecting with backoff when it closes (daemon restart). While the socket is down
// the bench status is polled over REST, so the page stays live (and keeps working against a
// daemon without /ws). Connection states: connecting, connected (WebSocket), polling (REST
// only), offline (nothing answers).
import { api, getToken } from './api.js';

const TELEMETRY_HZ = 20;

export class Link {
  constructor(handlers) {
    this.h = handlers;          // {state, telemetry, sweep, event, status, hello, unauthorized, restored}
    this.ws = null;
    this.state = 'offline';
    this.backoff = 500;
    this.timer = null;
    this.pollTimer = null;
    this.pollBusy = false;
    this.nextId = 1;
    this.pending = new Map();
    this.wasDown = false;
    this.stopped = true;
  }

  start() {
    this.stopped = false;
    this.connect();
    this.startPolling();
  }

  stop() {
    this.stopped = true;
    clearTimeout(this.timer);
    this.stopPolling();
    if (this.ws) { this.ws.onclose = null; this.ws.close(); this.ws = null; }
    this.setState('offline');
  }

  setState(s) {
    if (s === this.state) return;
    const prev = this.state;
    this.state = s;
    if (s === 'offline' || s === 'connecting') { if (prev === 'connected' || prev === 'polling') this.wasDown = true; }
    this.h.state?.(s);
    if ((s === 'connected' || s === 'polling') && this.wasDown) {
      this.wasDown = false;
      this.h.restored?.();
    }
  }

  connect() {
    if (this.stopped) return;
    clearTimeout(this.timer);
    const url = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`;
    let ws;
    try { ws = new WebSocket(url); } catch { this.scheduleReconnect(); return; }
    this.ws = ws;
    let greeted = false;
    if (this.state === 'offline') this.setState('connecting');
    ws.onopen = () => ws.send(JSON.stringify({ op: 'auth', token: getToken() }));
    ws.onmessage = (m) => {
      let msg;
      try { msg = JSON.parse(m.data); } catch { return; }
      switch (msg.type) {
        case 'hello':
          greeted = true;
          this.backoff = 500;
          this.stopPolling();
          this.setState('connected');
          for (const sub of [{ channel: 'telemetry', rate_hz: TELEMETRY_HZ }, { channel: 'sweep' }, { channel: 'events' }])
            ws.send(JSON.stringify({ op: 'subscribe', ...sub }));
          this.h.hello?.(msg);
          break;
        case 'telemetry': this.h.telemetry?.(msg); break;
        case 'sweep': this.h.sweep?.(msg); break;
        case 'event': this.h.event?.(msg); break;
        case 'state': this.h.status?.(msg); break;
        case 'reply': {
          const p = this.pending.get(msg.id);
          if (p) { this.pending.delete(msg.id); p(msg); }
          break;
        }
        case 'error':
          if (msg.code === 'unauthorized') { this.stopped = true; this.h.unauthorized?.(); }
          break;
        default: break;
      }
    };
    ws.onclose = () => {
      if (this.ws === ws) this.ws = null;
      for (const [, p] of this.pending) p({ status: 0, body: { error: { code: 'network', message: 'connection closed' } } });
      this.pending.clear();
      if (this.stopped) return;
      if (this.state === 'connected') this.setState('connecting');
      this.startPolling();
      this.scheduleReconnect();
    };
    ws.onerror = () => { /* onclose follows */ };
  }

  scheduleReconnect() {
    if (this.stopped) return;
    clearTimeout(this.timer);
    const delay = this.backoff;
    this.backoff = Math.min(this.backoff * 2, 8000);
    this.timer = setTimeout(() => this.connect(), delay * (0.8 + Math.random() * 0.4));
  }

  // REST fallback: the status every 250 ms as telemetry; also tells "offline" from "polling".
  startPolling() {
    if (this.pollTimer || this.stopped) return;
    const tick = async () => {
      if (this.pollBusy) return;
      this.pollBusy = true;
      try {
        const st = await api('GET', '/api/bench/status', undefined, { timeoutMs: 2000 });
        if (this.state !== 'connected') this.setState('polling');
        this.h.status?.(st);
        this.h.telemetry?.(statusToTelemetry(st));
      } catch (e) {
        if (e.status === 401) { this.stopped = true; this.stopPolling(); this.h.unauthorized?.(); }
        else if (this.state !== 'connected') this.setState('offline');
      } finally {
        this.pollBusy = false;
      }
    };
    this.pollTimer = setInterval(tick, 250);
    tick();
  }

  stopPolling() { clearInterval(this.pollTimer); this.pollTimer = null; }

  // A command over the socket when it is up ({"op":"request"} -> {"type":"reply"}), else REST.
  async request(method, path, body) {
    if (this.ws && this.state === 'connected' && this.ws.readyState === WebSocket.OPEN) {
      const id = this.nextId++;
      const reply = await new Promise((resolve) => {
        this.pending.set(id, resolve);
        this.ws.send(JSON.stringify({ op: 'request', id, method, path, body: body ?? {} }));
        setTimeout(() => { if (this.pending.delete(id)) resolve(null); }, 5000);
      });
      if (reply && reply.status >= 200 && reply.status < 300) return reply.body;
      if (reply && reply.status > 0) {
        const err = reply.body?.error || {};
        const e = new Error(err.message || `HTTP ${reply.status}`);
        e.status = reply.status; e.code = err.code;
        throw e;
      }
      // no reply: fall through to REST
    }
    return api(method, path, body ?? {});
  }
}

// A fault's name, with the device's own code when its profile has no label for it
// ("unknown (device code 6)", as the bench's events say it): status fault_code_raw.
export function faultText(fault, codeRaw) {
  return codeRaw == null ? fault : `${fault} (device code ${codeRaw})`;
}

export function statusToTelemetry(st) {
  const s = st.synrm || {};
  const fault = st.supervisor?.trip?.fault || (s.fault && s.fault !== 'none' ? s.fault : null)
    || (st.load?.fault && st.load.fault !== 'none' ? st.load.fault : null);
  return {
    type: 'telemetry', source: 'rest', t_s: st.t_s, enabled: st.enabled, phase: st.supervisor?.phase,
    speed_rpm: s.speed_rpm ?? null, torque_Nm: st.load?.torque_Nm ?? null,
    im_A: s.im_A ?? null, id_A: s.id_A ?? null, iq_A: s.iq_A ?? null, udc_V: s.udc_V ?? null,
    pac_W: s.pac_W ?? null, pdcm_W: s.pdcm_W ?? null, temp_C: s.temp_C ?? null, pos_err_deg: s.pos_err_deg ?? null,
    voltage_limited: !!s.voltage_limited, lock_lost: !!s.lock_lost, fault,
  };
}
