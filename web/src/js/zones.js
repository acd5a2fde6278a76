// Zones of a zone set as the map draws them: outlines (circles made polygons), the restriction
// that picks the colour, the floor and ceiling as heights above the local ground for the
// extrusion, and the time applicability that the time slider filters on.

import { circlePolygon } from './geometry.js';

const kDayMs = 86400000;
/** Drawn height of an unlimited ceiling above its floor [m]: tall enough to read as "no top". */
export const kUnlimitedDrawnHeightM = 1500;

/** The restriction as the legend names it; keep-in zones (an operator's inclusion fence) apart. */
export function restrictionOf(p) {
  if (p.keep_in === true || p.restriction === 'KEEP_IN') return 'KEEP_IN';
  return typeof p.restriction === 'string' ? p.restriction : 'UNKNOWN';
}

/**
 * A floor or ceiling as {value_m, reference, unlimited}: from the export's {"lower": {value_m,
 * reference, unlimited}} or from flat members lower_m / lower_reference.
 */
export function limitOf(p, which) {
  const nested = p[which];
  if (nested && typeof nested === 'object') {
    return { value_m: nested.value_m, reference: nested.reference || 'AGL', unlimited: !!nested.unlimited || nested.value_m == null };
  }
  const value = p[`${which}_m`];
  const reference = p[`${which}_reference`] || p[`${which}_ref`] || p[`${which}_vertical_reference`] || 'AGL';
  return { value_m: value, reference, unlimited: value == null };
}

/**
 * Height above the local ground of a limit [m]. `ground` = {amsl_m, undulation_m}: the ground's
 * height above mean sea level and the geoid's above the ellipsoid there (h_ell = alt_amsl + N).
 */
export function heightAboveGround(limit, ground) {
  if (limit.unlimited) return null;
  const ref = String(limit.reference).toUpperCase();
  if (ref.startsWith('AGL') || ref === 'SFC') return limit.value_m;
  if (ref.startsWith('WGS84') || ref === 'W84' || ref === 'ELLIPSOID') return limit.value_m - ground.undulation_m - ground.amsl_m;
  return limit.value_m - ground.amsl_m;  // AMSL, MSL, STD (a flight level read as AMSL)
}

/** Applicability entries: the export's list, or start/end members of a time-limited zone. */
export function applicabilityOf(p) {
  if (Array.isArray(p.applicability)) return p.applicability;
  if (p.start || p.end) return [{ permanent: false, start: p.start, end: p.end }];
  return [];
}

export function isTimeLimited(p) {
  return applicabilityOf(p).some((a) => !a.permanent || (a.schedule && a.schedule.length > 0));
}

const kWeekdays = ['MON', 'TUE', 'WED', 'THU', 'FRI', 'SAT', 'SUN'];

/** True when a weekly schedule ({day: [...], start_utc_s, end_utc_s}) covers t [ms, UTC]. */
function scheduleCovers(schedule, t) {
  if (!schedule || schedule.length === 0) return true;
  const today = Math.floor(t / kDayMs);
  // A period may run past midnight, and a local period shifted to UTC may start up to a day
  // before or after its day (start_utc_s < 0 or > 86400): the days around t are all tried.
  for (let d = today - 2; d <= today + 1; ++d) {
    const weekday = kWeekdays[(((d + 3) % 7) + 7) % 7];  // 1970-01-01 was a Thursday
    for (const p of schedule) {
      const days = p.day || [];
      if (!days.includes(weekday) && !days.includes('ANY')) continue;
      const start = d * kDayMs + p.start_utc_s * 1000;
      let end = d * kDayMs + p.end_utc_s * 1000;
      if (end <= start) end += kDayMs;
      if (start <= t && t < end) return true;
    }
  }
  return false;
}

/**
 * Whether a zone applies at t [ms since 1970, UTC]: some entry whose date range [start, end)
 * holds t and whose daily schedule, if any, covers it — the rule of skylane's
 * airspace/applicability.cpp (isActive), for the page's time slider.
 */
export function isActiveAt(p, t) {
  const entries = applicabilityOf(p);
  if (entries.length === 0) return true;
  return entries.some((a) => {
    const begin = a.permanent || !a.start ? -Infinity : Date.parse(a.start);
    const end = a.permanent || !a.end ? Infinity : Date.parse(a.end);
    return t >= begin && t < end && scheduleCovers(a.schedule, t);
  });
}

/** The times [ms] at which some zone starts or ends applying (for the slider's range). */
export function applicabilityTimes(p) {
  const times = [];
  for (const a of applicabilityOf(p)) {
    if (a.permanent) continue;
    if (a.start) times.push(Date.parse(a.start));
    if (a.end) times.push(Date.parse(a.end));
  }
  return times.filter(Number.isFinite);
}

function describeLimit(l) {
  return l.unlimited ? 'unlimited' : `${l.value_m} m ${l.reference}`;
}

function describeApplicability(p) {
  const entries = applicabilityOf(p);
  if (entries.length === 0) return 'permanent';
  return entries.map((a) => {
    if (a.permanent && !(a.schedule && a.schedule.length)) return 'permanent';
    let s = a.permanent ? 'permanent' : `${a.start || '…'} to ${a.end || '…'}`;
    for (const q of a.schedule || []) {
      s += `; ${(q.day || []).join(',')} ${q.start_utc_s}–${q.end_utc_s} s UTC`;
    }
    return s;
  }).join(' | ');
}

/** The outline as a polygon geometry: circles (Point + radius_m) become 64-gons. */
function outlineOf(feature) {
  const g = feature.geometry;
  if (g && g.type === 'Point' && Number.isFinite(feature.properties.radius_m)) {
    return circlePolygon(g.coordinates[0], g.coordinates[1], feature.properties.radius_m);
  }
  return g;
}

/**
 * The drawn features of one zone set's GeoJSON: flat properties for styling and popups, `key`
 * unique across sets, `base_m` / `top_m` above the ground for the extrusion.
 */
export function zoneFeatures(geojson, zoneset, ground) {
  return (geojson.features || []).map((f, i) => {
    const p = f.properties || {};
    const lower = limitOf(p, 'lower');
    const upper = limitOf(p, 'upper');
    const base = Math.max(0, heightAboveGround(lower, ground) ?? 0);
    const topAbove = heightAboveGround(upper, ground);
    const top = topAbove == null ? base + kUnlimitedDrawnHeightM : Math.max(base + 1, topAbove);
    return {
      type: 'Feature',
      id: i,
      geometry: outlineOf(f),
      properties: {
        kind: 'zone',
        key: `${zoneset.id}#${i}`,
        zoneset: zoneset.id,
        zoneset_name: zoneset.name || '',
        zoneset_version: zoneset.version ?? '',
        identifier: p.identifier || '',
        name: p.name || '',
        restriction: restrictionOf(p),
        message: p.message || '',
        floor: describeLimit(lower),
        ceiling: describeLimit(upper),
        applicability: describeApplicability(p),
        time_limited: isTimeLimited(p),
        base_m: base,
        top_m: top,
      },
      raw: p,
    };
  });
}
