// main.js: the operator's station. Everything the machine does comes from the session's
// status and messages; every button is one API call (docs/api.md, docs/ui.md).
import { Rpc } from './rpc.js';
import { MachineView } from './view3d.js';

const $ = (id) => document.getElementById(id);
const AXES = ['X', 'Y', 'Z', 'A', 'B', 'C'];
const fmt = (v, d = 3) => (v === null || v === undefined || Number.isNaN(v) ? '—' : v.toFixed(d));

let st = null;            // the last status
let info = null;          // station.info
let program = null;       // { name, lines } of the open program (name: in the program folder)
let listing = { from: 0, lines: [] };
let haveControl = false;
let lastLine = -1;
const history = [];
const plotData = [];      // { t, legs: [{length, rate, ferror}], pins: [] }
const plotPins = [];

const view = new MachineView($('view3d'));
const rpc = new Rpc({ onNotify, onOpen, onClose });

// ---- messages -------------------------------------------------------------------------
function message(severity, text, time) {
  const li = document.createElement('li');
  li.className = severity;
  const t = document.createElement('time');
  t.textContent = new Date(time || Date.now()).toLocaleTimeString();
  li.append(t, text);
  const ol = $('messages');
  ol.prepend(li);
  while (ol.children.length > 300) ol.lastChild.remove();
}

async function call(method, params) {
  try {
    return await rpc.call(method, params);
  } catch (e) {
    message('error', `${method}: ${e.message}`);
    throw e;
  }
}
const act = (method, params) => call(method, params).catch(() => {});

// ---- connection -----------------------------------------------------------------------
async function onOpen() {
  $('conn').textContent = 'connected';
  $('conn').className = 'conn ok';
  haveControl = false;   // a new connection holds nothing (before any await: a click may follow)
  controlUi();
  try {
    info = await rpc.call('station.info');
    $('machine-name').textContent = info.machine;
    document.title = `hexcnc — ${info.machine}`;
    view.setGeometry(info);
    if (info.geometry_error) message('error', `machine geometry: ${info.geometry_error}`);
    await rpc.call('status.subscribe', { rate_hz: 20 });
    await rpc.call('messages.subscribe');
    onStatus(await rpc.call('status.get'));
    await refreshPrograms();
  } catch (e) {
    message('error', `station: ${e.message}`);
  }
}

function onClose(reason) {
  $('conn').textContent = 'disconnected — retrying';
  $('conn').className = 'conn bad';
  $('conn').title = reason;
  message('error', `connection: ${reason}`);
  haveControl = false;
  controlUi();
}

function onNotify(method, params) {
  if (method === 'status') onStatus(params);
  else if (method === 'message') message(params.severity, `${params.source}: ${params.text}`);
  else if (method === 'station.disconnected') message('error', params.reason);
}

// ---- status ---------------------------------------------------------------------------
function initTables() {
  const dro = $('dro').tBodies[0];
  AXES.forEach((a) => {
    const tr = dro.insertRow();
    tr.innerHTML = `<td>${a}</td><td data-testid="dro-${a}" id="dro-${a}">—</td><td id="mdro-${a}">—</td>`;
  });
  const legs = $('legs').tBodies[0];
  for (let i = 1; i <= 6; i++) {
    const tr = legs.insertRow();
    tr.setAttribute('data-testid', `leg-${i}`);
    tr.innerHTML = `<td>${i}</td><td id="leg-len-${i}">—</td><td><span class="bar"><i id="leg-bar-${i}"></i></span></td>` +
      `<td id="leg-rate-${i}">—</td><td id="leg-fe-${i}">—</td>`;
  }
}

function onStatus(s) {
  st = s;
  const stateWord = `${s.state} ${s.mode}${s.homing ? ' homing' : ''}${s.interp !== 'idle' ? ' ' + s.interp : ''}`;
  $('state').textContent = stateWord;
  $('state').className = `badge ${s.state}`;
  $('estop').textContent = s.state === 'estop' ? 'Reset e-stop' : 'E-STOP';
  $('estop').classList.toggle('engaged', s.state === 'estop');
  $('power').textContent = s.state === 'on' ? 'Power off' : 'Power on';
  $('power').disabled = s.state === 'estop';
  $('home').disabled = s.state !== 'on';
  const p = s.pose.commanded, m = s.machine_pose.commanded;
  AXES.forEach((a, i) => {
    $(`dro-${a}`).textContent = fmt(p[i]);
    $(`mdro-${a}`).textContent = fmt(m[i]);
  });
  s.legs.forEach((l, i) => {
    const u = (l.length - l.min) / (l.max - l.min);
    $(`leg-len-${i + 1}`).textContent = fmt(l.length, 2);
    $(`leg-rate-${i + 1}`).textContent = fmt(l.rate, 1);
    $(`leg-fe-${i + 1}`).textContent = fmt(l.ferror, 4);
    const bar = $(`leg-bar-${i + 1}`);
    bar.style.width = `${Math.max(0, Math.min(1, u)) * 100}%`;
    const edge = Math.min(u, 1 - u);
    bar.style.background = edge < 0.05 ? '#e33' : edge < 0.15 ? '#db3' : '#3a3';
  });
  const homed = s.homed.every(Boolean) ? 'homed' : `homed ${s.homed.map((h) => (h ? '●' : '○')).join('')}`;
  $('modal').textContent = `${s.gcodes.join(' ')}\n${s.mcodes.join(' ')}\n` +
    `T${s.tool.number} (next T${s.tool.selected})  TLO ${fmt(s.tool.length)}\n` +
    `F ${fmt(s.feed, 0)}  S ${fmt(s.spindle.speed, 0)} ${s.spindle.direction > 0 ? 'CW' : s.spindle.direction < 0 ? 'CCW' : 'stopped'}\n` +
    `motion ${s.motion}  ${homed}`;
  view.setPose(m, s.legs);
  $('line').textContent = String(s.line);
  $('progress').textContent = s.program ? `${(s.progress * 100).toFixed(1)} %` : '';
  if (s.line !== lastLine) {
    lastLine = s.line;
    view.setProgress(s.line, s.interp !== 'idle');
    if (s.line > 0) view.setLine(s.line);
    followListing(s.line);
  }
  const fault = s.error && (s.state === 'estop' || s.motion === 'fault');
  $('fault').classList.toggle('hidden', !fault);
  if (fault) $('fault').textContent = `Fault: ${s.error}`;
  $('tool-changed').classList.toggle('hidden', s.interp !== 'waiting');
  const ov = s.overrides;
  syncSlider('feed-override', ov.feed * 100);
  syncSlider('rapid-override', ov.rapid * 100);
  syncSlider('spindle-override', ov.spindle * 100);
  $('optional-stop').checked = s.switches.optional_stop;
  $('block-delete').checked = s.switches.block_delete;
  plotData.push({ t: s.time, legs: s.legs.map((l) => ({ ...l })), pins: plotPins.map((q) => q.value) });
  while (plotData.length && plotData[0].t < s.time - 10) plotData.shift();
  drawPlotSoon();
}

function syncSlider(id, pct) {
  const el = $(id);
  if (document.activeElement === el) return;   // the operator is moving it
  el.value = String(Math.round(pct));
  $(`${id}-v`).textContent = `${Math.round(pct)} %`;
}

// ---- control, machine -----------------------------------------------------------------
function controlUi() {
  $('take-control').textContent = haveControl ? 'Release control' : 'Take control';
  $('control-state').textContent = haveControl ? 'in control' : 'watching';
}

$('take-control').onclick = async () => {
  if (haveControl) {
    await act('control.release');
    haveControl = false;
  } else {
    try { await call('control.acquire'); haveControl = true; } catch (e) { /* shown */ }
  }
  controlUi();
};
$('estop').onclick = () => act('machine.estop', { active: !st || st.state !== 'estop' });
$('power').onclick = () => act('machine.power', { on: !st || st.state !== 'on' });
$('home').onclick = () => act('machine.home');

// ---- jog ------------------------------------------------------------------------------
let jogging = false;
function jogButtons() {
  const frame = $('jog-frame').value;
  const box = $('jog-buttons');
  box.innerHTML = '';
  const slots = frame === 'joint' ? [1, 2, 3, 4, 5, 6].map((n) => [`L${n}`, n - 1])
    : (frame === 'tool' ? AXES.slice(0, 3) : AXES).map((a) => [a, a]);
  for (const [label, axis] of slots) {
    for (const sign of ['+', '-']) {
      const b = document.createElement('button');
      b.textContent = `${label}${sign}`;
      b.setAttribute('data-testid', `jog-${label}${sign}`);
      b.addEventListener('pointerdown', (e) => { e.preventDefault(); jogStart(axis, sign === '+' ? 1 : -1); });
      for (const ev of ['pointerup', 'pointerleave', 'pointercancel']) b.addEventListener(ev, jogEnd);
      box.append(b);
    }
  }
}

function jogStart(axis, dir) {
  const step = parseFloat($('jog-step').value);
  const speed = Math.abs(parseFloat($('jog-speed').value)) || 1;
  const frame = $('jog-frame').value;
  const params = { frame, axis, velocity: dir * speed };
  if (step > 0) {
    params.distance = step;
  } else {
    jogging = true;
  }
  act('jog.move', params);
}

function jogEnd() {
  if (!jogging) return;
  jogging = false;
  act('jog.stop');
}
window.addEventListener('blur', jogEnd);
document.addEventListener('visibilitychange', jogEnd);
$('jog-frame').onchange = jogButtons;

const KEYS = { ArrowRight: ['X', 1], ArrowLeft: ['X', -1], ArrowUp: ['Y', 1], ArrowDown: ['Y', -1],
  PageUp: ['Z', 1], PageDown: ['Z', -1], ']': ['A', 1], '[': ['A', -1], "'": ['B', 1], ';': ['B', -1],
  '.': ['C', 1], ',': ['C', -1] };
document.addEventListener('keydown', (e) => {
  if (e.key === 'F1') { e.preventDefault(); $('estop').click(); return; }
  if (e.key === 'F2') { e.preventDefault(); $('power').click(); return; }
  if (e.key === 'Escape') { jogEnd(); act('jog.stop'); if (st && st.interp !== 'idle') act('program.abort'); return; }
  if (e.target.matches('input, select, textarea') || e.repeat) return;
  if (e.ctrlKey && e.key === 'Home') { e.preventDefault(); $('home').click(); return; }
  const k = KEYS[e.key];
  if (!k || $('jog-frame').value !== 'world') return;
  e.preventDefault();
  jogStart(k[0], k[1]);
});
document.addEventListener('keyup', (e) => { if (KEYS[e.key]) jogEnd(); });

// ---- MDI ------------------------------------------------------------------------------
async function mdiSend() {
  const line = $('mdi-input').value.trim();
  if (!line) return;
  try {
    await call('mdi.execute', { line });
    history.unshift(line);
    $('mdi-input').value = '';
    const ol = $('mdi-history');
    const li = document.createElement('li');
    li.textContent = line;
    li.onclick = () => { $('mdi-input').value = line; $('mdi-input').focus(); };
    ol.prepend(li);
  } catch (e) { /* shown */ }
}
$('mdi-send').onclick = mdiSend;
let histPos = -1;
$('mdi-input').addEventListener('keydown', (e) => {
  if (e.key === 'Enter') { mdiSend(); histPos = -1; }
  if (e.key === 'ArrowUp' && histPos + 1 < history.length) $('mdi-input').value = history[++histPos];
  if (e.key === 'ArrowDown') $('mdi-input').value = histPos > 0 ? history[--histPos] : (histPos = -1, '');
});

// ---- programs -------------------------------------------------------------------------
async function refreshPrograms(select) {
  const r = await call('program.list');
  const sel = $('program-file');
  const keep = select || sel.value;
  sel.innerHTML = '';
  for (const f of r.files) {
    const o = document.createElement('option');
    o.value = o.textContent = f.name;
    sel.append(o);
  }
  if (keep) sel.value = keep;
}
$('program-refresh').onclick = () => refreshPrograms().catch(() => {});

async function openProgram(name) {
  const r = await call('program.open', { path: name });
  program = { name, lines: r.lines };
  $('program-name').textContent = `${name} (${r.lines} lines)`;
  $('check-report').innerHTML = '';
  $('run-from').max = String(r.lines);
  listing = { from: 0, lines: [] };
  await loadListing(1);
  const start = st ? st.machine_pose.commanded : [0, 0, 0, 0, 0, 0];
  const pv = await call('program.preview', { path: name, start });
  view.setPath(pv);
  view.setView('fit');
  const legend = pv.contour_line && pv.contour_line.length ? 'orange: G141/G142 tool path, magenta: its contour' : '';
  $('view-note').textContent = [pv.truncated ? `path shown up to ${pv.points} points` : '', legend].filter(Boolean).join('; ');
  if (pv.error) message('warning', `preview: ${pv.error}`);
}
$('program-open').onclick = () => openProgram($('program-file').value).catch(() => {});

$('program-upload').onchange = async (e) => {
  const f = e.target.files[0];
  if (!f) return;
  try {
    const text = await f.text();
    await call('program.upload', { name: f.name, text });
    message('info', `uploaded ${f.name} (${text.length} bytes)`);
    await refreshPrograms(f.name);
  } catch (err) { /* shown */ }
  e.target.value = '';
};

async function loadListing(line) {
  if (!program) return;
  const from = Math.max(1, line - 100);
  const r = await rpc.call('program.lines', { path: program.name, from, count: 400 });
  listing = { from, lines: r.lines };
  const box = $('listing');
  box.innerHTML = '';
  r.lines.forEach((text, i) => {
    const d = document.createElement('div');
    d.id = `ln-${from + i}`;
    const n = document.createElement('span');
    n.className = 'n';
    n.textContent = String(from + i);
    d.append(n, text);
    box.append(d);
  });
}

let listingBusy = false;
async function followListing(line) {
  if (!program || line < 1 || listingBusy) return;
  const inWindow = line >= listing.from && line < listing.from + listing.lines.length;
  const nearEdge = line > listing.from + listing.lines.length - 50 && listing.lines.length === 400;
  if (!inWindow || nearEdge || (line < listing.from + 50 && listing.from > 1)) {
    listingBusy = true;
    try { await loadListing(line); } catch (e) { /* a stale window stays */ }
    listingBusy = false;
  }
  for (const d of $('listing').querySelectorAll('.cur')) d.classList.remove('cur');
  const d = $(`ln-${line}`);
  if (d) {
    d.classList.add('cur');
    d.scrollIntoView({ block: 'center' });
  }
}

function showReport(r) {
  const box = $('check-report');
  box.innerHTML = '';
  const head = document.createElement('div');
  head.className = r.ok ? 'ok' : '';
  head.textContent = r.ok
    ? `Check passed: ${r.time_s.toFixed(1)} s, ${r.length_mm.toFixed(0)} mm, ${r.segments} segments`
    : `Check found ${r.problems.length} problem(s):`;
  box.append(head);
  for (const p of r.problems) {
    const a = document.createElement('a');
    a.textContent = `line ${p.line}: ${p.text}`;
    a.onclick = async () => {
      await followListing(p.line);
      const d = $(`ln-${p.line}`);
      if (d) d.classList.add('bad');
      view.setLine(p.line, 0xff3030);
    };
    box.append(a);
  }
}

$('check').onclick = async () => {
  $('check-report').textContent = 'checking…';
  try { showReport(await call('program.check')); } catch (e) { $('check-report').textContent = e.message; }
};
$('run').onclick = () => {
  const from = parseInt($('run-from').value, 10) || 1;
  act('program.run', from > 1 ? { from_line: from } : {});
};
$('pause').onclick = () => act('program.pause');
$('resume').onclick = () => act('program.resume');
$('step').onclick = () => act('program.step');
$('abort').onclick = () => act('program.abort');
$('tool-changed').onclick = () => act('tool.changed');
$('optional-stop').onchange = (e) => act('switch.set', { optional_stop: e.target.checked });
$('block-delete').onchange = (e) => act('switch.set', { block_delete: e.target.checked });

// ---- overrides ------------------------------------------------------------------------
for (const [id, key] of [['feed-override', 'feed'], ['rapid-override', 'rapid'], ['spindle-override', 'spindle']]) {
  $(id).addEventListener('input', (e) => {
    $(`${id}-v`).textContent = `${e.target.value} %`;
    act('override.set', { [key]: parseInt(e.target.value, 10) / 100 });
  });
}
$('override-reset').onclick = () => act('override.set', { feed: 1, rapid: 1, spindle: 1 });

// ---- tools ----------------------------------------------------------------------------
async function loadTools() {
  const r = await call('tooltable.get');
  const body = $('tools').tBodies[0];
  body.innerHTML = '';
  for (const t of r.tools) toolRow(t);
}
function toolRow(t) {
  const tr = $('tools').tBodies[0].insertRow();
  const num = (v) => `<input type="number" step="0.001" value="${v}">`;
  tr.innerHTML = `<td><input type="number" min="1" value="${t.tool}"></td><td><input type="number" min="0" value="${t.pocket}"></td>` +
    `<td>${num(t.length)}</td><td>${num(t.diameter)}</td><td>${num(t.wear || 0)}</td>` +
    '<td><input class="c" value=""></td><td><button>Save</button></td>';
  tr.cells[5].firstChild.value = t.comment || '';
  tr.querySelector('button').onclick = async () => {
    const v = [...tr.querySelectorAll('input')].map((i) => i.value);
    try {
      await call('tooltable.set', { tool: parseInt(v[0], 10), pocket: parseInt(v[1], 10), length: parseFloat(v[2]),
        diameter: parseFloat(v[3]), wear: parseFloat(v[4]), comment: v[5] });
      message('info', `tool ${v[0]} saved`);
    } catch (e) { /* shown */ }
  };
}
$('tool-add').onclick = () => toolRow({ tool: '', pocket: '', length: 0, diameter: 0, wear: 0, comment: '' });

// ---- plot -----------------------------------------------------------------------------
let plotQueued = false;
function drawPlotSoon() {
  if (plotQueued || $('tab-plot').classList.contains('hidden')) return;
  plotQueued = true;
  setTimeout(() => { plotQueued = false; drawPlot(); }, 100);
}
const PLOT_COLORS = ['#e66', '#6c6', '#69f', '#fc4', '#c6f', '#4dd', '#fff', '#f9c'];
function drawPlot() {
  const cv = $('plot'), g = cv.getContext('2d');
  const w = cv.width = cv.clientWidth || 400, h = cv.height;
  g.clearRect(0, 0, w, h);
  if (plotData.length < 2) return;
  const what = $('plot-what').value;
  const series = [];
  for (let i = 0; i < 6; i++) series.push({ name: `leg ${i + 1}`, v: plotData.map((d) => d.legs[i][what]) });
  plotPins.forEach((p, j) => series.push({ name: p.name, v: plotData.map((d) => d.pins[j]) }));
  const all = series.flatMap((s) => s.v).filter((x) => typeof x === 'number');
  let lo = Math.min(...all), hi = Math.max(...all);
  if (hi - lo < 1e-9) { hi += 1; lo -= 1; }
  const t0 = plotData[plotData.length - 1].t - 10;
  series.forEach((s, k) => {
    g.strokeStyle = PLOT_COLORS[k % PLOT_COLORS.length];
    g.beginPath();
    s.v.forEach((y, i) => {
      const X = ((plotData[i].t - t0) / 10) * w, Y = h - ((y - lo) / (hi - lo)) * (h - 10) - 5;
      if (i) g.lineTo(X, Y); else g.moveTo(X, Y);
    });
    g.stroke();
  });
  $('plot-legend').textContent = `${what}: ${fmt(lo, 3)} … ${fmt(hi, 3)} over the last 10 s; ` +
    series.map((s, k) => `${s.name} (${PLOT_COLORS[k % PLOT_COLORS.length]})`).join(', ');
}
$('plot-pin-add').onclick = async () => {
  const name = $('plot-pin').value.trim();
  if (!name) return;
  try {
    await call('hal.get', { name });
    plotPins.push({ name, value: null });
    $('plot-pin').value = '';
  } catch (e) { /* shown */ }
};
setInterval(async () => {
  for (const p of plotPins) {
    try { p.value = (await rpc.call('hal.get', { name: p.name })).value; } catch (e) { p.value = null; }
  }
}, 200);

// ---- layout ---------------------------------------------------------------------------
for (const b of document.querySelectorAll('.tabs button')) {
  b.onclick = () => {
    for (const o of document.querySelectorAll('.tabs button')) o.classList.toggle('active', o === b);
    for (const t of document.querySelectorAll('.tab')) t.classList.toggle('hidden', t.id !== `tab-${b.dataset.tab}`);
    if (b.dataset.tab === 'tools') loadTools().catch(() => {});
  };
}
for (const b of document.querySelectorAll('.viewbar button')) b.onclick = () => view.setView(b.dataset.view);

initTables();
jogButtons();
rpc.connect();
