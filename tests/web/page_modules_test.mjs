// The map page's pure modules under node's test runner:
//   node --test tests/web/page_modules_test.mjs   (SKYLANE_BINARY=build/skylane for the zone cases)
// - the event-stream parser against the WHATWG HTML Living Standard's examples and rules;
// - zone applicability against the C++ rule: the zones of tests/data/geozones exported by
//   `skylane zones export`, at the instants tests/airspace/validation_test.cpp checks;
// - the verdict colour of fix events as the tracker writes them;
// - drawn circles: every vertex at the radius by an independent (haversine) distance.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

import { EventStreamParser } from '../../web/src/js/sse.js';
import { isActiveAt, zoneFeatures, heightAboveGround } from '../../web/src/js/zones.js';
import { verdictColour } from '../../web/src/js/flights.js';
import { circlePolygon } from '../../web/src/js/geometry.js';

const repo = resolve(dirname(fileURLToPath(import.meta.url)), '..', '..');
/** Haversine distances on the same sphere as the drawing agree to far below a millimetre. */
const kCircleToleranceM = 1e-6;

test('event stream: data lines join with LF, a blank line dispatches (WHATWG example "YHOO +2 10")', () => {
  const p = new EventStreamParser();
  assert.deepEqual(p.feed('data: YHOO\ndata: +2\ndata: 10\n\n'), [{ type: 'message', data: 'YHOO\n+2\n10', id: '' }]);
});

test('event stream: comments, event and id fields, CRLF and CR line ends split across chunks', () => {
  const p = new EventStreamParser();
  assert.deepEqual(p.feed(': keep-alive\r\nid: 7\r\nevent: fix\r'), []);
  // A CR at a chunk's end waits: it may be the first half of a CRLF.
  assert.deepEqual(p.feed('\ndata: {"a":1}\r\n\r'), []);
  assert.deepEqual(p.feed('\rdata:x\r'), [{ type: 'fix', data: '{"a":1}', id: '7' }]);
  assert.deepEqual(p.feed('\n\n'), [{ type: 'message', data: 'x', id: '7' }]);  // the id stays
  assert.equal(p.lastEventId, '7');
});

test('event stream: no data means no event, but id and retry still count', () => {
  const p = new EventStreamParser();
  assert.deepEqual(p.feed('retry: 1000\n\nid: 12\n\n'), []);
  assert.equal(p.retryMs, 1000);
  assert.equal(p.lastEventId, '12');
  assert.deepEqual(p.feed('data\n\n'), [{ type: 'message', data: '', id: '12' }]);  // a field name alone: empty value
});

function exported(file) {
  const bin = process.env.SKYLANE_BINARY || join(repo, 'build', 'skylane');
  return JSON.parse(execFileSync(bin, ['zones', 'export', join(repo, 'tests/data/geozones', file), '--to', 'geojson'], { encoding: 'utf8' }));
}

test('applicability: schedule edges, midnight and weekdays as the C++ rule (validation_test.cpp)', () => {
  const market = exported('plain_zones.geojson').features[1].properties;  // SAT 21:00Z–01:00Z, 2026
  const at = (s) => isActiveAt(market, Date.parse(s));
  assert.equal(at('2026-06-13T20:59:59Z'), false);
  assert.equal(at('2026-06-13T21:00:00Z'), true);  // start inclusive
  assert.equal(at('2026-06-14T00:59:59Z'), true);  // across midnight
  assert.equal(at('2026-06-14T01:00:00Z'), false);  // end exclusive
  assert.equal(at('2026-06-14T21:30:00Z'), false);  // Sunday evening
  assert.equal(at('2027-01-02T21:30:00Z'), false);  // a Saturday after the end date
  // One feature per zone volume: the first volume of each zone, in the file's zone order.
  const seen = new Set();
  const che = exported('geo-awareness-che-1.json').features.map((f) => f.properties)
    .filter((p) => !seen.has(p.identifier) && seen.add(p.identifier));
  const concert = che[0];
  assert.equal(isActiveAt(concert, Date.parse('2022-06-18T17:00:00Z')), true);
  assert.equal(isActiveAt(concert, Date.parse('2022-06-19T23:59:59.5Z')), true);
  assert.equal(isActiveAt(concert, Date.parse('2022-06-20T17:30:00Z')), false);  // Monday
  assert.equal(isActiveAt(concert, Date.parse('2022-06-11T18:00:00Z')), false);  // before the start date
  assert.equal(isActiveAt(che[1], Date.parse('2022-06-15T09:00:00Z')), true);
  assert.equal(isActiveAt(che[1], Date.parse('2023-06-15T09:00:00Z')), false);
  assert.equal(isActiveAt(che[2], Date.parse('1999-01-01T00:00:00Z')), true);  // permanent
});

test('zones: heights above ground by reference, circles as polygons', () => {
  const ground = { amsl_m: 408, undulation_m: 47.4 };
  assert.equal(heightAboveGround({ value_m: 150, reference: 'AGL', unlimited: false }, ground), 150);
  assert.equal(heightAboveGround({ value_m: 558, reference: 'AMSL', unlimited: false }, ground), 150);
  assert.ok(Math.abs(heightAboveGround({ value_m: 605.4, reference: 'WGS84', unlimited: false }, ground) - 150) < 1e-9);
  const zones = zoneFeatures(exported('plain_zones.geojson'), { id: 'zs-1', name: 'plain' }, ground);
  for (const z of zones) assert.equal(z.geometry.type === 'Polygon' || z.geometry.type === 'MultiPolygon', true);
  assert.ok(zones.every((z) => z.properties.top_m > z.properties.base_m));
});

test('verdict colour: green inside and clear, red on any violated level or met zone, amber indeterminate', () => {
  const inside = { verdict: 'inside', violated: null, levels: { level1: { verdict: 'inside' }, level2: { verdict: 'inside' } },
    near: [{ level: 'zone', verdict: 'clear' }] };
  assert.equal(verdictColour(inside), 'green');
  assert.equal(verdictColour({ ...inside, verdict: 'outside', violated: 'level1',
    levels: { level1: { verdict: 'outside' }, level2: { verdict: 'inside' } } }), 'red');
  assert.equal(verdictColour({ ...inside, near: [{ level: 'zone', verdict: 'met' }] }), 'red');
  assert.equal(verdictColour({ ...inside, levels: { level1: { verdict: 'indeterminate' } } }), 'amber');
  assert.equal(verdictColour(null), 'grey');
});

test('circles: every vertex at the radius (haversine on the same sphere)', () => {
  const R = 6371008.8;
  const rad = Math.PI / 180;
  for (const [lon, lat, r] of [[8.538, 47.379, 250], [179.999, -60, 1000], [0, 89.9, 50]]) {
    const ring = circlePolygon(lon, lat, r).coordinates[0];
    assert.deepEqual(ring[0], ring[ring.length - 1]);
    for (const [x, y] of ring) {
      const h = Math.sin(((y - lat) * rad) / 2) ** 2 + Math.cos(lat * rad) * Math.cos(y * rad) * Math.sin(((x - lon) * rad) / 2) ** 2;
      assert.ok(Math.abs(2 * R * Math.asin(Math.sqrt(h)) - r) < kCircleToleranceM, `${x} ${y}`);
    }
  }
});
