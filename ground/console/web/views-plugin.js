// Open MCT views for Rocksteady: status (mode and health at a glance, link/staleness), events
// (names and severities; ERROR and FATAL red, WARNING yellow) and the command form (every command
// goes through the server's command gate and shows the flight's acknowledgement). A status-bar
// indicator shows mode and link on every page.
/* exported RocksteadyViewsPlugin */
function RocksteadyViewsPlugin(client) {
  const TLM = 'RS_GNC_TLM';

  function el(tag, attrs, text) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
    if (text !== undefined) e.textContent = text;
    return e;
  }

  function fmt(v, digits) {
    if (v === undefined || v === null) return '—';
    return Number(v).toPrecision(digits || 4);
  }

  function ageText(s) {
    if (!s || s.age_ms === null || s.age_ms === undefined) return 'never heard';
    return (s.age_ms / 1000).toFixed(1) + ' s ago';
  }

  // The limit class of a point's value, from the dictionary.
  function limitClass(channel, key, v) {
    const c = client.channels[channel];
    const p = c && c.points[c.index[key]];
    const s = p && RocksteadyTelemetryPlugin.limitState(p, v);
    return s ? (s[0] === 'r' ? 'rs-red' : 'rs-yellow') : 'rs-nominal';
  }

  function statusView(element) {
    const root = el('div', { class: 'rs-status' });
    const link = el('div', { id: 'rs-link', class: 'rs-link' });
    const tiles = el('div', { class: 'rs-tiles' });
    const table = el('table', { class: 'rs-channels' });
    root.append(link, tiles, el('h3', {}, 'Channels'), table);
    element.appendChild(root);

    const tile = (id, label) => {
      const t = el('div', { class: 'rs-tile', id: 'rs-tile-' + id });
      t.append(el('div', { class: 'rs-tile-label' }, label), el('div', { class: 'rs-tile-value' }, '—'));
      tiles.appendChild(t);
      return (text, cls) => {
        t.querySelector('.rs-tile-value').textContent = text;
        t.className = 'rs-tile ' + (cls || 'rs-nominal');
      };
    };
    const mode = tile('mode', 'Mode');
    const law = tile('law', 'Law / phase');
    const rate = tile('rate', '|ω̂| (rad/s)');
    const fuel = tile('fuel', 'Fuel used (kg, on-board)');
    const sat = tile('saturated', 'Allocator');
    const cmds = tile('commands', 'Commands accepted / rejected');
    const health = tile('health', 'Bus rejects / events dropped');
    const clock = tile('time', 'On-board time (s)');

    const update = () => {
      const s = client.stats[TLM];
      const stale = client.isStale(TLM);
      link.className = 'rs-link ' + (stale ? 'rs-stale' : 'rs-live');
      link.textContent = !client.connected ? 'STALE — no connection to the ground server'
        : stale ? 'STALE — no flight telemetry (' + TLM + ' ' + ageText(s) + ')'
          : 'LIVE — flight telemetry ' + ageText(s);
      const v = (k) => client.value(TLM, k);
      if (v('mode') !== undefined) {
        const m = client.enumName('mode', v('mode'));
        mode(m, m === 'SAFE' ? 'rs-red' : 'rs-nominal');
        law(client.enumName('law', v('law')) + ' / ' + client.enumName('phase', v('phase')));
        const w = Math.hypot(v('omega_hat_0'), v('omega_hat_1'), v('omega_hat_2'));
        const worst = ['omega_hat_0', 'omega_hat_1', 'omega_hat_2'].map((k) => limitClass(TLM, k, v(k)));
        rate(fmt(w), worst.includes('rs-red') ? 'rs-red' : worst.includes('rs-yellow') ? 'rs-yellow' : 'rs-nominal');
        fuel(fmt(v('fuel_kg')), limitClass(TLM, 'fuel_kg', v('fuel_kg')));
        sat(v('saturated') ? 'SATURATED (scale ' + fmt(v('alloc_scale'), 3) + ')' : 'within limits',
          v('saturated') ? 'rs-yellow' : 'rs-nominal');
        cmds(v('cmd_accepted') + ' / ' + v('cmd_rejected') +
          (v('cmd_rejected') > 0 ? ' (last: ' + client.enumName('reason', v('cmd_last_reject')) + ')' : ''),
        limitClass(TLM, 'cmd_rejected', v('cmd_rejected')));
        const rx = v('rx_malformed') + v('rx_bad_kind') + v('rx_out_of_range');
        health(rx + ' / ' + v('events_dropped'), v('events_dropped') > 0 ? 'rs-red' : rx > 0 ? 'rs-yellow' : 'rs-nominal');
        clock(fmt(v('t'), 8));
      }
      table.replaceChildren(el('tr', {}, ''));
      table.firstChild.append(el('th', {}, 'channel'), el('th', {}, 'messages'), el('th', {}, 'rejected'),
        el('th', {}, 'last'), el('th', {}, 'state'));
      for (const c of client.dictionary.channels) {
        const st = client.stats[c.channel] || {};
        const row = el('tr', { class: client.isStale(c.channel) ? 'rs-row-stale' : 'rs-row-live' });
        row.append(el('td', {}, c.channel), el('td', {}, String(st.received || 0)),
          el('td', {}, String(st.rejected || 0)), el('td', {}, ageText(st)),
          el('td', {}, client.isStale(c.channel) ? 'STALE' : c.periodic ? 'live' : 'on occasion'));
        table.appendChild(row);
      }
    };
    return client.onStatus(update);
  }

  function eventsView(element) {
    const root = el('div', { class: 'rs-events' });
    const table = el('table', { id: 'rs-events-table' });
    const head = el('tr');
    for (const h of ['received (UTC)', 't (s)', 'severity', 'event', 'arg0', 'arg1', 'text']) head.append(el('th', {}, h));
    table.append(head);
    root.append(table);
    element.appendChild(root);
    let newest = 0;
    const add = (e) => {
      if (e.index <= newest) return;
      newest = e.index;
      const row = el('tr', { class: 'rs-event rs-sev-' + e.severity_name, 'data-event': e.name });
      row.append(el('td', {}, new Date(e.utc).toISOString().slice(11, 23)), el('td', {}, fmt(e.t, 8)),
        el('td', { class: 'rs-sev' }, e.severity_name), el('td', {}, e.name + ' (' + e.id + ')'),
        el('td', {}, String(e.arg0)), el('td', {}, String(e.arg1)), el('td', {}, e.text));
      head.after(row);  // newest first
      while (table.rows.length > 1001) table.deleteRow(table.rows.length - 1);
    };
    let off = () => {};
    client.events(0).then((list) => {
      list.forEach(add);
      off = client.onEvent(add);
    });
    return () => off();
  }

  function commandsView(element) {
    const root = el('div', { class: 'rs-commands' });
    const form = el('form', { id: 'rs-command-form' });
    const select = el('select', { id: 'rs-command' });
    const args = el('input', { id: 'rs-args', type: 'text', size: '40', placeholder: 'arguments' });
    const usage = el('div', { class: 'rs-usage' });
    const send = el('button', { id: 'rs-send', type: 'submit' }, 'Send');
    const result = el('div', { id: 'rs-command-result', class: 'rs-result' });
    const log = el('ol', { id: 'rs-command-log', class: 'rs-log', reversed: '' });
    form.append(el('label', {}, 'Command '), select, ' ', args, ' ', send, usage);
    const seqText = el('textarea', { id: 'rs-sequence', rows: '8', cols: '60',
      placeholder: 'name: hold\nsteps:\n  - send: set-mode HOLD\n  - wait: mode == HOLD, timeout 60 s' });
    const seqRun = el('button', { id: 'rs-run-sequence', type: 'button' }, 'Run sequence');
    const seqResult = el('pre', { id: 'rs-sequence-result', class: 'rs-result' });
    root.append(el('h3', {}, 'Command'), form, result, el('h3', {}, 'Sent'), log,
      el('h3', {}, 'Sequence'), seqText, el('br'), seqRun, seqResult);
    element.appendChild(root);

    let help = [];
    client.commands().then((list) => {
      help = list;
      for (const h of list) select.append(el('option', { value: h.name }, h.name));
      showUsage();
    });
    const showUsage = () => {
      const h = help.find((x) => x.name === select.value);
      usage.textContent = h ? h.usage + ' — ' + h.what : '';
    };
    select.addEventListener('change', showUsage);
    form.addEventListener('submit', async (ev) => {
      ev.preventDefault();
      const words = args.value.trim() === '' ? [] : args.value.trim().split(/\s+/);
      send.disabled = true;
      result.className = 'rs-result rs-pending';
      result.textContent = 'sending ' + select.value + ' ' + words.join(' ') + ' …';
      try {
        const r = await client.send(select.value, words);
        result.className = 'rs-result rs-outcome-' + r.outcome;
        // The flight's verdict as `send` prints it ("ACCEPTED", "REJECTED: <reason> ..."), or what
        // went wrong on the ground ("TIMEOUT — no acknowledgement ...").
        const outcome = r.outcome.toUpperCase();
        const verdict = r.outcome === 'accepted' ? 'ACCEPTED'
          : (r.message || '').startsWith(outcome) ? r.message : outcome + ' — ' + r.message;
        result.textContent = (r.description || select.value) + (r.seq ? ' (seq ' + r.seq + ')' : '') + ': ' + verdict;
        log.prepend(el('li', { class: 'rs-outcome-' + r.outcome }, new Date().toISOString().slice(11, 19) + ' ' + result.textContent));
      } catch (e) {
        result.className = 'rs-result rs-outcome-error';
        result.textContent = 'ERROR — ' + e;
      }
      send.disabled = false;
    });
    seqRun.addEventListener('click', async () => {
      seqRun.disabled = true;
      seqResult.className = 'rs-result rs-pending';
      seqResult.textContent = 'running …';
      try {
        const r = await client.runSequence(seqText.value);
        seqResult.className = 'rs-result rs-outcome-' + r.outcome;
        seqResult.textContent = r.report || JSON.stringify(r, null, 1);
      } catch (e) {
        seqResult.className = 'rs-result rs-outcome-error';
        seqResult.textContent = 'ERROR — ' + e;
      }
      seqRun.disabled = false;
    });
    return () => {};
  }

  function provider(key, name, type, show) {
    return {
      key: key,
      name: name,
      cssClass: 'icon-gauge',
      canView: (o) => o.type === type,
      view: function () {
        let off = () => {};
        return {
          show: (element) => { off = show(element); },
          destroy: () => off()
        };
      },
      priority: () => 1
    };
  }

  return function install(openmct) {
    openmct.objectViews.addProvider(provider('rocksteady.status-view', 'Status', 'rocksteady.status', statusView));
    openmct.objectViews.addProvider(provider('rocksteady.events-view', 'Events', 'rocksteady.events', eventsView));
    openmct.objectViews.addProvider(provider('rocksteady.commands-view', 'Commands', 'rocksteady.commands', commandsView));

    const indicator = openmct.indicators.simpleIndicator();
    indicator.iconClass('icon-telemetry');
    client.onStatus(() => {
      const stale = client.isStale(TLM);
      const m = client.value(TLM, 'mode');
      const mode = m === undefined ? '—' : client.enumName('mode', m);
      indicator.text((stale ? 'STALE' : 'LIVE') + ' · ' + mode);
      indicator.description('Rocksteady: flight telemetry ' + (stale ? 'stale' : 'live') + ', mode ' + mode);
      indicator.statusClass(stale || mode === 'SAFE' ? 's-status-error' : 's-status-on');
    });
    openmct.indicators.add(indicator);
  };
}
