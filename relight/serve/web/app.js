// prizma-relight --serve: the live relighting page: its controls, the URL fragment's state, the
// render loop (each change of a control asks the server for the exact weights of the new state —
// RelightMatrix, the C++ code of prizma-relight; from spectral-basis coefficients W_l = M_l·B_l, as
// relight_compressed_into — and draws one frame), the probe, the A/B comparison and Save. No colour
// maths here. The WebGL2 side (the transport or coefficient textures, the shader, the canvas's colour
// space and size) is gpu.js's; the URL fragment's text (the run's secret, the state ⇄ the controls'
// values) is state.js's; the plots are plots.js's.
'use strict';

const canvas = document.getElementById('relit');
const $ = (id) => document.getElementById(id);
const kPalette = ['#ffb347', '#6ec6ff', '#b6f36b', '#ff6ec7', '#f3e96b', '#c49bff'];

let info = null;       // /api/info
let frames = 0;
let uiLights = {};     // light name → control state
let lastState = '';

// ---------- server calls ----------

const { enc, splitFragment, specOf, kindValue, chooseKind, fieldsOf } = PrizmaState;
const kTokenKey = 'prizma-relight-token';
let token = null;      // the run's secret: from the URL's fragment, kept in this tab's sessionStorage

// Every API request carries the secret in a header (page_access.h): a page elsewhere cannot send it.
async function request(path, query, method) {
  const headers = token ? { 'X-Prizma-Token': token } : {};
  const r = await fetch(path + (query ? '?' + query : ''), { method: method || 'GET', headers });
  if (r.status === 403) {
    const body = await r.json().catch(() => ({}));
    throw new Error('the server refused this page: ' + (body.error || 'HTTP 403'));
  }
  return r;
}

async function api(path, query, method) {
  const r = await request(path, query, method);
  const body = await r.json();
  if (!r.ok) throw new Error(body.error || ('HTTP ' + r.status));
  return body;
}

// ---------- state: URL fragment ↔ controls ----------

// Takes the secret out of the fragment (into sessionStorage, so a reload of a state-only URL in this
// tab still works) and leaves only the state in the address bar, the history and data-state.
function takeToken() {
  const { token: t, state } = splitFragment(location.hash);
  if (t) {
    token = t;
    try { sessionStorage.setItem(kTokenKey, t); } catch (e) { /* storage off: this load still works */ }
  } else if (!token) {
    try { token = sessionStorage.getItem(kTokenKey); } catch (e) { token = null; }
  }
  if (location.hash !== (state ? '#' + state : '')) {
    history.replaceState(null, '', location.pathname + location.search + (state ? '#' + state : ''));
  }
}

function parseSpec(text, prev) { return PrizmaState.parseSpec(text, info.spectra, prev); }

// Controls from a fragment: the server's starting state first, then the fragment's keys.
function stateToControls(fragment) {
  const s = PrizmaState.stateValues(info.state, fragment, info.lights.map((l) => l.name));
  for (const [name, spec] of Object.entries(s.lights)) uiLights[name] = parseSpec(spec, uiLights[name]);
  $('exposure').value = s.exposure; $('exposure_n').value = s.exposure;
  $('cmf').value = s.cmf; $('display').value = s.display; $('adapt').checked = s.adapt;
  for (const name of Object.keys(uiLights)) syncLightControls(name);
  return s;
}

function controlsToState() {
  return PrizmaState.stateString(info.lights.map((l) => [l.name, specOf(uiLights[l.name])]), {
    exposure: $('exposure_n').value, cmf: $('cmf').value, display: $('display').value, adapt: $('adapt').checked });
}

function currentFragment() { return splitFragment(location.hash).state; }

function onControlChange() {
  const frag = controlsToState();
  history.replaceState(null, '', '#' + frag);
  requestRender(frag);
}

// ---------- controls ----------

function slider(label, min, max, step, onInput) {
  const row = document.createElement('label');
  row.innerHTML = '<span class="k">' + label + '</span>';
  const r = document.createElement('input');
  Object.assign(r, { type: 'range', min, max, step });
  const n = document.createElement('input');
  Object.assign(n, { type: 'number', min, max: max * 10, step });
  r.addEventListener('input', () => { n.value = r.value; onInput(Number(r.value)); });
  n.addEventListener('change', () => { r.value = n.value; onInput(Number(n.value)); });
  row.append(r, n);
  row.set = (v) => { r.value = v; n.value = v; };
  return row;
}

function buildLightControls() {
  const box = $('lights');
  info.lights.forEach((light, index) => {
    const name = light.name;
    uiLights[name] = parseSpec(light.spec);
    const fs = document.createElement('fieldset');
    fs.dataset.light = name;
    fs.innerHTML = '<legend style="color:' + kPalette[index % kPalette.length] + '">light ' + name + '</legend>';
    const on = document.createElement('label');
    on.innerHTML = '<span class="k">on</span>';
    const onBox = document.createElement('input');
    onBox.type = 'checkbox';
    on.append(onBox, document.createTextNode(' default ' + light.default));
    const kindRow = document.createElement('label');
    kindRow.innerHTML = '<span class="k">spectrum</span>';
    const kind = document.createElement('select');
    kind.className = 'kind';
    for (const s of info.spectra) kind.add(new Option(s, 'named:' + s));
    kind.add(new Option('blackbody', 'blackbody'));
    kind.add(new Option('gaussian', 'gaussian'));
    kind.add(new Option('other spec…', 'custom'));
    kindRow.append(kind);
    const l = () => uiLights[name];
    const temp = slider('temperature K', 1000, 20000, 50, (v) => { l().temp = v; onControlChange(); });
    const centre = slider('centre nm', 360, 830, 1, (v) => { l().centre = v; onControlChange(); });
    const fwhm = slider('FWHM nm', 1, 200, 1, (v) => { l().fwhm = v; onControlChange(); });
    const customRow = document.createElement('label');
    customRow.innerHTML = '<span class="k">spec</span>';
    const custom = document.createElement('input');
    custom.type = 'text';
    custom.placeholder = 'box:500:560, 0.5, …';
    customRow.append(custom);
    const scale = slider('intensity', 0, 4, 0.01, (v) => { l().scale = v; onControlChange(); });
    const rows = { temp, centre, fwhm, custom: customRow };  // each kind's parameter rows (fieldsOf)
    for (const [field, row] of Object.entries(rows)) row.dataset.field = field;
    fs.append(on, kindRow, temp, centre, fwhm, customRow, scale);
    box.append(fs);

    onBox.addEventListener('change', () => { l().on = onBox.checked; onControlChange(); });
    // A new kind shows its parameter rows at once (and the spec goes into the URL with them).
    kind.addEventListener('change', () => {
      uiLights[name] = chooseKind(l(), kind.value);
      syncLightControls(name);
      onControlChange();
    });
    custom.addEventListener('change', () => { l().custom = custom.value; onControlChange(); });
    uiLights[name].sync = () => {
      const s = l();
      onBox.checked = s.on;
      kind.value = kindValue(s);
      temp.set(s.temp); centre.set(s.centre); fwhm.set(s.fwhm); custom.value = s.custom; scale.set(s.scale);
      for (const [field, shown] of Object.entries(fieldsOf(s.kind))) rows[field].classList.toggle('hidden', !shown);
    };
  });
}

// parseSpec copies the previous control state, so the control binding (sync) travels with it.
function syncLightControls(name) { (uiLights[name].sync || (() => {}))(); }

function buildGlobalControls() {
  for (const d of info.displays) $('display').add(new Option(d, d));
  $('exposure').addEventListener('input', () => { $('exposure_n').value = $('exposure').value; onControlChange(); });
  $('exposure_n').addEventListener('change', () => { $('exposure').value = $('exposure_n').value; onControlChange(); });
  for (const id of ['cmf', 'display', 'adapt']) $(id).addEventListener('change', onControlChange);
  $('save').addEventListener('click', async () => {
    try {
      const r = await api('/api/save', 'file=' + enc($('savename').value) + '&' + (lastState || currentFragment()), 'POST');
      $('saved').textContent = 'saved ' + r.path;
    } catch (e) { $('saved').textContent = 'error: ' + e.message; }
  });
}

// ---------- render loop: one request in flight, the latest state wins ----------

let pending = null;
let busy = false;

function requestRender(fragment) {
  pending = fragment;
  if (!busy) pump();
}

// Waits until the GPU has drawn the frame (a 1-pixel read), so that the frame time is the GPU's.
function finishFrame() {
  const px = new Uint8Array(4);
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
}

async function pump() {
  busy = true;
  while (pending !== null) {
    const frag = pending;
    pending = null;
    try {
      const shown = shownDisplay(stateDisplay(frag));
      const t0 = performance.now();
      const [w, prog] = await Promise.all([api('/api/weights', frag), programFor(shown.display)]);
      const serverMs = performance.now() - t0;
      await uploadReradiation(stateValue(frag, 'cmf', '1931'));
      setWeights(w);
      currentProgram = prog;
      setCanvasSpace(shown.canvas);
      const t1 = performance.now();
      draw();
      finishFrame();
      const frameMs = performance.now() - t1;
      frames += 1;
      lastState = frag;
      canvas.dataset.frame = String(frames);
      canvas.dataset.state = frag;
      canvas.dataset.shownDisplay = shown.display;
      canvas.dataset.frameMs = frameMs.toFixed(2);
      delete canvas.dataset.error;
      $('status').textContent = '';
      $('notice').textContent = shown.notice;
      $('frameinfo').textContent = 'frame ' + frameMs.toFixed(1) + ' ms (relight + display on the GPU, ' + info.width +
        '×' + info.height + ') · weights ' + serverMs.toFixed(0) + ' ms (server) · canvas ' + canvas.dataset.colourSpace;
      plotSpectra(frag);
      if (hover) probe(hover.x, hover.y);
      if (picks.length === 2) compare();
    } catch (e) {
      canvas.dataset.error = e.message;
      $('status').textContent = e.message;
    }
  }
  busy = false;
}

function stateValue(frag, key, fallback) { return PrizmaState.stateValue(info.state, frag, key, fallback); }

function stateDisplay(frag) { return stateValue(frag, 'display', 'sRGB'); }

// ---------- plots, probe, compare ----------

let spectraBusy = false;
async function plotSpectra(frag) {
  if (spectraBusy) return;
  spectraBusy = true;
  try {
    const r = await api('/api/spectra', frag);
    PrizmaPlots.steps($('spectra'), info.bins, r.lights.map((l, k) => ({ values: l.values, colour: kPalette[k % kPalette.length],
                                                                         label: l.name })), 'relative power');
  } catch (e) { /* the frame's own request reports errors */ } finally { spectraBusy = false; }
}

let hover = null;
let probeBusy = false;
const picks = [];

function pixelOf(ev) {
  const r = canvas.getBoundingClientRect();
  const x = Math.floor((ev.clientX - r.left) / r.width * info.width);
  const y = Math.floor((ev.clientY - r.top) / r.height * info.height);
  return { x: Math.min(Math.max(x, 0), info.width - 1), y: Math.min(Math.max(y, 0), info.height - 1) };
}

const f3 = (v, d) => v.map((x) => x.toFixed(d === undefined ? 4 : d).padStart(8)).join(' ');

// The probed pixel's spectra: the file's bins per light and, when the page relights from
// coefficients, the bins they give (B·c, dashed; in a compact file the only ones there are).
function probeSeries(r) {
  const series = [];
  const compact = info.coefficients && info.coefficients.compact;
  r.bins.forEach((l, k) => {
    const colour = kPalette[k % kPalette.length];
    if (!compact) series.push({ values: l.bins, colour, label: l.name });
    if (l.coefficientBins) {
      series.push({ values: l.coefficientBins, colour, dashed: true,
                    label: l.name + ' (k = ' + info.coefficients.lights[k].k + ')' });
    }
  });
  return series;
}

async function probe(x, y) {
  if (probeBusy) return;
  probeBusy = true;
  try {
    const r = await api('/api/probe', 'x=' + x + '&y=' + y + '&' + lastState);
    $('probe').textContent = 'pixel (' + x + ', ' + y + ')\nXYZ  ' + f3(r.xyz) + '\nLab  ' + f3(r.lab, 2) +
                             '\nsRGB ' + f3(r.srgb);
    PrizmaPlots.steps($('probeplot'), info.bins, probeSeries(r), 'transport');
    if (info.reradiation) {
      const light = r.bins.find((l) => l.name === $('eemlight').value) || r.bins[0];
      $('eeminfo').textContent = PrizmaPlots.excitationEmission($('eem'), info.bins, r, light);
    }
  } catch (e) { $('probe').textContent = e.message; } finally { probeBusy = false; }
}

async function compare() {
  const [a, b] = picks;
  try {
    const r = await api('/api/compare', 'x1=' + a.x + '&y1=' + a.y + '&x2=' + b.x + '&y2=' + b.y + '&' + lastState);
    const row = (name, p, lab) => (name + ' (' + p.x + ', ' + p.y + ')').padEnd(15) + 'Lab' +
                                   lab.map((v) => v.toFixed(2).padStart(8)).join('');
    $('compare').textContent = row('A', a, r.lab1) + '\n' + row('B', b, r.lab2) + '\nΔE00 ' + r.dE00.toFixed(3);
  } catch (e) { $('compare').textContent = e.message; }
}

// The A and B marks over the picked pixels, wherever the image is drawn now.
function placeMarks() {
  ['markA', 'markB'].forEach((id, k) => {
    const m = $(id);
    m.classList.toggle('hidden', k >= picks.length);
    if (k < picks.length) {
      m.style.left = ((picks[k].x + 0.5) / info.width * canvas.clientWidth) + 'px';
      m.style.top = ((picks[k].y + 0.5) / info.height * canvas.clientHeight) + 'px';
    }
  });
}

canvas.addEventListener('mousemove', (ev) => { if (!info) return; hover = pixelOf(ev); probe(hover.x, hover.y); });
canvas.addEventListener('click', (ev) => {
  if (!info) return;
  if (picks.length === 2) picks.length = 0;
  picks.push(pixelOf(ev));
  placeMarks();
  if (picks.length === 2) compare();
  else $('compare').textContent = 'A (' + picks[0].x + ', ' + picks[0].y + '): click a second pixel';
});

// ---------- frame timing (bench/live-page): n draws, each synchronised by a 1-pixel readPixels ----------

window.prizmaBench = {
  drawTimed(n) {
    draw(); finishFrame();
    const t0 = performance.now();
    for (let i = 0; i < n; ++i) { draw(); finishFrame(); }
    return (performance.now() - t0) / n;
  },
};

// ---------- start ----------

// What the page relights from, in words (and data-transport on the canvas): the bins, or the file's
// coefficients with their k and the ΔE00 the file records for them (prizma:coefficients; each light
// and test light in the tooltip).
function describeTransport() {
  canvas.dataset.transport = info.transport;
  if (info.transport !== 'coefficients') return '';
  const lights = info.coefficients.lights;
  const errors = lights.flatMap((c) => c.errors);
  const worst = (key) => Math.max(...errors.map((e) => e[key])).toFixed(2);
  $('transport').title = 'ΔE00 of the coefficients against the bins, 99th percentile / maximum:\n' +
    lights.map((c, i) => info.lights[i].name + ': ' + c.errors.map((e) => e.light + ' ' + e.percentile.toFixed(3) +
                                                                  ' / ' + e.max.toFixed(3)).join(', ')).join('\n');
  return 'relit from spectral-basis coefficients (half floats): ' +
         lights.map((c, i) => info.lights[i].name + ' k = ' + c.k).join(', ') + ' of ' + (info.bins.length - 1) + ' bins' +
         (errors.length ? '; the file\'s ΔE00 p99 ≤ ' + worst('percentile') + ', max ' + worst('max') + ' (hover: each)' : '') +
         (info.coefficients.compact ? '; compact file' : '; --exact: the bins');
}

async function main() {
  try {
    takeToken();
    info = await api('/api/info');
    const what = info.source + ' — ' + info.width + '×' + info.height + ', ' + (info.bins.length - 1) + ' bins ' +
                 info.bins[0] + '–' + info.bins[info.bins.length - 1] + ' nm, lights ' +
                 info.lights.map((l) => l.name).join(', ') + (info.denoised ? ' — ' + info.denoised : '');
    if (info.denoised) document.title += ' (denoised)';
    $('title').textContent = what;
    $('transport').textContent = describeTransport();
    buildLightControls();
    buildGlobalControls();
    if (info.reradiation) {
      $('eembox').classList.remove('hidden');
      for (const l of info.lights) $('eemlight').add(new Option(l.name, l.name));
      $('eemlight').addEventListener('change', () => { if (hover) probe(hover.x, hover.y); });
    }
    setupGL();
    await uploadTransport();
    $('title').textContent = what + ' (prizma ' + info.version + ')';
    window.addEventListener('hashchange', () => {
      takeToken();
      stateToControls(currentFragment());
      requestRender(currentFragment());
    });
    if (!currentFragment()) history.replaceState(null, '', '#' + info.state);
    stateToControls(currentFragment());
    requestRender(currentFragment());
  } catch (e) {
    canvas.dataset.error = e.message;
    $('status').textContent = e.message;
  }
}

main();
