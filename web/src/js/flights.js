// Live flights: each one's last fix drawn as its protection volume (a vertical cylinder of
// radius HPL and half-height VPL around the estimated position, docs/method.md) coloured by the
// fix's verdict, a short trail, and the violations as they happen.

import { circlePolygon } from './geometry.js';

export const kVerdictColours = { green: '#1a9850', amber: '#f39c12', red: '#d7191c', grey: '#888888' };
/** Fixes kept per flight for its trail: a few minutes at 1 Hz. */
const kTrailLength = 300;
/** Drawn radius of a cylinder whose fix carries no finite HPL [m]. */
const kUnknownHplDrawnM = 5;

/**
 * The colour of a fix event's verdict: red when any level or zone is violated (the fix's
 * `violated` level, an "outside" overall or per-level verdict, a zone or obstacle "met"), amber
 * when a check is indeterminate, green when every check holds (inside / clear).
 */
export function verdictColour(fix) {
  if (!fix) return 'grey';
  const verdicts = [fix.verdict];
  for (const level of Object.values(fix.levels || {})) verdicts.push(level && level.verdict);
  for (const near of fix.near || []) verdicts.push(near && near.verdict);
  if (fix.violated || verdicts.includes('outside') || verdicts.includes('met')) return 'red';
  if (verdicts.includes('indeterminate')) return 'amber';
  return 'green';
}

export class FlightStore {
  constructor() {
    this.flights_ = new Map();
    this.violations_ = [];
  }

  /** A flight as GET /v1/flights lists it ({id, approval, status, last_fix}). */
  upsert(summary) {
    const f = this.flights_.get(summary.id) || { id: summary.id, trail: [], fix: null };
    f.approval = summary.approval ?? f.approval;
    f.status = summary.status ?? f.status;
    if (summary.last_fix && !f.fix) this.applyFix(f, summary.last_fix);
    this.flights_.set(summary.id, f);
    return f;
  }

  get(id) { return this.flights_.get(id); }

  ids() { return [...this.flights_.keys()]; }

  /** Takes a fix event: the flight's last fix, its colour and trail. */
  fix(event) {
    const f = this.flights_.get(event.flight) || this.upsert({ id: event.flight });
    this.applyFix(f, event);
    return f;
  }

  applyFix(f, event) {
    f.fix = event;
    f.colour = verdictColour(event);
    f.trail.push([event.lon, event.lat]);
    if (f.trail.length > kTrailLength) f.trail.shift();
    // The engine writes a fix's violation events before the fix event itself (tracker.cpp's
    // step order); they are placed at the fix of the same input line.
    const waiting = (f.pendingViolations || []).filter((v) => v.line === event.line || v.line == null);
    for (const v of waiting) this.violations_.push({ at: [event.lon, event.lat], event: v });
    f.pendingViolations = (f.pendingViolations || []).filter((v) => !waiting.includes(v));
  }

  /** A violation event: placed now if its fix is the last one, else when that fix arrives. */
  violation(event) {
    const f = this.flights_.get(event.flight) || this.upsert({ id: event.flight });
    if (f.fix && event.line != null && f.fix.line === event.line) {
      this.violations_.push({ at: [f.fix.lon, f.fix.lat], event });
    } else {
      (f.pendingViolations = f.pendingViolations || []).push(event);
    }
  }

  colour(id) {
    const f = this.flights_.get(id);
    return f ? f.colour || 'grey' : null;
  }

  /** Cylinders (fill-extrusion from h − VPL to h + VPL above `groundH_ell_m`) per flight. */
  cylinders(groundH_ell_m) {
    const out = [];
    for (const f of this.flights_.values()) {
      if (!f.fix) continue;
      const x = f.fix;
      const hpl = Number.isFinite(x.hpl_m) ? x.hpl_m : kUnknownHplDrawnM;
      const vpl = Number.isFinite(x.vpl_m) ? x.vpl_m : hpl;
      const h = x.h_ell_m - groundH_ell_m;
      out.push({ type: 'Feature', geometry: circlePolygon(x.lon, x.lat, hpl),
        properties: { kind: 'flight', flight: f.id, approval: f.approval || '', status: f.status || '',
          colour: kVerdictColours[f.colour], verdict_colour: f.colour, time: x.time || '', verdict: x.verdict || '',
          violated: x.violated || '', hpl_m: x.hpl_m, vpl_m: x.vpl_m, h_ell_m: x.h_ell_m,
          levels: JSON.stringify(x.levels || {}), near: JSON.stringify(x.near || []),
          route_version: x.route_version ?? '', base_m: Math.max(0, h - vpl), top_m: Math.max(0.5, h + vpl) } });
    }
    return out;
  }

  /** The estimated positions, drawn as dots visible at any zoom. */
  points() {
    return [...this.flights_.values()].filter((f) => f.fix).map((f) => ({ type: 'Feature',
      geometry: { type: 'Point', coordinates: [f.fix.lon, f.fix.lat] },
      properties: { kind: 'flight', flight: f.id, colour: kVerdictColours[f.colour], verdict_colour: f.colour,
        time: f.fix.time || '', verdict: f.fix.verdict || '', violated: f.fix.violated || '',
        hpl_m: f.fix.hpl_m, vpl_m: f.fix.vpl_m } }));
  }

  trails() {
    return [...this.flights_.values()].filter((f) => f.trail.length >= 2).map((f) => ({ type: 'Feature',
      geometry: { type: 'LineString', coordinates: f.trail }, properties: { kind: 'trail', flight: f.id } }));
  }

  violations() {
    return this.violations_.map((v, i) => ({ type: 'Feature', id: i,
      geometry: { type: 'Point', coordinates: v.at },
      properties: { kind: 'violation', flight: v.event.flight, time: v.event.time || '',
        details: JSON.stringify(v.event) } }));
  }

  count() { return [...this.flights_.values()].filter((f) => f.fix).length; }

  violationCount() { return this.violations_.length; }
}
