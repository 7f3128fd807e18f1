// The browser side of rocksteady-ground serve: the dictionary, one Server-Sent Events stream
// (/api/stream) fanned out to subscribers per point, events, channel ages (staleness), commands.
/* exported RocksteadyClient */
class RocksteadyClient {
  constructor() {
    this.dictionary = null;
    this.pointListeners = new Map();  // "CHANNEL.key" -> Set(callback)
    this.eventListeners = new Set();
    this.statusListeners = new Set();
    this.stats = {};  // channel -> {received, age_ms, stale, last_utc}
    this.latest = {};  // channel -> {utc, values, text}
    this.channels = {};  // channel -> dictionary entry (after start)
    this.staleAfterMs = 3000;
    this.connected = false;
  }

  async start() {
    this.dictionary = await (await fetch('/api/dictionary')).json();
    this.channels = {};
    for (const c of this.dictionary.channels) {
      c.index = {};
      c.points.forEach((p, i) => { c.index[p.key] = i; });
      this.channels[c.channel] = c;
    }
    this.enums = {};
    for (const [name, values] of Object.entries(this.dictionary.enums)) {
      this.enums[name] = {};
      for (const v of values) this.enums[name][v.value] = v.name;
    }
    const latest = await (await fetch('/api/latest')).json();
    this.absorb(latest);
    this.connect();
  }

  connect() {
    this.source = new EventSource('/api/stream');
    this.source.onopen = () => { this.connected = true; this.notifyStatus(); };
    this.source.onerror = () => {
      // The server is gone (or restarting): every channel is stale until it answers again.
      this.connected = false;
      for (const s of Object.values(this.stats)) s.stale = true;
      this.notifyStatus();
    };
    this.source.onmessage = (msg) => this.absorb(JSON.parse(msg.data));
  }

  absorb(msg) {
    if (msg.stale_after_ms) this.staleAfterMs = msg.stale_after_ms;
    for (const [channel, sample] of Object.entries(msg.samples || {})) {
      this.latest[channel] = sample;
      const dict = this.channels[channel];
      if (!dict) continue;
      dict.points.forEach((p, i) => {
        const listeners = this.pointListeners.get(channel + '.' + p.key);
        if (!listeners) return;
        const datum = { id: channel + '.' + p.key, utc: sample.utc, value: sample.values[i] };
        listeners.forEach((cb) => cb(datum));
      });
    }
    for (const e of msg.events || []) this.eventListeners.forEach((cb) => cb(e));
    if (msg.stats) {
      this.stats = msg.stats;
      this.notifyStatus();
    }
  }

  notifyStatus() {
    this.statusListeners.forEach((cb) => cb(this));
  }

  subscribePoint(id, callback) {
    if (!this.pointListeners.has(id)) this.pointListeners.set(id, new Set());
    this.pointListeners.get(id).add(callback);
    return () => this.pointListeners.get(id).delete(callback);
  }

  onEvent(callback) {
    this.eventListeners.add(callback);
    return () => this.eventListeners.delete(callback);
  }

  onStatus(callback) {
    this.statusListeners.add(callback);
    callback(this);
    return () => this.statusListeners.delete(callback);
  }

  // Periodic channels (telemetry, truth, sensors) are stale when silent; occasional ones (events,
  // acknowledgements, commands, uplink) only when the server itself is unreachable.
  isStale(channel) {
    if (!this.connected) return true;
    const c = this.channels[channel];
    if (c && !c.periodic) return false;
    const s = this.stats[channel];
    return !s || s.stale;
  }

  // The newest value of a point, or undefined.
  value(channel, key) {
    const s = this.latest[channel];
    const c = this.channels[channel];
    if (!s || !c || !(key in c.index)) return undefined;
    return s.values[c.index[key]];
  }

  enumName(enumName, value) {
    const e = this.enums[enumName];
    return e && value in e ? e[value] : String(value);
  }

  async history(channel, key, start, end) {
    const url = '/api/history?channel=' + encodeURIComponent(channel) + '&key=' +
      encodeURIComponent(key) + '&start=' + start + '&end=' + end;
    const rows = await (await fetch(url)).json();
    return rows.map((r) => ({ id: channel + '.' + key, utc: r[0], value: r[1] }));
  }

  async events(after) {
    return (await fetch('/api/events?after=' + (after || 0))).json();
  }

  async commands() {
    return (await fetch('/api/commands')).json();
  }

  async send(command, args) {
    const res = await fetch('/api/command', {
      method: 'POST',
      headers: { 'Content-Type': 'application/json' },
      body: JSON.stringify({ command: command, args: args })
    });
    return res.json();
  }

  async runSequence(text) {
    const res = await fetch('/api/sequence', { method: 'POST', body: text });
    return res.json();
  }
}
