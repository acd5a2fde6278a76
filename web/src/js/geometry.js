// Small spherical geometry for drawing: circles as polygons, box heights.

/** Mean Earth radius [m] (IUGG R1): the drawing error over a few km is far below a pixel. */
const kEarthRadiusM = 6371008.8;
/** Vertices of a drawn circle: under 0.2 % of the radius between chord and arc. */
export const kCircleVertices = 64;

/**
 * A circle of `radius_m` around (lon, lat) [deg] as a GeoJSON Polygon, each vertex the
 * destination point on a sphere (Sinnott's great-circle "destination point" formula).
 */
export function circlePolygon(lon, lat, radius_m, vertices = kCircleVertices) {
  const phi1 = (lat * Math.PI) / 180;
  const lambda1 = (lon * Math.PI) / 180;
  const delta = radius_m / kEarthRadiusM;
  const ring = [];
  for (let k = 0; k < vertices; ++k) {
    const theta = (2 * Math.PI * k) / vertices;
    const phi2 = Math.asin(Math.sin(phi1) * Math.cos(delta) + Math.cos(phi1) * Math.sin(delta) * Math.cos(theta));
    const lambda2 = lambda1 + Math.atan2(Math.sin(theta) * Math.sin(delta) * Math.cos(phi1),
      Math.cos(delta) - Math.sin(phi1) * Math.sin(phi2));
    ring.push([(lambda2 * 180) / Math.PI, (phi2 * 180) / Math.PI]);
  }
  ring.push(ring[0]);
  return { type: 'Polygon', coordinates: [ring] };
}

/** Extends bounds [[w, s], [e, n]] (or null) by every position of a GeoJSON geometry. */
export function extendBounds(bounds, geometry) {
  let b = bounds;
  const visit = (c) => {
    if (typeof c[0] === 'number') {
      if (!b) b = [[c[0], c[1]], [c[0], c[1]]];
      b[0][0] = Math.min(b[0][0], c[0]);
      b[0][1] = Math.min(b[0][1], c[1]);
      b[1][0] = Math.max(b[1][0], c[0]);
      b[1][1] = Math.max(b[1][1], c[1]);
      return;
    }
    for (const x of c) visit(x);
  };
  if (geometry && geometry.coordinates) visit(geometry.coordinates);
  return b;
}
