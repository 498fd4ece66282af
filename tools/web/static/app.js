// SPDX-License-Identifier: GPL-3.0-or-later
// amfi-web's pages: one script for all, chosen by the path. Everything shown
// comes from the JSON API and reaches the page as text nodes (textContent),
// never as HTML. Charts: Chart.js (served by amfi-web from libjs-chart.js);
// each chart's canvas gets data-points, the number of points drawn.
'use strict';

const main = document.getElementById('main');
const statuses = ['ok', 'gap', 'late', 'overload', 'multiple', 'invalid', 'error'];

function el(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k === 'class') e.className = v; else e.setAttribute(k, v);
  }
  for (const c of children) {
    if (c === null || c === undefined) continue;
    e.appendChild(typeof c === 'object' ? c : document.createTextNode(String(c)));
  }
  return e;
}

function num(x, digits) {
  return x === null || x === undefined ? '—' : Number(x).toFixed(digits);
}
function when(iso) { return iso ? iso.replace('T', ' ').replace(/\.\d+Z$/, 'Z') : '—'; }

async function api(path) {
  const r = await fetch(path, {headers: {Accept: 'application/json'}});
  const body = await r.json();
  if (!r.ok) throw new Error((body && body.error) || ('HTTP ' + r.status));
  return body;
}

function fail(e) {
  main.replaceChildren(el('p', {class: 'error', id: 'error'}, 'Could not load: ' + e.message));
}

function table(id, head, rows) {
  const t = el('table', {id: id});
  t.appendChild(el('thead', {}, el('tr', {}, ...head.map(h => el('th', {}, h)))));
  const b = el('tbody');
  for (const r of rows) b.appendChild(r);
  t.appendChild(b);
  return t;
}

function cell(v, cls) { return el('td', cls ? {class: cls} : {}, v); }

function chart(id, type, labels, datasets, yTitle) {
  const canvas = el('canvas', {id: id, 'data-points': String(labels.length),
                               'data-series': datasets.map(d => d.label).join('|')});
  const box = el('div', {class: 'chart'}, canvas);
  if (typeof Chart === 'undefined') {
    box.appendChild(el('p', {class: 'muted'}, 'Charts need Chart.js (libjs-chart.js).'));
    return box;
  }
  // drawn once the box is in the page (Chart.js measures it)
  setTimeout(() => {
    new Chart(canvas, {
      type: type,
      data: {labels: labels, datasets: datasets},
      options: {animation: false, responsive: true, maintainAspectRatio: false,
                scales: {y: {title: {display: !!yTitle, text: yTitle || ''}}}}
    });
    canvas.setAttribute('data-drawn', '1');
  }, 0);
  return box;
}

function passageRow(p) {
  const bad = p.status !== 'ok';
  return el('tr', {class: bad ? 'st-bad' : 'st-ok', 'data-id': String(p.id)},
    cell(el('a', {href: '/vehicle?id=' + encodeURIComponent(p.id)}, String(p.id))),
    cell(when(p.utime_utc)), cell(p.lane, 'num'), cell(p.class || '—'),
    cell(p.n_axles, 'num'), cell(p.axle_groups || '—'), cell(num(p.gvw_kg, 0), 'num'),
    cell(num(p.speed_mps, 1), 'num'), cell(p.status, 'status'),
    cell(p.reason || (p.loads_refused ? 'loads refused: ' + p.loads_refused : '')));
}
const passageHead = ['id', 'time (UTC)', 'lane', 'class', 'axles', 'groups', 'GVW kg',
                     'speed m/s', 'status', 'reason'];

// ---- status (live) ---------------------------------------------------------
// live: drawn again every 5 s, and tried again 5 s after a failure (amfid or
// the store restarting)
async function pageStatus() {
  try {
    await drawStatus();
  } finally {
    setTimeout(() => pageStatus().catch(fail), 5000);
  }
}

async function drawStatus() {
  const s = await api('/api/status');
  const last = await api('/api/passages?limit=10');
  const counts = c => table('', ['status', 'passages'],
    statuses.map(k => el('tr', {}, cell(k), cell(c.by_status[k], 'num'))));
  const parts = [
    el('h2', {}, 'Site'),
    table('summary', ['', ''], [
      el('tr', {}, cell('site'), cell(s.site || '—')),
      el('tr', {}, cell('source'), cell(s.source + ': ' + s.source_name)),
      el('tr', {}, cell('passages'), cell(s.passages, 'num')),
      el('tr', {}, cell('last passage'), cell(s.last_passage ? when(s.last_passage.utime_utc) : '—')),
      el('tr', {}, cell('indicator'), cell(s.indicator ? s.indicator.state + ' (STD ratio ' +
        num(s.indicator.std_ratio, 3) + ')' : '—')),
      el('tr', {}, cell('store version'), cell(s.store_version, 'num'))]),
    el('h2', {}, 'Open alerts'),
    s.open_alerts.length ? table('open-alerts', ['time', 'level', 'kind', 'message'],
      s.open_alerts.map(a => el('tr', {}, cell(when(a.utime_utc)), cell(a.level, 'warning'),
                                cell(a.kind), cell(a.message))))
      : el('p', {id: 'open-alerts'}, 'none'),
    el('h2', {}, 'Today (UTC, since ' + when(s.today.since_utc) + '): ' + s.today.total),
    counts(s.today),
    el('h2', {}, 'Day of the newest passage (since ' + when(s.newest_day.since_utc) + '): ' +
       s.newest_day.total),
    counts(s.newest_day),
    el('h2', {}, 'Latest passages'),
    table('passages', passageHead, last.passages.map(passageRow))];
  if (s.metrics) {
    parts.push(el('h2', {}, 'amfid intake'),
      table('metrics', ['counter', 'value'], Object.entries(s.metrics).map(
        ([k, v]) => el('tr', {}, cell(k), cell(v, 'num')))));
  }
  parts.push(el('p', {class: 'muted', id: 'updated'}, 'updated ' + when(s.now_utc) +
                ', every 5 s'));
  document.getElementById('site').textContent = 'amfi: ' + (s.site_name || s.site || '');
  main.replaceChildren(...parts);
}

// ---- passages ----------------------------------------------------------------
async function pagePassages() {
  const q = new URLSearchParams(location.search);
  const api_q = new URLSearchParams();
  for (const k of ['from', 'to', 'status', 'class', 'limit']) {
    if (q.get(k)) api_q.set(k, q.get(k));
  }
  const r = await api('/api/passages?' + api_q.toString());
  const sel = el('select', {name: 'status'}, el('option', {value: ''}, 'any'),
                 ...statuses.map(k => el('option', {value: k}, k)));
  sel.value = q.get('status') || '';
  const input = (name, size) => {
    const i = el('input', {name: name, size: String(size)});
    i.value = q.get(name) || '';
    return i;
  };
  const form = el('form', {method: 'get', action: '/passages'},
    el('label', {}, 'from ', input('from', 20)), el('label', {}, 'to ', input('to', 20)),
    el('label', {}, 'status ', sel), el('label', {}, 'class ', input('class', 8)),
    el('label', {}, 'limit ', input('limit', 5)), el('button', {type: 'submit'}, 'show'));
  main.replaceChildren(form,
    el('h2', {}, r.count + ' passages, newest first (limit ' + r.limit + ')'),
    table('passages', passageHead, r.passages.map(passageRow)));
}

// ---- one vehicle ---------------------------------------------------------------
async function pageVehicle() {
  const id = new URLSearchParams(location.search).get('id') || '';
  if (!/^[1-9][0-9]{0,17}$/.test(id)) throw new Error('no passage id in the address (?id=N)');
  const p = await api('/api/passages/' + id);
  const kv = [['vehicle id', p.vehicle_id], ['time (UTC)', when(p.utime_utc)], ['lane', p.lane],
    ['status', p.status], ['reason', p.reason || '—'], ['class', p.class || '—'],
    ['axle groups', p.axle_groups || '—'], ['GVW kg', num(p.gvw_kg, 0)],
    ['overload', p.overload === null ? '—' : (p.overload ? 'yes' : 'no')],
    ['loads refused', p.loads_refused || '—'],
    ['speed m/s', num(p.speed_mps, 2) + (p.speed_estimated ? ' (estimated)' : '')],
    ['detector speed m/s', num(p.speed_given_mps, 2)], ['residual RMS m/s²', num(p.residual_rms, 5)],
    ['quality', num(p.quality, 2)], ['vehicles in the event', p.n_vehicles],
    ['λ', num(p.lambda, 6)], ['formulation', p.formulation || '—'],
    ['solve ms', num(p.solve_ms, 1)], ['deck °C', num(p.deck_c, 1)],
    ['f1 Hz', num(p.f1_hz, 3)], ['reference GVW kg', num(p.reference_gvw_kg, 0)]];
  const parts = [el('h2', {}, 'Passage ' + p.id),
    table('passage', ['', ''], kv.map(([k, v]) => el('tr', {}, cell(k), cell(v, 'value')))),
    el('h2', {}, 'Axles'),
    table('axles', ['axle', 'load kg', 'spacing to the one before, m'],
      p.axles.map(a => el('tr', {}, cell(a.idx, 'num'), cell(num(a.load_kg, 0), 'num'),
                          cell(num(a.spacing_m, 2), 'num')))),
    chart('chart-axles', 'bar', p.axles.map(a => 'axle ' + a.idx),
          [{label: 'axle load kg', data: p.axles.map(a => a.load_kg)}], 'kg')];
  if (p.groups.length) {
    parts.push(el('h2', {}, 'Axle groups'),
      table('groups', ['group', 'axles', 'load kg'], p.groups.map((g, k) =>
        el('tr', {}, cell(k + 1, 'num'), cell(g.axles.join(', ')), cell(num(g.load_kg, 0), 'num')))));
  }
  parts.push(el('h2', {}, 'Signal'));
  if (p.raw && p.raw.sensors) {
    parts.push(el('p', {class: 'muted', id: 'raw-info'}, signalInfo(p.raw)));
    for (const [k, sensor] of p.raw.sensors.entries()) {
      parts.push(signalChart('chart-signal-' + k, p.raw, sensor));
    }
  } else {
    parts.push(el('p', {id: 'raw-reason', class: 'muted'}, p.raw_reason || 'no raw samples'));
  }
  main.replaceChildren(...parts);
}

// ---- the raw signal of a passage (docs/web.md: /api/passages/ID "raw") ----------
function signalInfo(raw) {
  const me = raw.vehicles[raw.vehicle];
  return raw.n_samples + ' samples a sensor at ' + raw.rate_hz + ' Hz (' + raw.precision +
    '), from ' + when(raw.t0_utc) + '; ' + raw.vehicles.length + ' vehicle(s) in the window' +
    (raw.decimated ? '; drawn as the min and max of every ' + raw.decimated + ' samples' : '') +
    '. Marked: this vehicle\'s entry (' + num(raw.t_entry_s, 3) + ' s) and its last axle\'s (' +
    num(me.t_last_axle_s, 3) + ' s)' + (raw.exit_marked ? '' : '; exit not marked: ' + raw.exit_reason) + '.';
}

// one chart per sensor: time after sample 0 (s) on a linear axis; a
// decimated sensor's points 2b, 2b + 1 are bucket b (its min and max)
function signalChart(id, raw, sensor) {
  const k = raw.decimated || 1;
  const pts = sensor.samples.map((y, i) => ({x: (k > 1 ? Math.floor(i / 2) * k + (i % 2) * (k - 1) : i) / raw.rate_hz, y: y}));
  const canvas = el('canvas', {id: id, 'data-points': String(pts.length),
                               'data-entry-s': String(raw.t_entry_s)});
  const box = el('div', {class: 'chart'}, canvas);
  if (typeof Chart === 'undefined') {
    box.appendChild(el('p', {class: 'muted'}, 'Charts need Chart.js (libjs-chart.js).'));
    return box;
  }
  let lo = Infinity, hi = -Infinity;
  for (const y of sensor.samples) { lo = Math.min(lo, y); hi = Math.max(hi, y); }
  const mark = (label, t, color, dash) => ({label: label, data: [{x: t, y: lo}, {x: t, y: hi}],
    borderColor: color, borderDash: dash, pointRadius: 0, borderWidth: 1});
  const sets = [{label: 'sensor ' + sensor.id + ' at ' + num(sensor.at_m, 2) + ' m', data: pts,
                 borderColor: '#236', pointRadius: 0, borderWidth: 1}];
  const me = raw.vehicles[raw.vehicle];
  sets.push(mark('entry', me.t_entry_s, '#c00', []),
            mark('last axle in', me.t_last_axle_s, '#c60', [4, 3]));
  raw.vehicles.forEach((v, i) => {
    if (i !== raw.vehicle) sets.push(mark('vehicle ' + v.vehicle_id + ' entry', v.t_entry_s, '#999', [2, 2]));
  });
  setTimeout(() => {
    new Chart(canvas, {
      type: 'line', data: {datasets: sets},
      options: {animation: false, responsive: true, maintainAspectRatio: false, parsing: false,
                normalized: true, spanGaps: true,
                scales: {x: {type: 'linear', title: {display: true, text: 's after ' + when(raw.t0_utc)}},
                         y: {title: {display: true, text: 'm/s²'}}}}
    });
    canvas.setAttribute('data-drawn', '1');
  }, 0);
  return box;
}

// ---- trends ----------------------------------------------------------------------
const seriesList = [['gvw', 'GVW of ok passages', 'kg'], ['indicator', 'STD indicator ratio', ''],
  ['natfreq', 'first natural frequency', 'Hz'], ['residual', 'fit residual RMS', 'm/s²'],
  ['temperature', 'deck temperature', '°C'],
  ['fit_ratio', 'model fit ratio over the free vibration (model_mismatch)', '']];

// the model_mismatch rule's raise and clear levels as flat lines (fit_ratio)
function levelLines(t) {
  const th = t.thresholds;
  if (!th) return [];
  const flat = v => t.points.map(() => v);
  const whose = th.source === 'amfid' ? "amfid's" : 'defaults';
  return [
    {label: 'raise at >= ' + th.raise + ' (median of ' + th.window + ', ' + th.raise_after +
            ' in a row; ' + whose + ')', data: flat(th.raise), borderColor: '#c33',
     pointRadius: 0, borderWidth: 1},
    {label: 'clear below ' + th.clear + ' (' + th.clear_after + ' in a row)', data: flat(th.clear),
     borderColor: '#393', borderDash: [6, 4], pointRadius: 0, borderWidth: 1}];
}

// a from/to form for the pages whose API defaults to the last 30 days
function rangeForm(action, q, shown) {
  const input = name => {
    const i = el('input', {name: name, size: '20'});
    i.value = q.get(name) || '';
    return i;
  };
  return el('form', {method: 'get', action: action},
    el('label', {}, 'from ', input('from')), el('label', {}, 'to ', input('to')),
    el('button', {type: 'submit'}, 'show'),
    el('span', {class: 'muted', id: 'range'}, ' ' + when(shown.from_utc) + ' to ' +
       when(shown.to_utc) + (q.get('from') ? '' : ' (default: the 30 days before the newest passage)')));
}

async function pageTrends() {
  const q = new URLSearchParams(location.search);
  const range = new URLSearchParams();
  for (const k of ['from', 'to']) if (q.get(k)) range.set(k, q.get(k));
  const parts = [];
  let shown = null;
  for (const [name, title, unit] of seriesList) {
    const t = await api('/api/trends?series=' + name + (range.toString() ? '&' + range : ''));
    shown = shown || t;
    const labels = t.points.map(p => when(p.t_utc));
    parts.push(el('h2', {}, title + (unit ? ' (' + unit + ')' : '') + ': ' + t.count +
                  ' points, ' + Math.round(t.bucket_s) + ' s each'));
    parts.push(chart('chart-' + name, 'line', labels, [
      {label: 'mean', data: t.points.map(p => p.mean), borderColor: '#236', pointRadius: 0},
      {label: 'min', data: t.points.map(p => p.min), borderColor: '#9ab', pointRadius: 0},
      {label: 'max', data: t.points.map(p => p.max), borderColor: '#c96', pointRadius: 0},
      ...levelLines(t)], unit));
  }
  main.replaceChildren(rangeForm('/trends', q, shown), ...parts);
}

// ---- alerts ----------------------------------------------------------------------
async function pageAlerts() {
  const a = await api('/api/alerts');
  const row = x => el('tr', {'data-id': String(x.id)}, cell(x.id, 'num'), cell(when(x.utime_utc)),
    cell(x.level, x.level === 'warning' ? 'warning' : ''), cell(x.kind),
    cell(x.raised ? 'raised' : 'cleared'), cell(x.message));
  const head = ['id', 'time (UTC)', 'level', 'kind', 'event', 'message'];
  main.replaceChildren(el('h2', {}, 'Open: ' + a.open.length),
    table('open-alerts', head, a.open.map(row)),
    el('h2', {}, 'Latest ' + a.recent.length + ' events'),
    table('alerts', head, a.recent.map(row)));
}

// ---- classes ----------------------------------------------------------------------
async function pageClasses() {
  const q = new URLSearchParams(location.search);
  const range = new URLSearchParams();
  for (const k of ['from', 'to']) if (q.get(k)) range.set(k, q.get(k));
  const c = await api('/api/classes' + (range.toString() ? '?' + range : ''));
  const name = x => x.class === null ? '(none)' : x.class;
  main.replaceChildren(rangeForm('/classes', q, c), el('h2', {}, 'Passages per class'),
    table('classes', ['class', 'passages', 'ok', 'overloaded', 'loads refused', 'mean GVW kg',
                      'max GVW kg'],
      c.classes.map(x => el('tr', {}, cell(name(x)), cell(x.n, 'num'), cell(x.n_ok, 'num'),
        cell(x.n_overload, 'num'), cell(x.n_refused, 'num'), cell(num(x.gvw_mean_kg, 0), 'num'),
        cell(num(x.gvw_max_kg, 0), 'num')))),
    chart('chart-classes', 'bar', c.classes.map(name),
          [{label: 'passages', data: c.classes.map(x => x.n)}], 'passages'));
}

const pages = {'/': pageStatus, '/passages': pagePassages, '/vehicle': pageVehicle,
               '/trends': pageTrends, '/alerts': pageAlerts, '/classes': pageClasses};
// data-drawn-ms on <body>: milliseconds from navigation to the first drawing
// (tools/bench/amfi-web-bench reads it)
(pages[location.pathname] || (async () => { throw new Error('no such page'); }))().catch(fail)
  .finally(() => document.body.setAttribute('data-drawn-ms', String(Math.round(performance.now()))));
