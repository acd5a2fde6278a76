// The operator's web map against a real `skylane serve`, in headless Chromium (playwright-core):
// the authority uploads the example zones, an operator has the example mission approved and
// starts its flight, the page loads with no console error and only loopback requests, its
// layers hold the numbers of features the inputs give, a violating fix posted to the service
// turns the flight red within 1 s, and screenshots go to the output folder for a person.
//
// node tests/web/map_test.mjs --skylane BIN --web BUILT_PAGE --modules NODE_MODULES --out DIR [--source REPO]
// (ctest runs it with the label `service`; the service serves the built page at /).

import { spawn, spawnSync } from 'node:child_process';
import { createHash, randomBytes } from 'node:crypto';
import { copyFileSync, mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

/** A violating fix must turn its flight red within this time of being posted [ms] (issue 20). */
const kRedWithinMs = 1000;
/** The service's start (database, tokens) [ms]. */
const kServiceStartMs = 30000;
/** An approval of the example mission (RRT* for 3 s, the PL prediction) [ms]. */
const kApprovalMs = 180000;
/** Lateral offset of the violating fix from the route [m]: far outside level 1 (±1.44 m), inside level 2 (±180 m). */
const kViolationOffsetM = 12;
/** Mean Earth radius [m] for the small offsets of the test's fixes. */
const kEarthRadiusM = 6371008.8;
/** The example's ground height above mean sea level [m] (examples/approve/mission.json, ground_amsl_m). */
const kGroundAmslM = 408;

const checks = [];
function check(name, ok, detail = '') {
  checks.push({ name, ok: !!ok });
  console.log(`${ok ? 'PASS' : 'FAIL'} ${name}${detail ? `: ${detail}` : ''}`);
}

function parseArgs(argv) {
  const here = dirname(fileURLToPath(import.meta.url));
  const a = { source: resolve(here, '..', '..') };
  for (let i = 0; i < argv.length; i += 2) {
    if (!argv[i].startsWith('--') || i + 1 >= argv.length) throw new Error(`map_test: argument ${argv[i]}: expected --name value`);
    a[argv[i].slice(2)] = resolve(argv[i + 1]);
  }
  for (const k of ['skylane', 'web', 'modules', 'out']) if (!a[k]) throw new Error(`map_test: --${k} is required`);
  return a;
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const sha256 = (s) => createHash('sha256').update(s).digest('hex');

/** Starts `skylane serve` on a free loopback port with its own database and tokens. */
async function startService(args, tmp) {
  const tokens = { authority: randomBytes(24).toString('hex'), operator: randomBytes(24).toString('hex') };
  writeFileSync(join(tmp, 'tokens.json'), JSON.stringify({ tokens: [
    { sha256: sha256(tokens.operator), operator: 'acme' }, { sha256: sha256(tokens.authority), role: 'authority' }] }));
  const orbits = join(tmp, 'orbits');
  mkdirSync(orbits);
  copyFileSync(join(args.source, 'tests/data/gnss/alm01jan2020.txt'), join(orbits, 'alm01jan2020.txt'));
  // --port 0: the service takes a free port and prints it ("skylane: serving on http://HOST:PORT/").
  const proc = spawn(args.skylane, ['serve', '--tokens', join(tmp, 'tokens.json'), '--db', join(tmp, 'service.sqlite'),
    '--host', '127.0.0.1', '--port', '0', '--orbits', orbits, '--web', args.web], { stdio: ['ignore', 'pipe', 'pipe'] });
  let log = '';
  proc.stdout.on('data', (d) => { log += d; });
  proc.stderr.on('data', (d) => { log += d; });
  const until = Date.now() + kServiceStartMs;
  let base = null;
  for (;;) {
    if (proc.exitCode !== null) throw new Error(`skylane serve exited ${proc.exitCode}: ${log}`);
    base = base || (/serving on (http:\/\/127\.0\.0\.1:\d+)\//.exec(log) || [])[1];
    try {
      if (base && (await fetch(`${base}/healthz`)).ok) break;
    } catch (_) { /* not answering yet */ }
    if (Date.now() > until) throw new Error(`skylane serve did not answer /healthz in ${kServiceStartMs} ms: ${log}`);
    await sleep(100);
  }
  return { proc, base, tokens, log: () => log };
}

async function stopService(service) {
  if (service.proc.exitCode !== null) return;
  const exited = new Promise((r) => service.proc.once('exit', r));
  service.proc.kill('SIGTERM');
  if (await Promise.race([exited.then(() => true), sleep(10000).then(() => false)])) return;
  service.proc.kill('SIGKILL');
  await exited;
}

async function call(service, token, method, path, body, type = 'application/json') {
  const headers = { Authorization: `Bearer ${token}` };
  if (body !== undefined) headers['Content-Type'] = type;
  const r = await fetch(service.base + path, { method, headers, body });
  const text = await r.text();
  let json = null;
  try { json = JSON.parse(text); } catch (_) { /* a non-JSON body (mission.plan, svg) */ }
  if (!r.ok) throw new Error(`${method} ${path}: HTTP ${r.status}: ${text}`);
  return json;
}

/** The example mission, zones by zone set id, with nothing that names a file on the server. */
function missionFor(args, zonesetId) {
  const m = JSON.parse(readFileSync(join(args.source, 'examples/approve/mission.json'), 'utf8'));
  delete m.zones;
  delete m.buildings;
  delete m.orbits;  // the service's --orbits directory gives the almanac
  m.zonesets = [zonesetId];
  return m;
}

async function approve(service, mission) {
  const token = service.tokens.operator;
  const { id } = await call(service, token, 'POST', '/v1/approvals', JSON.stringify(mission));
  const until = Date.now() + kApprovalMs;
  for (;;) {
    const a = await call(service, token, 'GET', `/v1/approvals/${id}`);
    if (a.status === 'approved') return id;
    if (a.status === 'rejected' || a.status === 'failed') throw new Error(`approval ${id} ${a.status}: ${JSON.stringify(a)}`);
    if (Date.now() > until) throw new Error(`approval ${id} still ${a.status} after ${kApprovalMs} ms`);
    await sleep(250);
  }
}

/**
 * A fix `t_s` after departure on the route's first leg (its points' times, linear between them),
 * moved `offset_m` to the left of the leg.
 */
function fixOnFirstLeg(report, flight, t_s, offset_m) {
  const [a, b] = report.route;
  const f = (t_s - a.eta_s) / (b.eta_s - a.eta_s);
  const lat = a.lat + f * (b.lat - a.lat);
  const lon = a.lon + f * (b.lon - a.lon);
  const coslat = Math.cos((lat * Math.PI) / 180);
  const e = (b.lon - a.lon) * coslat;
  const n = b.lat - a.lat;
  const len = Math.hypot(e, n);
  const dLat = ((e / len) * offset_m / kEarthRadiusM) * (180 / Math.PI);
  const dLon = ((-n / len) * offset_m / (kEarthRadiusM * coslat)) * (180 / Math.PI);
  const time = new Date(Date.parse(report.departure) + t_s * 1000).toISOString();
  return JSON.stringify({ flight, time, lat: lat + dLat, lon: lon + dLon, h_ell_m: a.h_ell_m + f * (b.h_ell_m - a.h_ell_m),
    hpl_m: 0.5, vpl_m: 0.6 });
}

/** Identifiers of an ED-269 file's zones that apply at t [ms]: permanent, or t in [start, end) (no schedules in the example). */
function ed269ActiveAt(doc, t) {
  return doc.UASZoneList.filter((z) => (z.applicability || []).length === 0 || z.applicability.some((a) =>
    a.permanent === 'YES' || (Date.parse(a.startDateTime) <= t && t < Date.parse(a.endDateTime))))
    .map((z) => z.identifier).sort();
}

/** Chromium headless with software WebGL (SwiftShader), a fresh profile, no network of its own. */
async function openBrowser(args, tmp) {
  const { chromium } = await import(join(args.modules, 'playwright-core', 'index.mjs'));
  return chromium.launchPersistentContext(join(tmp, 'chromium-profile'), {
    executablePath: process.env.SKYLANE_CHROMIUM || '/usr/bin/chromium', headless: true,
    viewport: { width: 1400, height: 900 },
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
      '--use-gl=angle', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
}

/** Console errors, uncaught page errors and every request the page makes. */
function watchPage(page) {
  const seen = { errors: [], requests: [] };
  page.on('console', (m) => { if (m.type() === 'error') seen.errors.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => seen.errors.push(`page: ${e.message}`));
  page.on('request', (r) => seen.requests.push(r.url()));
  return seen;
}

async function expectedCounts(args, service, zonesetId, approvalId, report) {
  const ed269 = JSON.parse(readFileSync(join(args.source, 'examples/approve/zones_ed269.json'), 'utf8'));
  const zones = await call(service, service.tokens.operator, 'GET', `/v1/zonesets/${zonesetId}/geojson`);
  const route = await call(service, service.tokens.operator, 'GET', `/v1/approvals/${approvalId}/route.geojson`);
  const kind = (k) => route.features.filter((f) => f.properties.kind === k).length;
  const departure = Date.parse(report.departure);
  return {
    zones: zones.features.length, zonesActive: ed269ActiveAt(ed269, departure).length, activeAtDeparture: ed269ActiveAt(ed269, departure), routes: 1, routePoints: kind('route_point'),
    level1Boxes: kind('corridor'), level2Boxes: kind('airspace'), flights: 1, segments: report.route.length - 1,
    sourceZones: ed269.UASZoneList.length, activeAt10: ed269ActiveAt(ed269, Date.parse('2020-01-01T10:00:00Z')),
  };
}

async function checkLoaded(page, expected) {
  const counts = await page.evaluate(() => window.skylaneMap.counts());
  for (const k of ['zones', 'zonesActive', 'routes', 'routePoints', 'level1Boxes', 'level2Boxes', 'flights']) {
    check(`layer count ${k}`, counts[k] === expected[k], `page ${counts[k]}, expected ${expected[k]}`);
  }
  const active = await page.evaluate(() => window.skylaneMap.activeZones());
  check('the zones shown at the departure are those the ED-269 file makes active then',
    JSON.stringify(active) === JSON.stringify(expected.activeAtDeparture), active.join(' '));
  check('one zone drawn per zone of the ED-269 file (no multi-volume zones there)', expected.zones === expected.sourceZones,
    `${expected.zones} features, ${expected.sourceZones} zones in the file`);
  check('one box per route segment at each level', expected.level1Boxes === expected.segments && expected.level2Boxes === expected.segments,
    `${expected.level1Boxes} / ${expected.level2Boxes} boxes, ${expected.segments} segments`);
  const rendered = {};
  for (const layer of ['zones-outline', 'route-line', 'level1-boxes', 'level2-boxes', 'flight-points']) {
    rendered[layer] = await page.evaluate((l) => window.skylaneMap.renderedCount(l), layer);
  }
  check('every active zone drawn in the fitted view', rendered['zones-outline'] === expected.zonesActive, JSON.stringify(rendered));
  check('the route, its level-1 and level-2 boxes and the flight drawn', rendered['route-line'] === 1 &&
    rendered['level2-boxes'] === expected.level2Boxes && rendered['level1-boxes'] >= 1 && rendered['flight-points'] === 1);
}

/** Posts the violating fix and measures how long the page takes to show the flight red. */
async function checkViolationTurnsRed(page, service, flight, report) {
  const token = service.tokens.operator;
  const t0 = Date.now();
  const answer = await call(service, token, 'POST', `/v1/flights/${flight}/fixes`,
    fixOnFirstLeg(report, flight, 4, kViolationOffsetM), 'application/x-ndjson');
  let red = true;
  try {
    await page.waitForFunction((id) => window.skylaneMap.flightColour(id) === 'red', flight, { timeout: kRedWithinMs, polling: 10 });
  } catch (_) {
    red = false;
  }
  const elapsed = Date.now() - t0;
  check(`a violating fix turns its flight red within ${kRedWithinMs} ms`, red && elapsed <= kRedWithinMs,
    `${elapsed} ms; service answered ${JSON.stringify(answer).slice(0, 200)}`);
  await page.waitForFunction((id) => window.skylaneMap.renderedCount('violations') >= 1, flight, { timeout: 5000 }).catch(() => {});
  const shown = await page.evaluate(() => window.skylaneMap.map.queryRenderedFeatures({ layers: ['flight-points'] })
    .map((f) => f.properties.verdict_colour));
  check('the drawn flight dot is red', shown.length === 1 && shown[0] === 'red', JSON.stringify(shown));
}

/**
 * Two more fixes beside the route: level 1 violated by the position in 3 of the last 5 fixes,
 * which the tracker replans (planner/tracking/tracker.hpp, step 6); the page draws the new route.
 */
async function checkReplanRedrawn(page, service, flight, report, out) {
  let replans = [];
  for (const t of [5, 6]) {
    const answer = await call(service, service.tokens.operator, 'POST', `/v1/flights/${flight}/fixes`,
      fixOnFirstLeg(report, flight, t, kViolationOffsetM), 'application/x-ndjson');
    replans = replans.concat((answer.events || []).filter((e) => e.event === 'replan'));
  }
  check('the service replans after the persistent level-1 violation', replans.length === 1 && replans[0].decision === 'approved',
    JSON.stringify(replans.map((e) => ({ decision: e.decision, route_version: e.route_version, error: e.error }))));
  const drawn = await page.waitForFunction(() => window.skylaneMap.counts().routes === 2, null, { timeout: 10000 })
    .then(() => true, () => false);
  const logged = await page.textContent('#event-log');
  check('the page draws the replanned route beside the approved one and logs the replan', drawn && logged.includes('replan'),
    JSON.stringify(await page.evaluate(() => window.skylaneMap.counts())));
  await page.waitForTimeout(500);
  await page.screenshot({ path: join(out, 'map_replan.png') });
}

async function checkPopupAndTime(page, flight, expected, out) {
  const at = await page.evaluate((id) => {
    const f = window.skylaneMap.map.queryRenderedFeatures({ layers: ['flight-points'] })[0];
    const p = window.skylaneMap.map.project(f.geometry.coordinates);
    return [p.x, p.y];
  }, flight);
  await page.mouse.click(at[0], at[1]);
  const popup = await page.waitForSelector('.maplibregl-popup', { timeout: 5000 }).then((e) => e.textContent()).catch(() => '');
  check('a click on the flight shows its details', popup.includes(`flight ${flight}`) && popup.includes('hpl_m'), popup.slice(0, 120));
  await page.screenshot({ path: join(out, 'map_popup.png') });
  await page.evaluate(() => window.skylaneMap.setTime('2020-01-01T10:00:00Z'));
  const active = await page.evaluate(() => window.skylaneMap.activeZones());
  check('the time slider at 10:00Z shows the zones active then', JSON.stringify(active) === JSON.stringify(expected.activeAt10),
    `${active.join(' ')} vs ${expected.activeAt10.join(' ')}`);
  await page.screenshot({ path: join(out, 'map_at_1000Z.png') });
}

/** A page opened after the replan: the token from the tab's session, the flight's current route from the service. */
async function checkReopened(page, out) {
  await page.reload();
  const ready = await page.waitForFunction(() => window.skylaneMap && window.skylaneMap.ready, null, { timeout: 60000 })
    .then(() => true, () => false);
  const counts = ready ? await page.evaluate(() => window.skylaneMap.counts()) : {};
  check('reopened with the session\'s token, the page shows the approved and the replanned route', ready && counts.routes === 2,
    JSON.stringify(counts));
  await page.waitForTimeout(500);
  await page.screenshot({ path: join(out, 'map_reopened.png') });
}

function checkOffline(seen, base) {
  const away = seen.requests.filter((u) => !u.startsWith(`${base}/`) && !u.startsWith('data:') && !u.startsWith('blob:'));
  check('every request the page makes goes to the loopback service', seen.requests.length > 0 && away.length === 0,
    `${seen.requests.length} requests${away.length ? `, away: ${away.slice(0, 5).join(' ')}` : ''}`);
  check('no console error and no uncaught page error', seen.errors.length === 0, seen.errors.slice(0, 5).join(' | '));
}

/** The service's side: zones, an approval and a flight (its first fix is posted with the page open). */
async function prepareService(args, service) {
  const zones = readFileSync(join(args.source, 'examples/approve/zones_ed269.json'));
  const set = await call(service, service.tokens.authority, 'POST', '/v1/zonesets?name=zurich-example', zones);
  const approvalId = await approve(service, missionFor(args, set.id));
  const report = await call(service, service.tokens.operator, 'GET', `/v1/approvals/${approvalId}/report.json`);
  const flight = (await call(service, service.tokens.operator, 'POST', '/v1/flights',
    JSON.stringify({ approval: approvalId, id: 'zrh-web' }))).id;
  return { zonesetId: set.id, approvalId, report, flight };
}

async function run(args, tmp) {
  mkdirSync(args.out, { recursive: true });
  const service = await startService(args, tmp);
  let browser = null;
  try {
    const s = await prepareService(args, service);
    const expected = await expectedCounts(args, service, s.zonesetId, s.approvalId, s.report);
    browser = await openBrowser(args, tmp);
    const page = browser.pages()[0] || (await browser.newPage());
    const seen = watchPage(page);
    await page.goto(`${service.base}/#token=${service.tokens.operator}&ground=${kGroundAmslM}`);
    await page.waitForFunction(() => window.skylaneMap && window.skylaneMap.ready, null, { timeout: 60000 });
    await page.waitForFunction(() => document.getElementById('stream').dataset.state === 'open', null, { timeout: 10000 });
    // The first fix, on the route: it reaches the page through the event stream.
    await call(service, service.tokens.operator, 'POST', `/v1/flights/${s.flight}/fixes`, fixOnFirstLeg(s.report, s.flight, 2, 0),
      'application/x-ndjson');
    const green = await page.waitForFunction((id) => window.skylaneMap.flightColour(id) === 'green', s.flight, { timeout: 5000 })
      .then(() => true, () => false);
    check('the flight appears green (its fix inside every level)', green,
      String(await page.evaluate((id) => window.skylaneMap.flightColour(id), s.flight)));
    await page.waitForTimeout(1000);  // the sources' data reach the map's worker and are drawn
    await checkLoaded(page, expected);
    await page.screenshot({ path: join(args.out, 'map_loaded.png') });
    await checkViolationTurnsRed(page, service, s.flight, s.report);
    await page.screenshot({ path: join(args.out, 'map_violation.png') });
    await checkReplanRedrawn(page, service, s.flight, s.report, args.out);
    await checkPopupAndTime(page, s.flight, expected, args.out);
    await checkReopened(page, args.out);
    checkOffline(seen, service.base);
  } finally {
    if (browser) await browser.close();
    await stopService(service);
    writeFileSync(join(args.out, 'service.log'), service.log());
  }
}

/** ctest's SKIP_RETURN_CODE for this test: a skylane built without the `serve` command. */
const kSkip = 77;

async function main() {
  const args = parseArgs(process.argv.slice(2));
  const help = spawnSync(args.skylane, ['--help'], { encoding: 'utf8' }).stdout || '';
  if (!/^\s+serve\s/m.test(help)) {
    console.log(`SKIP: ${args.skylane} has no serve command`);
    process.exitCode = kSkip;
    return;
  }
  const tmp = mkdtempSync(join(tmpdir(), 'skylane-web-'));
  try {
    await run(args, tmp);
  } catch (err) {
    check('the run completes', false, err.stack || String(err));
  } finally {
    rmSync(tmp, { recursive: true, force: true });
  }
  const failed = checks.filter((c) => !c.ok).length;
  console.log(`web map: ${checks.length - failed} passed, ${failed} failed (screenshots in ${args.out})`);
  process.exitCode = failed === 0 ? 0 : 1;
}

main();
