// prizma-relight --serve: the live page's plots, drawn on 2D canvases. Spectra over the file's bins
// as steps (one value per bin) with axes in their units: wavelength in nm, and the quantity named by
// the caller (relative power, transport); and a bispectral pixel's excitation–emission map. Drawing
// only: the values come from the server (app.js asks for them).
'use strict';

const PrizmaPlots = (() => {
  // About `count` round tick values covering [lo, hi]: steps of 1, 2 or 5 × 10^n.
  function ticks(lo, hi, count) {
    if (!(hi > lo)) return [lo];
    const raw = (hi - lo) / Math.max(1, count);
    const p = Math.pow(10, Math.floor(Math.log10(raw)));
    const step = [1, 2, 5, 10].map((m) => m * p).find((s) => s >= raw) || 10 * p;
    const out = [];
    for (let v = Math.ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9; v += step) out.push(Number(v.toPrecision(12)));
    return out;
  }

  // The canvas's backing store at its CSS size × devicePixelRatio (crisp lines and text), and a 2D
  // context scaled so that drawing is in CSS pixels. Returns [ctx, width, height] in CSS pixels.
  function fitCanvas(c) {
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, c.clientWidth), h = Math.max(1, c.clientHeight);
    if (c.width !== Math.round(w * dpr) || c.height !== Math.round(h * dpr)) {
      c.width = Math.round(w * dpr);
      c.height = Math.round(h * dpr);
    }
    const ctx = c.getContext('2d');
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, w, h);
    return [ctx, w, h];
  }

  function label(v) {
    const a = Math.abs(v);
    if (a === 0) return '0';
    if (a >= 1e4 || a < 1e-3) return v.toExponential(0);
    return String(Number(v.toPrecision(3)));
  }

  // Step plot of `series` ([{values, colour, label, dashed}], one value per bin of `edges` nm) with a
  // wavelength axis (nm) and a value axis named `yUnit`, from 0 to the largest value.
  function steps(c, edges, series, yUnit) {
    const [ctx, w, h] = fitCanvas(c);
    const lo = edges[0], hi = edges[edges.length - 1];
    let max = 0;
    for (const s of series) for (const v of s.values) if (isFinite(v)) max = Math.max(max, v);
    if (!(max > 0)) max = 1;
    const yt = ticks(0, max, 4);
    max = Math.max(max, yt[yt.length - 1]);
    ctx.font = '10px sans-serif';
    // Room on the left for the rotated unit (16 px) and the tick labels; on the right for half a label;
    // on top for the series' names, in as many rows as they need.
    const left = 18 + Math.max(...yt.map((v) => ctx.measureText(label(v)).width)) + 6, right = 14, bottom = 30;
    const names = [];
    let nx = left + 4, row = 0;
    for (const s of series) {
      const width = ctx.measureText(s.label).width;
      if (nx + width > w - right && nx > left + 4) { nx = left + 4; row += 1; }
      names.push([nx, 2 + 12 * row]);
      nx += width + 12;
    }
    const top = 16 + 12 * row;
    const X = (nm) => left + (w - left - right) * (nm - lo) / (hi - lo || 1);
    const Y = (v) => h - bottom - (h - top - bottom) * v / max;
    // Axes, grid and tick labels.
    ctx.strokeStyle = '#333';
    ctx.fillStyle = '#999';
    ctx.lineWidth = 1;
    ctx.textAlign = 'right';
    ctx.textBaseline = 'middle';
    for (const v of yt) {
      ctx.beginPath(); ctx.moveTo(left, Math.round(Y(v)) + 0.5); ctx.lineTo(w - right, Math.round(Y(v)) + 0.5); ctx.stroke();
      ctx.fillText(label(v), left - 4, Y(v));
    }
    ctx.textAlign = 'center';
    ctx.textBaseline = 'top';
    for (const nm of ticks(lo, hi, Math.max(2, Math.floor((w - left) / 60)))) {
      ctx.beginPath(); ctx.moveTo(Math.round(X(nm)) + 0.5, h - bottom); ctx.lineTo(Math.round(X(nm)) + 0.5, h - bottom + 4);
      ctx.strokeStyle = '#777'; ctx.stroke();
      ctx.fillText(String(nm), X(nm), h - bottom + 5);
    }
    ctx.strokeStyle = '#777';
    ctx.beginPath(); ctx.moveTo(left, top - 4); ctx.lineTo(left, h - bottom); ctx.lineTo(w - right, h - bottom); ctx.stroke();
    ctx.fillText('wavelength (nm)', (left + w - right) / 2, h - 12);
    ctx.save();
    ctx.translate(8, (top + h - bottom) / 2);
    ctx.rotate(-Math.PI / 2);
    ctx.textBaseline = 'middle';
    ctx.fillText(yUnit, 0, 0);
    ctx.restore();
    // The series, with their names along the top.
    ctx.textAlign = 'left';
    ctx.textBaseline = 'top';
    series.forEach((s, k) => {
      ctx.strokeStyle = s.colour;
      ctx.lineWidth = 1.5;
      ctx.setLineDash(s.dashed ? [4, 3] : []);
      ctx.beginPath();
      for (let i = 0; i < s.values.length; ++i) {
        const y = Y(isFinite(s.values[i]) ? s.values[i] : 0);
        if (i === 0) ctx.moveTo(X(edges[0]), y); else ctx.lineTo(X(edges[i]), y);
        ctx.lineTo(X(edges[i + 1]), y);
      }
      ctx.stroke();
      ctx.setLineDash([]);
      ctx.fillStyle = s.colour;
      ctx.fillText(s.label, names[k][0], names[k][1]);
    });
    c.dataset.yMax = String(max);
  }

  // The excitation–emission map of a probed pixel for one light: M[out][in], excitation (in) to the
  // right, emission (out) upward, one cell per bin pair; colour by value over the pixel's largest
  // off-diagonal value (kRamp); bins the file holds no pair for in #222; the diagonal (T, the plot
  // above) outlined. data-* attributes: the pixel, the light, the largest value, the pairs drawn.
  const kRamp = [[0, 0, 4], [87, 16, 110], [188, 55, 84], [249, 142, 9], [252, 255, 164]];

  function rampColour(t) {
    const x = Math.min(Math.max(t, 0), 1) * (kRamp.length - 1);
    const i = Math.min(Math.floor(x), kRamp.length - 2), f = x - i;
    return kRamp[i].map((a, c) => Math.round(a + (kRamp[i + 1][c] - a) * f));
  }

  // Returns the text that names the largest value (for the caption).
  function excitationEmission(c, edges, pixel, light) {
    const ctx = c.getContext('2d');
    const n = edges.length - 1, cell = Math.floor(c.width / n), size = cell * n;
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
    c.dataset.pixel = pixel.x + ',' + pixel.y;
    c.dataset.light = light.name;
    c.dataset.max = String(max);
    c.dataset.cell = String(cell);
    c.dataset.values = JSON.stringify(light.pairs);
    const nm = (b) => (0.5 * (edges[b] + edges[b + 1])).toFixed(0);
    return 'excitation → (in), emission ↑ (out), light ' + light.name + '\nlargest M ' + max.toPrecision(4) +
           (arg ? ' at ' + nm(arg[0]) + ' → ' + nm(arg[1]) + ' nm' : '');
  }

  return { ticks, steps, excitationEmission };
})();

if (typeof module !== 'undefined') module.exports = PrizmaPlots;
