// Open MCT object provider for Rocksteady's dictionary: a root folder "Rocksteady" holding the
// status, events and command views, and one folder per bus channel holding one telemetry point
// per field element, with its units, format, enum names and limits.
/* exported RocksteadyDictionaryPlugin */
function RocksteadyDictionaryPlugin(client) {
  const NS = 'rocksteady';
  const VIEWS = [
    { key: 'status', name: 'Status', type: 'rocksteady.status' },
    { key: 'events', name: 'Events', type: 'rocksteady.events' },
    { key: 'commands', name: 'Commands', type: 'rocksteady.commands' }
  ];
  // Overlay plots of the quantities an operator watches (Open MCT's own plot type, composed of our
  // points): the study's Figure 3 live.
  const PLOTS = [
    { key: 'plot-rate', name: 'Body rate ω̂ (rad/s)', points: ['RS_GNC_TLM.omega_hat_0', 'RS_GNC_TLM.omega_hat_1', 'RS_GNC_TLM.omega_hat_2'] },
    { key: 'plot-attitude', name: 'Attitude q̂ (MRP)', points: ['RS_GNC_TLM.q_hat_0', 'RS_GNC_TLM.q_hat_1', 'RS_GNC_TLM.q_hat_2'] },
    { key: 'plot-fuel', name: 'Fuel used (kg)', points: ['RS_GNC_TLM.fuel_kg', 'RS_PLANT_TRUTH.fuel_used_kg'] }
  ];

  function valueMetadata(channel, p) {
    const value = {
      key: 'value',
      name: p.key,
      units: p.units || undefined,
      format: p.format === 'float' ? 'float' : 'number',
      hints: { range: 1 }
    };
    if (p.enum) {
      value.format = 'enum';
      value.enumerations = client.dictionary.enums[p.enum].map((e) => ({ value: e.value, string: e.name }));
    }
    return [
      { key: 'utc', source: 'utc', name: 'Time', format: 'utc', hints: { domain: 1 } },
      value
    ];
  }

  function pointObject(identifier) {
    const dot = identifier.key.indexOf('.');
    const channel = client.channels[identifier.key.slice(0, dot)];
    const key = identifier.key.slice(dot + 1);
    const p = channel && channel.points[channel.index[key]];
    if (!p) return undefined;
    return {
      identifier: identifier,
      name: p.key + (p.units ? ' (' + p.units + ')' : ''),
      type: 'rocksteady.telemetry',
      location: NS + ':' + channel.channel,
      notes: p.description || '',
      telemetry: {
        values: valueMetadata(channel.channel, p),
        channel: channel.channel,
        key: p.key,
        yellow: p.yellow || null,
        red: p.red || null
      }
    };
  }

  // Open MCT keeps view settings (a plot's series colours, ...) in the object itself: the plots'
  // objects are kept in memory for the session, so their views can mutate them.
  const edited = new Map();
  const objectProvider = {
    update: function (domainObject) {
      edited.set(domainObject.identifier.key, domainObject);
      return Promise.resolve(true);
    },
    create: function (domainObject) {
      edited.set(domainObject.identifier.key, domainObject);
      return Promise.resolve(true);
    },
    get: function (identifier) {
      const k = identifier.key;
      if (edited.has(k)) return Promise.resolve(edited.get(k));
      if (k === 'spacecraft') {
        return Promise.resolve({
          identifier: identifier, name: 'Rocksteady', type: 'folder', location: 'ROOT'
        });
      }
      const view = VIEWS.find((v) => v.key === k);
      if (view) {
        return Promise.resolve({
          identifier: identifier, name: view.name, type: view.type, location: NS + ':spacecraft'
        });
      }
      const plot = PLOTS.find((p) => p.key === k);
      if (plot) {
        return Promise.resolve({
          identifier: identifier,
          name: plot.name,
          type: 'telemetry.plot.overlay',
          location: NS + ':spacecraft',
          composition: plot.points.map((key) => ({ namespace: NS, key: key })),
          configuration: { series: [] }
        });
      }
      if (client.channels[k]) {
        return Promise.resolve({
          identifier: identifier,
          name: client.channels[k].title + ' (' + k + ')',
          type: 'folder',
          location: NS + ':spacecraft'
        });
      }
      return Promise.resolve(pointObject(identifier));
    }
  };

  const compositionProvider = {
    appliesTo: function (domainObject) {
      return domainObject.identifier.namespace === NS && domainObject.type === 'folder';
    },
    load: function (domainObject) {
      const k = domainObject.identifier.key;
      if (k === 'spacecraft') {
        return Promise.resolve(
          VIEWS.concat(PLOTS).map((v) => ({ namespace: NS, key: v.key })).concat(
            client.dictionary.channels.map((c) => ({ namespace: NS, key: c.channel }))));
      }
      const c = client.channels[k];
      return Promise.resolve(c ? c.points.map((p) => ({ namespace: NS, key: c.channel + '.' + p.key })) : []);
    }
  };

  return function install(openmct) {
    openmct.objects.addRoot({ namespace: NS, key: 'spacecraft' });
    openmct.objects.addProvider(NS, objectProvider);
    openmct.composition.addProvider(compositionProvider);
    openmct.types.addType('rocksteady.telemetry', {
      name: 'Rocksteady telemetry point',
      description: 'One field element of a Rocksteady bus channel',
      cssClass: 'icon-telemetry'
    });
    openmct.types.addType('rocksteady.status', {
      name: 'Rocksteady status', description: 'Mode and health at a glance', cssClass: 'icon-gauge'
    });
    openmct.types.addType('rocksteady.events', {
      name: 'Rocksteady events', description: 'Flight events with severities', cssClass: 'icon-list-view'
    });
    openmct.types.addType('rocksteady.commands', {
      name: 'Rocksteady commands', description: 'Command form', cssClass: 'icon-activity'
    });
  };
}
