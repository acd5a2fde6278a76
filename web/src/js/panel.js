// The side panel (token form, time slider, legend, stream state, event log) and the popups.
// Every text from the service goes through textContent or escapeHtml: a zone name is data.

import { kRestrictionColours } from './layers.js';
import { kVerdictColours } from './flights.js';

/** Events kept in the panel's log. */
const kLogLength = 60;

export function escapeHtml(s) {
  return String(s).replace(/[&<>"']/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' })[c]);
}

/** Shows the token form; resolves with the token typed in. */
export function askToken(message) {
  const form = document.getElementById('token-form');
  const input = document.getElementById('token-input');
  document.getElementById('token-message').textContent = message || '';
  form.hidden = false;
  input.focus();
  return new Promise((resolve) => {
    form.onsubmit = (e) => {
      e.preventDefault();
      const token = input.value.trim();
      if (!token) return;
      form.hidden = true;
      resolve(token);
    };
  });
}

export function setStatus(text, isError = false) {
  const el = document.getElementById('status');
  el.textContent = text;
  el.classList.toggle('error', isError);
}

export function setStream(state, detail) {
  const el = document.getElementById('stream');
  el.textContent = `events: ${state}${detail ? ` (${detail})` : ''}`;
  el.dataset.state = state;
}

export function fillLegend() {
  const el = document.getElementById('legend');
  const rows = [
    ['PROHIBITED', kRestrictionColours.PROHIBITED, 'fill'], ['REQ_AUTHORISATION', kRestrictionColours.REQ_AUTHORISATION, 'fill'],
    ['CONDITIONAL', kRestrictionColours.CONDITIONAL, 'fill'], ['KEEP_IN', kRestrictionColours.KEEP_IN, 'outline'],
    ['other zones', kRestrictionColours.other, 'fill'], ['level-1 corridor', '#08519c', 'fill'],
    ['level-2 airspace', '#6baed6', 'outline'], ['route (approved / replanned)', '#08306b', 'line'],
    ['flight: all held', kVerdictColours.green, 'dot'], ['flight: indeterminate', kVerdictColours.amber, 'dot'],
    ['flight: violated', kVerdictColours.red, 'dot'],
  ];
  for (const [label, colour, shape] of rows) {
    const row = document.createElement('div');
    const swatch = document.createElement('span');
    swatch.className = `swatch ${shape}`;
    swatch.style.setProperty('--c', colour);
    row.append(swatch, document.createTextNode(label));
    el.append(row);
  }
}

/** The time slider over [min, max] ms; onChange(t) on each move. */
export function initTimeSlider(min, max, initial, onChange) {
  const slider = document.getElementById('time-slider');
  const label = document.getElementById('time-label');
  const kStepMs = 60000;  // one-minute steps
  slider.min = String(Math.floor(min / kStepMs));
  slider.max = String(Math.ceil(max / kStepMs));
  slider.value = String(Math.round(initial / kStepMs));
  const update = () => {
    const t = Number(slider.value) * kStepMs;
    label.textContent = new Date(t).toISOString().replace(/:00\.000Z$/, 'Z');
    onChange(t);
  };
  slider.oninput = update;
  update();
  return { set(t) { slider.value = String(Math.round(t / kStepMs)); update(); } };
}

export function logEvent(event) {
  const list = document.getElementById('event-log');
  const item = document.createElement('li');
  item.className = `ev-${event.event}`;
  const what = event.event === 'violation' ? `${event.level} ${event.verdict || ''}`
    : event.event === 'replan' ? `route v${event.route_version} (${event.decision || ''})`
      : event.event === 'recovered' ? event.level : event.event === 'fix' ? event.verdict : event.error || '';
  item.textContent = `${(event.time || '').slice(11, 19)} ${event.flight || ''} ${event.event} ${what}`;
  list.prepend(item);
  while (list.children.length > kLogLength) list.lastChild.remove();
}

/** The details of a clicked feature as an HTML table (keys that are only for drawing left out). */
export function detailsHtml(feature, others = []) {
  const p = feature.properties || {};
  const hidden = new Set(['colour', 'base_m', 'top_m', 'key', 'current']);
  const title = p.kind === 'zone' ? `${p.restriction} zone ${p.identifier}`
    : p.kind === 'flight' ? `flight ${p.flight}` : p.kind === 'violation' ? `violation, flight ${p.flight}`
      : p.kind === 'corridor' ? `level-1 corridor box, segment ${p.segment}`
        : p.kind === 'airspace' ? `level-2 airspace box, segment ${p.segment}` : p.kind || 'feature';
  const rows = Object.entries(p).filter(([k, v]) => !hidden.has(k) && v !== '' && v !== null)
    .map(([k, v]) => `<tr><th>${escapeHtml(k)}</th><td>${escapeHtml(typeof v === 'number' ? +v.toFixed(3) : v)}</td></tr>`);
  const seen = new Set();
  const also = others.map((f) => f.properties).map((q) => q.identifier || q.flight || (q.segment !== undefined ? `${q.kind} ${q.segment}` : q.kind))
    .filter((name) => name && !seen.has(name) && seen.add(name));
  const alsoHtml = also.length ? `<p class="also">also here: ${also.map(escapeHtml).join(', ')}</p>` : '';
  return `<div class="details"><h3>${escapeHtml(title)}</h3><table>${rows.join('')}</table>${alsoHtml}</div>`;
}
