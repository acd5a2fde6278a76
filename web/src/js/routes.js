// An approved route as `route.geojson` gives it (planner/report_formats.cpp, routeGeoJson): the
// route line, its points with their times, the level-1 corridor boxes (kind "corridor") and
// the level-2 airspace boxes (kind "airspace"), one polygon per segment, and the reasons.

const kKinds = ['route', 'route_point', 'corridor', 'airspace', 'reason'];

/**
 * The drawn features of one route, tagged with the key they are replaced by (an approval id,
 * or a flight id after a replan) and what they belong to.
 */
export function routeFeatures(geojson, owner) {
  const out = [];
  for (const f of geojson.features || []) {
    const p = { ...(f.properties || {}) };
    // A route given as a bare line (a flight's current route without its boxes) is a route.
    if (p.kind === undefined && f.geometry && f.geometry.type === 'LineString') p.kind = 'route';
    if (!kKinds.includes(p.kind)) continue;
    const properties = { ...p, owner: owner.key, approval: owner.approval || '', flight: owner.flight || '',
      route_version: owner.route_version ?? 1, current: owner.flight ? 'replanned' : 'approved' };
    for (const [k, v] of Object.entries(properties)) {
      if (v !== null && typeof v === 'object') properties[k] = JSON.stringify(v);
    }
    out.push({ type: 'Feature', geometry: f.geometry, properties });
  }
  return out;
}

/** Routes held by owner key: set() replaces one owner's features, all() lists every feature. */
export class RouteStore {
  constructor() {
    this.byOwner_ = new Map();
    this.version = 0;  // counts changes, so that a redraw knows whether the routes changed
  }

  set(key, features) {
    this.byOwner_.set(key, features);
    this.version += 1;
  }

  has(key) { return this.byOwner_.has(key); }

  all() { return [...this.byOwner_.values()].flat(); }

  /** Features of each kind (route, route_point, corridor, airspace, reason). */
  count(kind) { return this.all().filter((f) => f.properties.kind === kind).length; }
}
