// rpc.js: JSON-RPC 2.0 over the station's WebSocket (the session's API, docs/api.md), with
// reconnection. The token, when the station needs one, comes from the page's address
// (?token=...) once and is kept for the tab's life.

export class RpcError extends Error {
  constructor(code, message) { super(message); this.code = code; }
}

export function stationToken() {
  const q = new URLSearchParams(location.search);
  const t = q.get('token');
  if (t) {
    sessionStorage.setItem('hexcnc-token', t);
    q.delete('token');   // out of the address bar and the history
    const rest = q.toString();
    history.replaceState(null, '', location.pathname + (rest ? '?' + rest : '') + location.hash);
  }
  return sessionStorage.getItem('hexcnc-token') || '';
}

export class Rpc {
  constructor({ onNotify, onOpen, onClose }) {
    this.onNotify = onNotify; this.onOpen = onOpen; this.onClose = onClose;
    this.nextId = 1; this.pending = new Map(); this.ws = null; this.open = false;
    this.token = stationToken();
  }

  connect() {
    const scheme = location.protocol === 'https:' ? 'wss' : 'ws';
    const q = this.token ? '?token=' + encodeURIComponent(this.token) : '';
    const ws = new WebSocket(`${scheme}://${location.host}/ws${q}`);
    this.ws = ws;
    let reason = '';
    ws.onopen = () => { this.open = true; this.onOpen(); };
    ws.onmessage = (ev) => {
      let m;
      try { m = JSON.parse(ev.data); } catch (e) { return; }
      if (m.method) {
        if (m.method === 'station.disconnected') reason = m.params.reason;
        this.onNotify(m.method, m.params);
        return;
      }
      const p = this.pending.get(m.id);
      if (!p) return;
      this.pending.delete(m.id);
      if (m.error) p.reject(new RpcError(m.error.code, m.error.message));
      else p.resolve(m.result);
    };
    ws.onclose = () => {
      const was = this.open;
      this.open = false;
      for (const p of this.pending.values()) p.reject(new RpcError(-1, 'connection lost'));
      this.pending.clear();
      this.onClose(reason || (was ? 'the station closed the connection'
        : 'the station refused the connection (a token is needed, or the origin is not allowed)'));
      setTimeout(() => this.connect(), 2000);
    };
  }

  call(method, params = {}) {
    if (!this.open) return Promise.reject(new RpcError(-1, 'not connected to the station'));
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      this.pending.set(id, { resolve, reject });
      this.ws.send(JSON.stringify({ jsonrpc: '2.0', id, method, params }));
    });
  }
}
