// REST client: same origin, bearer token, JSON errors as {"error": {"code", "message"}}.
export class ApiError extends Error {
  constructor(status, code, message) {
    super(message || code || `HTTP ${status}`);
    this.status = status;
    this.code = code;
  }
}

let token = null;
let onUnauthorized = () => {};

export function setToken(t) { token = t; }
export function getToken() { return token; }
export function setUnauthorizedHandler(fn) { onUnauthorized = fn; }

// Routes the daemon answers without a token; every other request waits for a sign-in.
const PUBLIC = new Set(['/api/health']);

// api('GET', '/api/sweeps') -> parsed JSON (or text with {text: true}).
export async function api(method, path, body, { text = false, quiet401 = false, timeoutMs = 10000 } = {}) {
  // Before a sign-in nothing is asked of the daemon (a 401 would open the sign-in dialog over a
  // page that is about to sign in with its saved token): the caller gets the refusal locally.
  if (!token && !PUBLIC.has(path.split('?')[0])) throw new ApiError(401, 'signed_out', 'not signed in');
  const headers = {};
  if (token) headers.Authorization = `Bearer ${token}`;
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  const ctl = new AbortController();
  const timer = setTimeout(() => ctl.abort(), timeoutMs);
  let res;
  try {
    res = await fetch(path, { method, headers, body: body === undefined ? undefined : JSON.stringify(body), signal: ctl.signal, cache: 'no-store' });
  } catch (e) {
    throw new ApiError(0, 'network', `cannot reach the daemon (${e.name === 'AbortError' ? 'timeout' : e.message})`);
  } finally {
    clearTimeout(timer);
  }
  const raw = await res.text();
  if (!res.ok) {
    let code = `http_${res.status}`, message = raw.slice(0, 300);
    try {
      const doc = JSON.parse(raw);
      if (doc && doc.error) ({ code, message } = doc.error);
    } catch { /* not JSON */ }
    if (res.status === 401 && !quiet401) onUnauthorized();
    throw new ApiError(res.status, code, message);
  }
  if (text) return raw;
  return raw ? JSON.parse(raw) : null;
}

// Fetches with the token and saves the body as a file (export buttons: the token is a header,
// so a plain link would not do).
export async function download(path, filename, type) {
  const body = await api('GET', path, undefined, { text: true, timeoutMs: 60000 });
  saveBlob(new Blob([body], { type }), filename);
}

export function saveBlob(blob, filename) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = filename;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 5000);
}
