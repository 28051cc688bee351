// prizma-relight --serve: the live relighting page. The transport layers go to the GPU once
// (RGBA float or half texels, four bins each, one layer of a 2D array texture per light and group
// of four bins); each change of a control asks the server for the exact relight weights
// (RelightMatrix, the C++ code of prizma-relight) and the display transform (OpenColorIO's own
// GLSL), and the fragment shader computes XYZ = Σ_l M_l·T_l then the display. No colour maths here.
// Bispectral (fluorescent) files: each light has more texture layers after its bins, its per-pixel
// re-radiation weights K for the current observer (fetched again when the observer changes), with
// weights from the server (wr), so the shader adds the re-radiated light in the same sum.
// The URL fragment's text (the run's secret, the state ⇄ the controls' values) is state.js's.
'use strict';

const canvas = document.getElementById('relit');
const $ = (id) => document.getElementById(id);
const kPalette = ['#ffb347', '#6ec6ff', '#b6f36b', '#ff6ec7', '#f3e96b', '#c49bff'];

let info = null;       // /api/info
let gl = null;
let transportTex = null;
const programs = {};   // display name → {program, uniforms, textures}
let frames = 0;
let uiLights = {};     // light name → control state
let lastState = '';
let uploadedCmf = null; // bispectral files: the observer whose K the texture holds

// Texture groups (4 values each) per light: the bins, then K (bispectral files only).
function groupsPerLight() { return info.groups + (info.reradiation ? info.reradiation.groups : 0); }

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

// ---------- WebGL2 ----------

const kVertex = `#version 300 es
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}`;

function fragmentSource(ocio) {
  const L = info.lights.length, G = groupsPerLight();
  // Σ_l M_l·T_l written out with constant indices (software GPUs index uniform arrays slowly).
  let sum = '';
  for (let l = 0; l < L; ++l) {
    sum += '  if (u_on[' + l + ']) {\n';
    for (let g = 0; g < G; ++g) {
      const k = l * G + g;
      sum += '    t = texelFetch(u_transport, ivec3(p, ' + k + '), 0);\n' +
             '    xyz += vec3(dot(u_w[' + 3 * k + '], t), dot(u_w[' + (3 * k + 1) + '], t), dot(u_w[' + (3 * k + 2) +
             '], t));\n';
    }
    sum += '  }\n';
  }
  return `#version 300 es
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp sampler3D;
precision highp sampler2DArray;
#define LIGHTS ${L}
#define GROUPS ${G}
uniform sampler2DArray u_transport;
uniform vec4 u_w[3 * LIGHTS * GROUPS];   // per light and group of 4 bins: X, Y, Z weight rows
uniform bool u_on[LIGHTS];
uniform int u_height;
out vec4 fragColor;

// ---- OpenColorIO (GpuShaderDesc, GLSL ES 3.0), as generated for this display ----
${ocio.glsl}
// ---- end of OpenColorIO ----

void main() {
  ivec2 p = ivec2(int(gl_FragCoord.x), u_height - 1 - int(gl_FragCoord.y));
  vec3 xyz = vec3(0.0);
  vec4 t;
${sum}
  // As the CPU path: non-finite values become 0, the display output is clamped to [0, 1].
  for (int c = 0; c < 3; ++c) if (isnan(xyz[c]) || isinf(xyz[c])) xyz[c] = 0.0;
  vec4 rgb = ${ocio.function}(vec4(xyz, 1.0));
  fragColor = vec4(clamp(rgb.rgb, 0.0, 1.0), 1.0);
}`;
}

function compile(type, src) {
  const s = gl.createShader(type);
  gl.shaderSource(s, src);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error('shader: ' + gl.getShaderInfoLog(s));
  return s;
}

async function programFor(display) {
  if (programs[display]) return programs[display];
  const ocio = await api('/api/display', 'name=' + enc(display));
  const prog = gl.createProgram();
  gl.attachShader(prog, compile(gl.VERTEX_SHADER, kVertex));
  gl.attachShader(prog, compile(gl.FRAGMENT_SHADER, fragmentSource(ocio)));
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error('link: ' + gl.getProgramInfoLog(prog));
  gl.useProgram(prog);
  gl.uniform1i(gl.getUniformLocation(prog, 'u_transport'), 0);
  gl.uniform1i(gl.getUniformLocation(prog, 'u_height'), info.height);
  // OCIO's uniforms (dynamic properties) and LUT textures, as OCIO described them.
  for (const u of ocio.uniforms) {
    const loc = gl.getUniformLocation(prog, u.name);
    if (u.type === 'double') gl.uniform1f(loc, u.values[0]);
    else if (u.type === 'bool') gl.uniform1i(loc, u.values[0] ? 1 : 0);
    else if (u.type === 'float3') gl.uniform3fv(loc, u.values);
    else if (u.type === 'vector_float') gl.uniform1fv(loc, u.values);
    else if (u.type === 'vector_int') gl.uniform1iv(loc, u.values);
  }
  const textures = ocio.textures.map((t, i) => {
    const tex = gl.createTexture();
    const target = t.depth > 0 ? gl.TEXTURE_3D : gl.TEXTURE_2D;
    gl.activeTexture(gl.TEXTURE1 + i);
    gl.bindTexture(target, tex);
    const fmt = t.channels === 1 ? [gl.R32F, gl.RED] : [gl.RGB32F, gl.RGB];
    const data = new Float32Array(t.values);
    if (t.depth > 0) gl.texImage3D(target, 0, fmt[0], t.width, t.height, t.depth, 0, fmt[1], gl.FLOAT, data);
    else gl.texImage2D(target, 0, fmt[0], t.width, t.height, 0, fmt[1], gl.FLOAT, data);
    const filter = t.linear && gl.getExtension('OES_texture_float_linear') ? gl.LINEAR : gl.NEAREST;
    gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, filter);
    gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, filter);
    for (const w of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R]) gl.texParameteri(target, w, gl.CLAMP_TO_EDGE);
    gl.uniform1i(gl.getUniformLocation(prog, t.sampler), 1 + i);
    return { tex, target };
  });
  gl.activeTexture(gl.TEXTURE0);
  programs[display] = {
    prog, textures,
    w: gl.getUniformLocation(prog, 'u_w'),
    on: gl.getUniformLocation(prog, 'u_on'),
  };
  return programs[display];
}

function setupGL() {
  gl = canvas.getContext('webgl2', { antialias: false, depth: false, stencil: false, alpha: false,
                                     preserveDrawingBuffer: true, premultipliedAlpha: false });
  if (!gl) throw new Error('this browser has no WebGL2');
  canvas.width = info.width;
  canvas.height = info.height;
  // Shown at an integer zoom (pixels stay square) that fits the view, or scaled down to fit it.
  const room = Math.max(200, $('view').clientWidth);
  const zoom = info.width <= room ? Math.min(8, Math.floor(room / info.width)) : room / info.width;
  canvas.style.width = Math.round(info.width * zoom) + 'px';
  canvas.style.height = Math.round(info.height * zoom) + 'px';
  const layers = info.lights.length * groupsPerLight();
  const need = 3 * layers + 8;
  if (need > gl.getParameter(gl.MAX_FRAGMENT_UNIFORM_VECTORS)) {
    throw new Error(layers * 4 + ' bins × lights need ' + need + ' uniform vectors, this GPU has ' +
                    gl.getParameter(gl.MAX_FRAGMENT_UNIFORM_VECTORS));
  }
  if (layers > gl.getParameter(gl.MAX_ARRAY_TEXTURE_LAYERS) ||
      Math.max(info.width, info.height) > gl.getParameter(gl.MAX_TEXTURE_SIZE)) {
    throw new Error('the image is larger than this GPU\'s textures');
  }
}

// Texel type: float32 unless ?texture=f16 or the float layers would pass 512 MB.
function textureType() {
  const q = new URLSearchParams(location.search).get('texture');
  if (q === 'f16' || q === 'f32') return q;
  const bytes = info.width * info.height * 16 * info.lights.length * groupsPerLight();
  return bytes > 512 * 1024 * 1024 ? 'f16' : 'f32';
}

async function uploadTransport() {
  const type = textureType();
  const half = type === 'f16';
  transportTex = gl.createTexture();
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D_ARRAY, transportTex);
  const layers = info.lights.length * groupsPerLight();
  gl.texStorage3D(gl.TEXTURE_2D_ARRAY, 1, half ? gl.RGBA16F : gl.RGBA32F, info.width, info.height, layers);
  gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  for (let l = 0; l < info.lights.length; ++l) {
    for (let g = 0; g < info.groups; ++g) {
      $('title').textContent = 'loading transport ' + (l * info.groups + g + 1) + '/' + layers + ' (' + type + ')';
      await uploadLayer(l, g, type, '');
    }
  }
  canvas.dataset.texture = type;
}

async function uploadLayer(l, g, type, cmf) {
  const half = type === 'f16';
  const r = await request('/api/transport', 'light=' + l + '&group=' + g + '&type=' + type + (cmf ? '&cmf=' + enc(cmf) : ''));
  if (!r.ok) throw new Error('transport: HTTP ' + r.status);
  const buf = await r.arrayBuffer();
  const data = half ? new Uint16Array(buf) : new Float32Array(buf);
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D_ARRAY, transportTex);
  gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, 0, 0, 0, l * groupsPerLight() + g, info.width, info.height, 1, gl.RGBA,
                   half ? gl.HALF_FLOAT : gl.FLOAT, data);
}

// Bispectral files: K of every light for observer cmf into the layers after the bins.
async function uploadReradiation(cmf) {
  if (!info.reradiation || cmf === uploadedCmf) return;
  for (let l = 0; l < info.lights.length; ++l)
    for (let g = 0; g < info.reradiation.groups; ++g) await uploadLayer(l, info.groups + g, canvas.dataset.texture, cmf);
  uploadedCmf = cmf;
  canvas.dataset.reradiationCmf = cmf;
}

let currentWeights = null;   // Float32Array for u_w
let currentOn = null;
let currentProgram = null;

function setWeights(w) {
  const L = info.lights.length, G = groupsPerLight(), n = info.bins.length - 1;
  const u = new Float32Array(3 * L * G * 4);
  const on = new Int32Array(L);
  w.lights.forEach((light, l) => {
    on[l] = light.on ? 1 : 0;
    for (let c = 0; c < 3; ++c)
      for (let i = 0; i < n; ++i) {
        const g = Math.floor(i / 4);
        u[((l * G + g) * 3 + c) * 4 + (i % 4)] = light.w[c * n + i];
      }
    if (light.wr) {  // the weights of K: 3 rows of 3·|in| values
      const nk = light.wr.length / 3;
      for (let c = 0; c < 3; ++c)
        for (let j = 0; j < nk; ++j) {
          const g = info.groups + Math.floor(j / 4);
          u[((l * G + g) * 3 + c) * 4 + (j % 4)] = light.wr[c * nk + j];
        }
    }
  });
  currentWeights = u;
  currentOn = on;
}

function draw() {
  const p = currentProgram;
  gl.viewport(0, 0, info.width, info.height);
  gl.useProgram(p.prog);
  gl.uniform4fv(p.w, currentWeights);
  gl.uniform1iv(p.on, currentOn);
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D_ARRAY, transportTex);
  p.textures.forEach((t, i) => { gl.activeTexture(gl.TEXTURE1 + i); gl.bindTexture(t.target, t.tex); });
  gl.activeTexture(gl.TEXTURE0);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
}

// ---------- render loop: one request in flight, the latest state wins ----------

let pending = null;
let busy = false;

function requestRender(fragment) {
  pending = fragment;
  if (!busy) pump();
}

async function pump() {
  busy = true;
  while (pending !== null) {
    const frag = pending;
    pending = null;
    try {
      const display = stateDisplay(frag);
      const [w, prog] = await Promise.all([api('/api/weights', frag), programFor(display)]);
      await uploadReradiation(stateValue(frag, 'cmf', '1931'));
      setWeights(w);
      currentProgram = prog;
      draw();
      frames += 1;
      lastState = frag;
      canvas.dataset.frame = String(frames);
      canvas.dataset.state = frag;
      delete canvas.dataset.error;
      $('status').textContent = '';
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

function plotSteps(ctx, series, w, h, labels) {
  ctx.clearRect(0, 0, w, h);
  const edges = info.bins;
  const lo = edges[0], hi = edges[edges.length - 1];
  let max = 0;
  for (const s of series) for (const v of s.values) max = Math.max(max, v);
  if (!(max > 0)) max = 1;
  const X = (nm) => 4 + (w - 8) * (nm - lo) / (hi - lo || 1);
  const Y = (v) => h - 14 - (h - 22) * v / max;
  ctx.strokeStyle = '#555';
  ctx.fillStyle = '#888';
  ctx.font = '10px sans-serif';
  ctx.beginPath(); ctx.moveTo(4, h - 14); ctx.lineTo(w - 4, h - 14); ctx.stroke();
  ctx.fillText(lo.toFixed(0) + ' nm', 4, h - 2);
  ctx.fillText(hi.toFixed(0) + ' nm', w - 40, h - 2);
  series.forEach((s, k) => {
    ctx.strokeStyle = s.colour;
    ctx.beginPath();
    for (let i = 0; i < s.values.length; ++i) {
      const y = Y(s.values[i]);
      if (i === 0) ctx.moveTo(X(edges[0]), y); else ctx.lineTo(X(edges[i]), y);
      ctx.lineTo(X(edges[i + 1]), y);
    }
    ctx.stroke();
    if (labels) { ctx.fillStyle = s.colour; ctx.fillText(s.label, 8 + 70 * k, 10); }
  });
}

let spectraBusy = false;
async function plotSpectra(frag) {
  if (spectraBusy) return;
  spectraBusy = true;
  try {
    const r = await api('/api/spectra', frag);
    const c = $('spectra');
    plotSteps(c.getContext('2d'), r.lights.map((l, k) => ({ values: l.values, colour: kPalette[k % kPalette.length],
                                                              label: l.name })), c.width, c.height, true);
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

const f3 = (v, d) => v.map((x) => x.toFixed(d === undefined ? 4 : d)).join(' ');

async function probe(x, y) {
  if (probeBusy) return;
  probeBusy = true;
  try {
    const r = await api('/api/probe', 'x=' + x + '&y=' + y + '&' + lastState);
    $('probe').textContent = 'pixel (' + x + ', ' + y + ')   sRGB ' + f3(r.srgb) + '   Lab ' + f3(r.lab, 2) +
                             '   XYZ ' + f3(r.xyz);
    const c = $('probeplot');
    plotSteps(c.getContext('2d'), r.bins.map((l, k) => ({ values: l.bins, colour: kPalette[k % kPalette.length],
                                                          label: 'T ' + l.name })), c.width, c.height, true);
    if (info.reradiation) drawExcitationEmission(r);
  } catch (e) { $('probe').textContent = e.message; } finally { probeBusy = false; }
}

// The excitation–emission map of the probed pixel for one light: M[out][in], excitation (in) to the
// right, emission (out) upward, one cell per bin pair; colour by value over the pixel's largest
// off-diagonal value (kRamp); bins the file holds no pair for in #222; the diagonal (T, the plot
// beside it) outlined. data-* attributes: the pixel, the light, the largest value, the pairs drawn.
const kRamp = [[0, 0, 4], [87, 16, 110], [188, 55, 84], [249, 142, 9], [252, 255, 164]];

function rampColour(t) {
  const x = Math.min(Math.max(t, 0), 1) * (kRamp.length - 1);
  const i = Math.min(Math.floor(x), kRamp.length - 2), f = x - i;
  return kRamp[i].map((a, c) => Math.round(a + (kRamp[i + 1][c] - a) * f));
}

function drawExcitationEmission(r) {
  const sel = $('eemlight');
  const light = r.bins.find((l) => l.name === sel.value) || r.bins[0];
  const c = $('eem'), ctx = c.getContext('2d');
  const n = info.bins.length - 1, cell = Math.floor(c.width / n), size = cell * n;
  let max = 0, arg = null;
  for (const [i, o, v] of light.pairs) if (v > max) { max = v; arg = [i, o]; }
  ctx.fillStyle = '#111';
  ctx.fillRect(0, 0, c.width, c.height);
  ctx.fillStyle = '#222';
  ctx.fillRect(0, c.height - size, size, size);
  for (const [i, o, v] of light.pairs) {
    const [R, G, B] = rampColour(max > 0 ? v / max : 0);
    ctx.fillStyle = 'rgb(' + R + ',' + G + ',' + B + ')';
    ctx.fillRect(i * cell, c.height - (o + 1) * cell, cell, cell);
  }
  ctx.strokeStyle = '#777';
  for (let i = 0; i < n; ++i) ctx.strokeRect(i * cell + 0.5, c.height - (i + 1) * cell + 0.5, cell - 1, cell - 1);
  c.dataset.pixel = r.x + ',' + r.y;
  c.dataset.light = light.name;
  c.dataset.max = String(max);
  c.dataset.cell = String(cell);
  c.dataset.values = JSON.stringify(light.pairs);
  const nm = (b) => (0.5 * (info.bins[b] + info.bins[b + 1])).toFixed(0);
  $('eeminfo').textContent = 'excitation → (in), emission ↑ (out), light ' + light.name + '\nlargest M ' +
    max.toPrecision(4) + (arg ? ' at ' + nm(arg[0]) + ' → ' + nm(arg[1]) + ' nm' : '');
}

async function compare() {
  const [a, b] = picks;
  try {
    const r = await api('/api/compare', 'x1=' + a.x + '&y1=' + a.y + '&x2=' + b.x + '&y2=' + b.y + '&' + lastState);
    $('compare').textContent = 'A (' + a.x + ', ' + a.y + ') Lab ' + f3(r.lab1, 2) + '\nB (' + b.x + ', ' + b.y +
                               ') Lab ' + f3(r.lab2, 2) + '\nΔE00 ' + r.dE00.toFixed(3);
  } catch (e) { $('compare').textContent = e.message; }
}

canvas.addEventListener('mousemove', (ev) => { if (!info) return; hover = pixelOf(ev); probe(hover.x, hover.y); });
canvas.addEventListener('click', (ev) => {
  if (!info) return;
  if (picks.length === 2) picks.length = 0;
  picks.push(pixelOf(ev));
  ['markA', 'markB'].forEach((id, k) => {
    const m = $(id);
    m.classList.toggle('hidden', k >= picks.length);
    if (k < picks.length) {
      m.style.left = ((picks[k].x + 0.5) / info.width * canvas.clientWidth) + 'px';
      m.style.top = ((picks[k].y + 0.5) / info.height * canvas.clientHeight) + 'px';
    }
  });
  if (picks.length === 2) compare();
  else $('compare').textContent = 'A (' + picks[0].x + ', ' + picks[0].y + '): click a second pixel';
});

// ---------- frame timing (bench/live-page): n draws, each synchronised by a 1-pixel readPixels ----------

window.prizmaBench = {
  drawTimed(n) {
    const px = new Uint8Array(4);
    draw(); gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const t0 = performance.now();
    for (let i = 0; i < n; ++i) { draw(); gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px); }
    return (performance.now() - t0) / n;
  },
};

// ---------- start ----------

async function main() {
  try {
    takeToken();
    info = await api('/api/info');
    $('title').textContent = info.source + ' — ' + info.width + '×' + info.height + ', ' + (info.bins.length - 1) +
                             ' bins ' + info.bins[0] + '–' + info.bins[info.bins.length - 1] + ' nm, lights ' +
                             info.lights.map((l) => l.name).join(', ');
    buildLightControls();
    buildGlobalControls();
    if (info.reradiation) {
      $('eembox').classList.remove('hidden');
      for (const l of info.lights) $('eemlight').add(new Option(l.name, l.name));
      $('eemlight').addEventListener('change', () => { if (hover) probe(hover.x, hover.y); });
    }
    setupGL();
    await uploadTransport();
    $('title').textContent = info.source + ' — ' + info.width + '×' + info.height + ', ' + (info.bins.length - 1) +
                             ' bins, lights ' + info.lights.map((l) => l.name).join(', ') + ' (prizma ' +
                             info.version + ')';
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
