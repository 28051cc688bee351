// The live page's state handling (relight/serve/web/state.js) under node's test runner: the URL fragment
// ⇄ the controls' values, and the run's secret kept out of every state the page writes.
// ctest relight.live.page_state: node --test tests/e2e/browser/state_test.js
'use strict';
const test = require('node:test');
const assert = require('node:assert/strict');
const path = require('node:path');

const S = require(path.join(__dirname, '..', '..', '..', 'relight', 'serve', 'web', 'state.js'));

const kToken = '3f0c9e2d8a7b41c6a05d1e9f7c2b8a64';
const kStart = 'light.side=D65&light.back=A*0.5&exposure=0&cmf=1931&display=sRGB&adapt=0';
const kSpectra = ['D65', 'D50', 'A', 'E', 'F2', 'F11', 'LED-B1', 'LED-V1'];

test('the printed URL: the secret alone', () => {
  assert.deepEqual(S.splitFragment('#token=' + kToken), { token: kToken, state: '' });
});

test('a state appended after & or after a second # (the form from before the secret)', () => {
  const want = { token: kToken, state: 'light.side=A&exposure=1' };
  assert.deepEqual(S.splitFragment('#token=' + kToken + '&light.side=A&exposure=1'), want);
  assert.deepEqual(S.splitFragment('#token=' + kToken + '#light.side=A&exposure=1'), want);
  assert.deepEqual(S.splitFragment('#light.side=A&token=' + kToken + '&exposure=1'), want);
});

test('a state without a secret, and no fragment at all', () => {
  assert.deepEqual(S.splitFragment('#light.side=A'), { token: null, state: 'light.side=A' });
  assert.deepEqual(S.splitFragment(''), { token: null, state: '' });
  assert.deepEqual(S.splitFragment('#'), { token: null, state: '' });
});

test('fragment → controls → fragment never carries the secret', () => {
  const { state } = S.splitFragment('#token=' + kToken + '&light.back=off&exposure=1.5');
  const v = S.stateValues(kStart, state, ['side', 'back']);
  const out = S.stateString([['side', v.lights.side], ['back', v.lights.back]], v);
  assert.equal(out, 'light.side=D65&light.back=off&exposure=1.5&cmf=1931&display=sRGB&adapt=0');
  assert.ok(!out.includes('token') && !out.includes(kToken));
});

test('missing keys keep the starting state; unknown lights and keys are left to the server', () => {
  const v = S.stateValues(kStart, 'display=Display%20P3&adapt=1&light.fill=D65&colour=red', ['side', 'back']);
  assert.deepEqual(v, { lights: { side: 'D65', back: 'A*0.5' }, exposure: 0, cmf: '1931', display: 'Display P3',
                        adapt: true });
});

test('the browser test\'s states survive the round trip through the controls', () => {
  for (const state of [
    'light.side=D65&light.back=A*2&exposure=6&cmf=1931&display=sRGB&adapt=0',
    'light.side=A&light.back=LED-B1*1.5&exposure=0.5&cmf=1931&display=Display%20P3&adapt=0',
    'light.side=blackbody:2700K&light.back=gaussian:600:30*0.7&exposure=0&cmf=1964&display=Rec.2020&adapt=1',
    'light.side=off&light.back=box:500:560&exposure=-7.5&cmf=2012-10&display=sRGB&adapt=0',
  ]) {
    const v = S.stateValues(kStart, state, ['side', 'back']);
    const lights = ['side', 'back'].map((n) => [n, S.specOf(S.parseSpec(v.lights[n], kSpectra))]);
    assert.equal(S.stateString(lights, v), state);
  }
});

test('light specs → controls', () => {
  assert.deepEqual(S.parseSpec('off', kSpectra).on, false);
  const named = S.parseSpec('LED-B1*1.5', kSpectra);
  assert.equal(named.kind, 'named'); assert.equal(named.named, 'LED-B1'); assert.equal(named.scale, 1.5);
  const bb = S.parseSpec('blackbody:2700K*2*0.5', kSpectra);
  assert.equal(bb.kind, 'blackbody'); assert.equal(bb.temp, 2700); assert.equal(bb.scale, 1);
  const g = S.parseSpec('gaussian:600:30', kSpectra);
  assert.equal(g.kind, 'gaussian'); assert.equal(g.centre, 600); assert.equal(g.fwhm, 30);
  const other = S.parseSpec('csv:lamp.csv', kSpectra, { temp: 5000 });
  assert.equal(other.kind, 'custom'); assert.equal(other.custom, 'csv:lamp.csv'); assert.equal(other.temp, 5000);
});

test('query text: decoding and encoding', () => {
  assert.deepEqual(S.parseQuery('display=Display+P3&a=%26%3D&&b'), [['display', 'Display P3'], ['a', '&='], ['b', '']]);
  assert.equal(S.enc('blackbody:3200K*0.5 & #'), 'blackbody:3200K*0.5%20%26%20%23');
  assert.equal(S.stateValue(kStart, 'cmf=1964', 'cmf', '1931'), '1964');
  assert.equal(S.stateValue(kStart, '', 'display', 'x'), 'sRGB');
});

// Issue 25 item 1: choosing a kind in a light's spectrum menu shows that kind's parameter rows and
// puts its spec into the URL; the URL's spec brings back the same menu entry and parameters.
test('every spectrum kind: menu → controls → spec → controls (round trip), and its rows shown', () => {
  const start = S.parseSpec('D65*0.5', kSpectra);
  const want = {
    'named:F11': { spec: 'F11*0.5', rows: [] },
    blackbody: { spec: 'blackbody:3200K*0.5', rows: ['temp'] },
    gaussian: { spec: 'gaussian:550:40*0.5', rows: ['centre', 'fwhm'] },
    custom: { spec: 'D65*0.5', rows: ['custom'] },  // "other spec…" starts from the spec shown so far
  };
  for (const [value, w] of Object.entries(want)) {
    const l = S.chooseKind(start, value);
    assert.equal(S.kindValue(l), value);
    assert.equal(S.specOf(l), w.spec, value);
    const shown = Object.entries(S.fieldsOf(l.kind)).filter(([, on]) => on).map(([k]) => k);
    assert.deepEqual(shown, w.rows, value);
    // Through the URL and back: the same menu entry, the same spec.
    const v = S.stateValues(kStart, 'light.side=' + S.enc(S.specOf(l)), ['side', 'back']);
    const back = S.parseSpec(v.lights.side, kSpectra);
    assert.equal(S.kindValue(back), value === 'custom' ? 'named:D65' : value);
    assert.equal(S.specOf(back), w.spec);
  }
});

test('a kind\'s parameters move with its sliders into the spec; switching kinds keeps them', () => {
  let l = S.chooseKind(S.parseSpec('A', kSpectra), 'blackbody');
  l = Object.assign(l, { temp: 5600 });
  assert.equal(S.specOf(l), 'blackbody:5600K');
  l = S.chooseKind(l, 'gaussian');
  l = Object.assign(l, { centre: 610, fwhm: 25 });
  assert.equal(S.specOf(l), 'gaussian:610:25');
  l = S.chooseKind(l, 'blackbody');
  assert.equal(S.specOf(l), 'blackbody:5600K');
  l = S.chooseKind(l, 'custom');
  assert.equal(S.specOf(l), 'blackbody:5600K');  // editable from there
  l = S.chooseKind(S.parseSpec('off', kSpectra), 'gaussian');
  assert.equal(l.on, true, 'choosing a spectrum switches an off light on');
});
