// The operator's live map: zones by restriction and time, approved routes with both box levels,
// live flights with their protection cylinders, from `skylane serve`'s API and event stream.

import * as maplibregl from '../vendor/maplibre-gl.mjs';
import { Api, takeToken } from './api.js';
import { openEventStream } from './sse.js';
import { zoneFeatures, isActiveAt, applicabilityTimes } from './zones.js';
import { routeFeatures, RouteStore } from './routes.js';
import { FlightStore } from './flights.js';
import { buildStyle, kClickableLayers } from './layers.js';
import { extendBounds } from './geometry.js';
import { askToken, setStatus, setStream, fillLegend, initTimeSlider, logEvent, detailsHtml } from './panel.js';

/** Margin of the time slider beyond the first and last zone or route time [ms]. */
const kSliderMarginMs = 6 * 3600 * 1000;
/** Coalescing of redraws while fixes stream in [ms]: at most ~10 source updates per second. */
const kRedrawMs = 100;
/** Flights labelled with an HTML marker (above this, the dots and popups only). */
const kMaxLabels = 200;

const state = {
  api: null, map: null, zones: [], zonesets: [], activeKeys: new Set(), time: Date.now(),
  routes: new RouteStore(), flights: new FlightStore(), labels: new Map(), approvals: new Map(),
  ground: { amsl_m: 0, undulation_m: 0, given: false }, stream: null, events: 0, redraw: null, ready: false,
  discovered: new Set(), slider: null, zonesDrawn: null, routesDrawn: -1,
};

function hashParam(name) {
  return new URLSearchParams(window.location.hash.replace(/^#/, '')).get(name);
}

/** The ground under the drawing: `#ground=<m AMSL>` or a route's `ground_amsl_m`, else sea level. */
function initGround() {
  const given = Number(hashParam('ground'));
  if (hashParam('ground') !== null && Number.isFinite(given)) state.ground = { amsl_m: given, undulation_m: 0, given: true };
}

/** The geoid undulation (h_ell − alt_amsl) and the ground, read from a loaded route. */
function groundFromRoutes(routes) {
  for (const g of routes) {
    for (const f of g.features || []) {
      const p = f.properties || {};
      if (p.kind === 'route' && Number.isFinite(p.ground_amsl_m) && !state.ground.given) state.ground.amsl_m = p.ground_amsl_m;
      if (p.kind === 'route_point' && Number.isFinite(p.h_ell_m) && Number.isFinite(p.alt_amsl_m)) {
        state.ground.undulation_m = p.h_ell_m - p.alt_amsl_m;
      }
    }
  }
}

async function loadApprovals() {
  const list = (await state.api.approvals()).approvals || [];
  const approved = list.filter((a) => a.status === 'approved' && !state.routes.has(a.id));
  for (const a of list) state.approvals.set(a.id, a);
  const routes = await Promise.all(approved.map((a) => state.api.approvalRoute(a.id)));
  groundFromRoutes(routes);
  approved.forEach((a, i) => state.routes.set(a.id, routeFeatures(routes[i], { key: a.id, approval: a.id })));
}

async function loadZones() {
  state.zonesets = (await state.api.zonesets()).zonesets || [];
  const sets = await Promise.all(state.zonesets.map((z) => state.api.zonesetGeojson(z.id)));
  state.zones = sets.flatMap((g, i) => zoneFeatures(g, state.zonesets[i], state.ground));
}

async function loadFlightRoute(id, version) {
  const g = await state.api.flightRoute(id);
  const approval = state.flights.get(id)?.approval || '';
  state.routes.set(`flight:${id}`, routeFeatures(g, { key: `flight:${id}`, flight: id, approval, route_version: version }));
  redrawNow();
}

async function loadFlights() {
  const list = (await state.api.flights()).flights || [];
  for (const f of list) {
    state.flights.upsert(f);
    // The state's version counts a replan that came after the last fix event.
    const version = Math.max(f.last_fix?.route_version ?? 0, f.state?.route_version ?? 0);
    if (version > 0 && !state.routes.has(`flight:${f.id}`)) await loadFlightRoute(f.id, version);
  }
}

/** Everything the map shows, read once at start (the stream keeps flights current after). */
async function loadAll() {
  await loadApprovals();
  await loadZones();
  await loadFlights();
}

function setData(source, features) {
  state.map.getSource(source).setData({ type: 'FeatureCollection', features });
}

function applyTime(t) {
  state.time = t;
  state.activeKeys = new Set(state.zones.filter((z) => isActiveAt(z.raw, t)).map((z) => z.properties.key));
  const active = ['in', ['get', 'key'], ['literal', [...state.activeKeys]]];
  const prohibited = ['==', ['get', 'restriction'], 'PROHIBITED'];
  state.map.setFilter('zones-extrusion', ['all', prohibited, active]);
  state.map.setFilter('zones-extrusion-other', ['all', ['!', prohibited], ['!=', ['get', 'restriction'], 'KEEP_IN'], active]);
  state.map.setFilter('zones-outline', active);
}

function updateLabels() {
  for (const id of state.flights.ids().slice(0, kMaxLabels)) {
    const f = state.flights.get(id);
    if (!f.fix) continue;
    let marker = state.labels.get(id);
    if (!marker) {
      const el = document.createElement('div');
      el.className = 'flight-label';
      el.textContent = id;
      marker = new maplibregl.Marker({ element: el, anchor: 'left', offset: [10, 0] });
      marker.setLngLat([f.fix.lon, f.fix.lat]).addTo(state.map);
      state.labels.set(id, marker);
    }
    marker.setLngLat([f.fix.lon, f.fix.lat]);
    marker.getElement().dataset.colour = f.colour;
  }
}

function redrawNow() {
  clearTimeout(state.redraw);
  state.redraw = null;
  const groundH_ell = state.ground.amsl_m + state.ground.undulation_m;
  // Zones and routes change rarely (a load, a replan); fixes only move the flights' layers.
  if (state.zonesDrawn !== state.zones) {
    setData('zones', state.zones.map(({ type, id, geometry, properties }) => ({ type, id, geometry, properties })));
    state.zonesDrawn = state.zones;
  }
  if (state.routesDrawn !== state.routes.version) {
    setData('routes', state.routes.all());
    state.routesDrawn = state.routes.version;
  }
  setData('cylinders', state.flights.cylinders(groundH_ell));
  setData('flight_points', state.flights.points());
  setData('trails', state.flights.trails());
  setData('violations', state.flights.violations());
  updateLabels();
  setStatus(`${state.zones.length} zones in ${state.zonesets.length} sets, ${state.routes.count('route')} routes, ` +
    `${state.flights.count()} flights, ${state.flights.violationCount()} violations`);
}

function redrawSoon() {
  if (state.redraw === null) state.redraw = setTimeout(redrawNow, kRedrawMs);
}

/** One event of the stream: flights move and change colour, violations mark, replans redraw. */
function onEvent(message) {
  let e;
  try {
    e = JSON.parse(message.data);
  } catch (err) {
    console.warn(`event ${message.id}: data is not JSON: ${err.message}`);
    return;
  }
  state.events += 1;
  const type = e.event || message.type;
  if (type !== 'fix') logEvent({ ...e, event: type });
  if (type === 'fix') state.flights.fix(e);
  else if (type === 'violation') state.flights.violation(e);
  else if (type === 'replan' && e.decision === 'approved') {
    loadFlightRoute(e.flight, e.route_version).catch((err) => setStatus(String(err.message), true));
  }
  if (type === 'fix' && !state.flights.get(e.flight).approval && !state.discovered.has(e.flight)) {
    state.discovered.add(e.flight);
    discoverSoon();
  }
  redrawSoon();
}

let discovering = null;
/** A flight not seen at start: its approval, its route and its summary are fetched once. */
function discoverSoon() {
  if (discovering) return;
  discovering = Promise.all([loadApprovals(), loadFlights()])
    .then(redrawNow).catch((err) => setStatus(String(err.message), true))
    .finally(() => { discovering = null; });
}

function openStream() {
  state.stream = openEventStream(state.api.eventsUrl(), state.api.headers(), onEvent, (s, detail) => {
    setStream(s, detail);
    if (s === 'failed') setStatus(`event stream refused: ${detail}`, true);
  });
}

function fitToContent() {
  let b = null;
  for (const z of state.zones) b = extendBounds(b, z.geometry);
  for (const f of state.routes.all()) b = extendBounds(b, f.geometry);
  for (const f of state.flights.points()) b = extendBounds(b, f.geometry);
  if (b) state.map.fitBounds(b, { padding: 60, pitch: 50, bearing: -15, duration: 0, maxZoom: 16 });
}

function initSlider() {
  const times = state.zones.flatMap((z) => applicabilityTimes(z.raw));
  const departures = state.routes.all().filter((f) => f.properties.kind === 'route' && f.properties.departure)
    .map((f) => Date.parse(f.properties.departure)).filter(Number.isFinite);
  const all = [...times, ...departures];
  const initialAt = Number.isFinite(Date.parse(hashParam('time'))) ? Date.parse(hashParam('time'))
    : departures.length ? departures[0] : Date.now();
  all.push(initialAt);
  state.slider = initTimeSlider(Math.min(...all) - kSliderMarginMs, Math.max(...all) + kSliderMarginMs, initialAt, applyTime);
}

/** A click shows the details of the most specific feature there (kClickableLayers' order). */
function onClick(e) {
  const layers = kClickableLayers.filter((id) => state.map.getLayer(id));
  const rank = (f) => layers.indexOf(f.layer.id);
  const hits = state.map.queryRenderedFeatures(e.point, { layers }).sort((a, b) => rank(a) - rank(b));
  if (hits.length === 0) return;
  new maplibregl.Popup({ maxWidth: '360px' }).setLngLat(e.lngLat).setHTML(detailsHtml(hits[0], hits.slice(1)))
    .addTo(state.map);
}

function createMap() {
  const basemap = new URL('basemap/countries.geojson', document.baseURI).href;
  const map = new maplibregl.Map({
    container: 'map', style: buildStyle(basemap), center: [8.54, 47.38], zoom: 3, pitch: 0,
    attributionControl: { compact: true, customAttribution: 'Natural Earth (world-atlas) · skylane' },
  });
  map.addControl(new maplibregl.NavigationControl({ visualizePitch: true }));
  map.addControl(new maplibregl.ScaleControl({ unit: 'metric' }));
  map.on('click', onClick);
  for (const id of kClickableLayers) {
    map.on('mouseenter', id, () => { map.getCanvas().style.cursor = 'pointer'; });
    map.on('mouseleave', id, () => { map.getCanvas().style.cursor = ''; });
  }
  return map;
}

/** Features of a layer drawn now, counted once each (a polygon may span several tiles). */
function renderedCount(layer) {
  const seen = new Set();
  for (const f of state.map.queryRenderedFeatures({ layers: [layer] })) {
    const p = f.properties;
    seen.add(`${p.key ?? ''}|${p.owner ?? ''}|${p.kind ?? ''}|${p.segment ?? ''}|${p.index ?? ''}|${p.flight ?? ''}|${f.id ?? ''}`);
  }
  return seen.size;
}

/** The test hook: the map, feature counts and a flight's colour. */
function exposeHook() {
  window.skylaneMap = {
    map: state.map,
    get ready() { return state.ready; },
    counts: () => ({
      zonesets: state.zonesets.length, zones: state.zones.length, zonesActive: state.activeKeys.size,
      routes: state.routes.count('route'), routePoints: state.routes.count('route_point'),
      level1Boxes: state.routes.count('corridor'), level2Boxes: state.routes.count('airspace'),
      flights: state.flights.count(), violations: state.flights.violationCount(), events: state.events,
    }),
    renderedCount,
    activeZones: () => state.zones.filter((z) => state.activeKeys.has(z.properties.key)).map((z) => z.properties.identifier).sort(),
    flightColour: (id) => state.flights.colour(id),
    setTime: (t) => state.slider.set(typeof t === 'number' ? t : Date.parse(t)),  // as a move of the slider
    lastEventId: () => state.stream?.lastEventId ?? '',
  };
}

/** Starts with a token: asks again while the service refuses it (401). */
async function loadWithToken(token) {
  for (let t = token; ; ) {
    state.api = new Api(t);
    try {
      await loadAll();
      sessionStorage.setItem('skylane.token', t);
      return;
    } catch (err) {
      if (err.status !== 401) throw err;
      sessionStorage.removeItem('skylane.token');
      t = await askToken('The service refused this token (401).');
    }
  }
}

async function main() {
  fillLegend();
  initGround();
  const token = takeToken(window.location, window.history, sessionStorage) || (await askToken());
  state.map = createMap();
  exposeHook();
  await new Promise((resolve) => state.map.on('load', resolve));
  setStatus('loading…');
  await loadWithToken(token);
  redrawNow();
  initSlider();
  fitToContent();
  openStream();
  document.getElementById('reload').onclick = () => loadAll().then(() => {
    redrawNow();
    applyTime(state.time);  // the reloaded zones' applicability
  }, (err) => setStatus(String(err.message), true));
  state.ready = true;
}

main().catch((err) => {
  setStatus(String(err.message || err), true);
  console.error(err);
});
