// Open MCT telemetry providers for Rocksteady: historical requests (GET /api/history), real-time
// subscriptions (the client's event stream), limits (yellow/red from the dictionary) and staleness
// (a channel without a message for longer than the server's --stale-after).
/* exported RocksteadyTelemetryPlugin */
function RocksteadyTelemetryPlugin(client) {
  const isPoint = (o) => o.type === 'rocksteady.telemetry';

  const LIMITS = {
    rh: { cssClass: 'is-limit--upr is-limit--red', name: 'Red High' },
    rl: { cssClass: 'is-limit--lwr is-limit--red', name: 'Red Low' },
    yh: { cssClass: 'is-limit--upr is-limit--yellow', name: 'Yellow High' },
    yl: { cssClass: 'is-limit--lwr is-limit--yellow', name: 'Yellow Low' }
  };

  // 'rh', 'rl', 'yh', 'yl' or undefined for a value against [low, high] pairs (null: no bound).
  function limitState(t, v) {
    if (v === null || v === undefined || Number.isNaN(v)) return undefined;
    const out = (b, side) => b && b[side] !== null && (side === 0 ? v < b[0] : v > b[1]);
    if (out(t.red, 1)) return 'rh';
    if (out(t.red, 0)) return 'rl';
    if (out(t.yellow, 1)) return 'yh';
    if (out(t.yellow, 0)) return 'yl';
    return undefined;
  }

  const provider = {
    supportsRequest: isPoint,
    request: function (domainObject, options) {
      const t = domainObject.telemetry;
      return client.history(t.channel, t.key, options.start, options.end);
    },
    supportsSubscribe: isPoint,
    subscribe: function (domainObject, callback) {
      const t = domainObject.telemetry;
      return client.subscribePoint(t.channel + '.' + t.key, callback);
    },
    supportsLimits: function (o) {
      return isPoint(o) && Boolean(o.telemetry.yellow || o.telemetry.red);
    },
    getLimitEvaluator: function (domainObject) {
      return {
        evaluate: function (datum) {
          const s = limitState(domainObject.telemetry, datum.value);
          return s ? LIMITS[s] : undefined;
        }
      };
    },
    getLimits: function (domainObject) {
      const t = domainObject.telemetry;
      const band = (b, color) => {
        const out = {};
        if (b && b[0] !== null) out.low = { color: color, value: b[0] };
        if (b && b[1] !== null) out.high = { color: color, value: b[1] };
        return out;
      };
      return {
        limits: function () {
          const l = {};
          if (t.yellow) l.WARNING = band(t.yellow, 'yellow');
          if (t.red) l.CRITICAL = band(t.red, 'red');
          return Promise.resolve(l);
        }
      };
    },
    supportsStaleness: isPoint,
    isStale: function (domainObject) {
      return Promise.resolve({ isStale: client.isStale(domainObject.telemetry.channel), utc: Date.now() });
    },
    subscribeToStaleness: function (domainObject, callback) {
      const channel = domainObject.telemetry.channel;
      let last;
      return client.onStatus(() => {
        const stale = client.isStale(channel);
        if (stale !== last) {
          last = stale;
          callback({ isStale: stale, utc: Date.now() });
        }
      });
    }
  };

  RocksteadyTelemetryPlugin.limitState = limitState;
  return function install(openmct) {
    openmct.telemetry.addProvider(provider);
  };
}
