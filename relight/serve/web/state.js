// prizma-relight --serve: the live page's state, without the page. The URL fragment holds the run's
// secret (token=…, from the URL the server printed) and the view state (light.NAME=SPEC, exposure,
// cmf, display, adapt: docs/relight.md, "State in the URL"); these functions split the two, and turn
// the state into the controls' values and back. No DOM and no server here: the page (app.js, loaded
// after this file) and node's tests (tests/e2e/browser/state_test.js) use the very same code.
'use strict';

const PrizmaState = (() => {
  // encodeURIComponent with ':' kept (the specs' separator reads better unencoded, and the server's
  // url_encode writes it so too).
  function enc(v) { return encodeURIComponent(v).replace(/%3A/g, ':'); }

  // "k=v&k2=v2" → [[k, v], [k2, v2]], decoded ('+' is a space, as in forms).
  function parseQuery(q) {
    const out = [];
    for (const part of q.split('&')) {
      if (!part) continue;
      const eq = part.indexOf('=');
      const k = decodeURIComponent(eq < 0 ? part : part.slice(0, eq));
      const v = decodeURIComponent(eq < 0 ? '' : part.slice(eq + 1).replace(/\+/g, ' '));
      out.push([k, v]);
    }
    return out;
  }

  // A location.hash → { token, state }: the secret (null when the fragment has none) and the view
  // state without it. The printed URL is "…/#token=SECRET"; a state may follow it after '&' or,
  // as users wrote it before there was a secret, after a second '#': "#token=S#light.side=A".
  function splitFragment(hash) {
    let token = null;
    const rest = [];
    for (const part of hash.replace(/^#/, '').split(/[&#]/)) {
      if (!part) continue;
      if (part.startsWith('token=')) token = decodeURIComponent(part.slice(6));
      else rest.push(part);
    }
    return { token, state: rest.join('&') };
  }

  // A light spec → its controls: kind (named / blackbody / gaussian / custom), their parameters,
  // scale (the product of trailing "*x"), on. `spectra`: the named spectra; `prev`: the controls'
  // previous values, kept where the spec does not set them.
  function parseSpec(text, spectra, prev) {
    const l = Object.assign({ on: true, kind: 'named', named: 'D65', temp: 3200, centre: 550, fwhm: 40,
                              custom: '', scale: 1 }, prev || {});
    if (text === 'off') { l.on = false; return l; }
    l.on = true;
    let base = text, scale = 1, m;
    while ((m = /^(.*)\*([0-9.eE+-]+)$/.exec(base)) && isFinite(Number(m[2]))) { base = m[1]; scale *= Number(m[2]); }
    l.scale = scale;
    if (spectra.includes(base)) { l.kind = 'named'; l.named = base; }
    else if ((m = /^blackbody:([0-9.]+)K?$/i.exec(base))) { l.kind = 'blackbody'; l.temp = Number(m[1]); }
    else if ((m = /^gaussian:([0-9.]+):([0-9.]+)$/.exec(base))) { l.kind = 'gaussian'; l.centre = Number(m[1]); l.fwhm = Number(m[2]); }
    else { l.kind = 'custom'; l.custom = base; }
    return l;
  }

  // The controls of one light → its spec.
  function specOf(l) {
    if (!l.on) return 'off';
    let base;
    switch (l.kind) {
      case 'named': base = l.named; break;
      case 'blackbody': base = 'blackbody:' + l.temp + 'K'; break;
      case 'gaussian': base = 'gaussian:' + l.centre + ':' + l.fwhm; break;
      default: base = l.custom;
    }
    return Number(l.scale) === 1 ? base : base + '*' + l.scale;
  }

  // The view of `start` (the server's starting state) with the keys of `fragment` applied:
  // { lights: { NAME: SPEC } for the names in `lightNames`, exposure, cmf, display, adapt }.
  // Unknown keys and lights are ignored here (the server names them when it refuses them).
  function stateValues(start, fragment, lightNames) {
    const s = { lights: {}, exposure: 0, cmf: '1931', display: 'sRGB', adapt: false };
    for (const [k, v] of parseQuery(start).concat(parseQuery(fragment))) {
      if (k.startsWith('light.')) {
        if (lightNames.includes(k.slice(6))) s.lights[k.slice(6)] = v;
      } else if (k === 'exposure') s.exposure = Number(v);
      else if (k === 'cmf') s.cmf = v;
      else if (k === 'display') s.display = v;
      else if (k === 'adapt') s.adapt = v === '1' || v === 'on' || v === 'true';
    }
    return s;
  }

  // The spectrum menu's value for a light's controls: 'named:D65', 'blackbody', 'gaussian', 'custom'.
  function kindValue(l) { return l.kind === 'named' ? 'named:' + l.named : l.kind; }

  // The controls after choosing `value` in a light's spectrum menu: that kind, switched on, with the
  // parameters it had before (temperature, centre, FWHM) or their defaults. "other spec…" starts
  // from the spec shown so far, so the URL holds a spec the server takes from the first frame on.
  function chooseKind(l, value) {
    const out = Object.assign({}, l, { on: true });
    if (value.startsWith('named:')) {
      out.kind = 'named';
      out.named = value.slice(6);
    } else if (value === 'custom') {
      if (!out.custom) out.custom = specOf(Object.assign({}, l, { on: true, scale: 1 }));
      out.kind = 'custom';
    } else {
      out.kind = value;
    }
    return out;
  }

  // Which parameter rows a spectrum kind shows: its own, and only those.
  function fieldsOf(kind) {
    return { temp: kind === 'blackbody', centre: kind === 'gaussian', fwhm: kind === 'gaussian', custom: kind === 'custom' };
  }

  // The state string of a view: every light in `lights` ([[name, spec], …], the file's order),
  // then exposure, cmf, display, adapt. Never the secret.
  function stateString(lights, view) {
    const parts = lights.map(([name, spec]) => 'light.' + enc(name) + '=' + enc(spec));
    parts.push('exposure=' + enc(String(Number(view.exposure))));
    parts.push('cmf=' + enc(view.cmf));
    parts.push('display=' + enc(view.display));
    parts.push('adapt=' + (view.adapt ? '1' : '0'));
    return parts.join('&');
  }

  // The last value of `key` in `start` then `fragment`, else `fallback`.
  function stateValue(start, fragment, key, fallback) {
    let d = fallback;
    for (const [k, v] of parseQuery(start).concat(parseQuery(fragment))) if (k === key) d = v;
    return d;
  }

  return { enc, parseQuery, splitFragment, parseSpec, specOf, kindValue, chooseKind, fieldsOf, stateValues, stateString,
           stateValue };
})();

if (typeof module !== 'undefined') module.exports = PrizmaState;
