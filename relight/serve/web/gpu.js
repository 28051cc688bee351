// prizma-relight --serve: the live page's WebGL2 side (loaded before app.js, which calls it; both
// are classic scripts sharing the page's globals). The transport layers go to a 2D array texture
// once, one layer per light and group of four values (RGBA float or half texels): the bins
// (bispectral files: then each light's re-radiation weights K for the current observer, fetched again
// when it changes), or each light's k spectral-basis coefficients (half: the file's own bits); the
// fragment shader computes XYZ = Σ_l W_l·T_l with the server's weights, then OpenColorIO's own GLSL
// for the display. The canvas is told the colour space of the display it shows (a display no canvas
// colour space holds, Rec.2020, is replaced by one that is, and the page says so), and is sized to
// fit its box.
'use strict';

let gl = null;
let transportTex = null;
const programs = {};    // display name → {program, uniforms, textures}
let uploadedCmf = null; // bispectral files: the observer whose K the texture holds

// Texture groups (4 values each) per light: the bins or coefficients, then K (bispectral files only).
function groupsPerLight() { return info.groups + (info.reradiation ? info.reradiation.groups : 0); }

// ---------- WebGL2 ----------

const kVertex = `#version 300 es
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}`;

function fragmentSource(ocio) {
  const L = info.lights.length, G = groupsPerLight();
  // Σ_l W_l·T_l written out with constant indices (software GPUs index uniform arrays slowly).
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
uniform vec4 u_w[3 * LIGHTS * GROUPS];   // per light and group of 4 values: X, Y, Z weight rows
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
  fitImage();
  new ResizeObserver(fitImage).observe($('stagebox'));
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

// Texel type: float32 unless ?texture=f16 or the float layers would pass 512 MB; coefficients are
// half in the file, so half texels hold them exactly (float ones too, at twice the bytes).
function textureType() {
  const q = new URLSearchParams(location.search).get('texture');
  if (q === 'f16' || q === 'f32') return q;
  if (info.transport === 'coefficients') return 'f16';
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

// The weights into the uniform array: per light and group of 4 values, X, Y, Z rows. A light's w has
// 3 rows of its values per pixel: n bins, or its k coefficients.
function setWeights(w) {
  const L = info.lights.length, G = groupsPerLight();
  const u = new Float32Array(3 * L * G * 4);
  const on = new Int32Array(L);
  w.lights.forEach((light, l) => {
    on[l] = light.on ? 1 : 0;
    const n = light.w.length / 3;
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

// ---------- what the canvas shows: the display, the canvas colour space, the image's size ----------

const canvasSpaces = {};  // colour space → whether this browser's WebGL canvas holds it

// Whether the canvas can be told its pixels are in colour space cs (WebGL's drawingBufferColorSpace;
// a browser without it has sRGB only). An unknown value is ignored by the setter (a WebIDL enum).
function canvasSupports(cs) {
  if (cs === 'srgb') return true;
  if (!('drawingBufferColorSpace' in gl)) return false;
  if (!(cs in canvasSpaces)) {
    const before = gl.drawingBufferColorSpace;
    gl.drawingBufferColorSpace = cs;
    canvasSpaces[cs] = gl.drawingBufferColorSpace === cs;
    gl.drawingBufferColorSpace = before;
  }
  return canvasSpaces[cs];
}

// What the canvas shows for the chosen display: that display in its canvas colour space when the
// browser has one for it (info.displaySpaces, found by the server from the display's primaries, white
// and curve); else the config's display of the widest colour space this canvas holds (display-p3,
// else srgb), with a notice naming both. Save writes the chosen display whatever is shown.
function shownDisplay(chosen) {
  const spaces = info.displaySpaces || {};
  const own = spaces[chosen] || { canvas: null, encoding: 'unknown' };
  if (own.canvas && canvasSupports(own.canvas)) return { display: chosen, canvas: own.canvas, notice: '' };
  const why = own.canvas ? 'this browser\'s canvas has no ' + own.canvas + ' colour space'
                         : 'no browser canvas holds it (they are sRGB or Display P3)';
  for (const want of ['display-p3', 'srgb']) {
    const other = info.displays.find((d) => spaces[d] && spaces[d].canvas === want);
    if (other && canvasSupports(want)) {
      return { display: other, canvas: want, notice: chosen + ' (' + own.encoding + '): ' + why + '. Shown instead: ' +
               other + ', colours outside it clipped; Save writes ' + chosen + '.' };
    }
  }
  return { display: chosen, canvas: 'srgb', notice: chosen + ' (' + own.encoding + '): ' + why +
           ', and the config has no display that it holds: its code values are shown as sRGB (colours wrong).' };
}

function setCanvasSpace(cs) {
  if ('drawingBufferColorSpace' in gl && gl.drawingBufferColorSpace !== cs) gl.drawingBufferColorSpace = cs;
  canvas.dataset.colourSpace = 'drawingBufferColorSpace' in gl ? gl.drawingBufferColorSpace : 'srgb';
}

// The image at the largest size that fits its box: a whole number of device pixels per image pixel
// (crisp; image-rendering: pixelated) when it fits at 1× or more, else scaled down smoothly.
function fitImage() {
  if (!info) return;
  const box = $('stagebox'), dpr = window.devicePixelRatio || 1;
  const room = Math.min(box.clientWidth / info.width, box.clientHeight / info.height) * dpr;
  const zoom = room >= 1 ? Math.floor(room) : Math.max(room, 1 / 64);
  canvas.style.width = info.width * zoom / dpr + 'px';
  canvas.style.height = info.height * zoom / dpr + 'px';
  canvas.classList.toggle('zoomed', zoom >= 1);
  canvas.dataset.zoom = String(zoom);
  placeMarks();
}

