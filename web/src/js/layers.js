// The map's style: an offline basemap (Natural Earth countries bundled at build time), then the
// zones, the routes with both box levels, and the live flights. No glyphs and no sprites — the
// style holds no symbol layer, so it asks nothing of any server; labels are HTML popups.

import { kVerdictColours } from './flights.js';

export const kRestrictionColours = {
  PROHIBITED: '#d7191c',
  REQ_AUTHORISATION: '#fd8d3c',
  CONDITIONAL: '#ffd92f',
  KEEP_IN: '#7b3294',
  other: '#969696',
};

const restrictionColour = ['match', ['get', 'restriction'],
  'PROHIBITED', kRestrictionColours.PROHIBITED,
  'REQ_AUTHORISATION', kRestrictionColours.REQ_AUTHORISATION,
  'CONDITIONAL', kRestrictionColours.CONDITIONAL,
  'KEEP_IN', kRestrictionColours.KEEP_IN,
  kRestrictionColours.other];

const empty = () => ({ type: 'geojson', data: { type: 'FeatureCollection', features: [] } });

/** The sources and layers; `basemapUrl` is the bundled countries GeoJSON on this server. */
export function buildStyle(basemapUrl) {
  return {
    version: 8,
    sources: {
      basemap: { type: 'geojson', data: basemapUrl },
      zones: empty(),
      routes: empty(),
      trails: empty(),
      cylinders: empty(),
      flight_points: empty(),
      violations: empty(),
    },
    layers: [
      { id: 'sea', type: 'background', paint: { 'background-color': '#c6dbef' } },
      { id: 'land', type: 'fill', source: 'basemap', paint: { 'fill-color': '#f2efe6' } },
      { id: 'borders', type: 'line', source: 'basemap', paint: { 'line-color': '#a6a29a', 'line-width': 0.8 } },
      ...routeLayers(),
      ...zoneLayers(),
      ...flightLayers(),
    ],
  };
}

function zoneLayers() {
  // Prohibited zones first, the wider authorisation and condition zones after them and fainter:
  // they share the depth buffer, so a zone drawn later shows what lies inside it through its
  // walls, while one drawn earlier would hide what is nested in it.
  const prohibited = ['==', ['get', 'restriction'], 'PROHIBITED'];
  return [
    { id: 'zones-extrusion', type: 'fill-extrusion', source: 'zones', filter: prohibited,
      paint: { 'fill-extrusion-color': restrictionColour, 'fill-extrusion-base': ['get', 'base_m'],
        'fill-extrusion-height': ['get', 'top_m'], 'fill-extrusion-opacity': 0.6 } },
    { id: 'zones-extrusion-other', type: 'fill-extrusion', source: 'zones',
      filter: ['all', ['!', prohibited], ['!=', ['get', 'restriction'], 'KEEP_IN']],
      paint: { 'fill-extrusion-color': restrictionColour, 'fill-extrusion-base': ['get', 'base_m'],
        'fill-extrusion-height': ['get', 'top_m'], 'fill-extrusion-opacity': 0.25 } },
    { id: 'zones-outline', type: 'line', source: 'zones',
      paint: { 'line-color': restrictionColour,
        'line-width': ['case', ['==', ['get', 'restriction'], 'KEEP_IN'], 3, 1.5] } },
  ];
}

function routeLayers() {
  const kind = (k) => ['==', ['get', 'kind'], k];
  return [
    { id: 'level2-boxes', type: 'fill', source: 'routes', filter: kind('airspace'),
      paint: { 'fill-color': '#6baed6', 'fill-opacity': 0.12 } },
    { id: 'level2-outline', type: 'line', source: 'routes', filter: kind('airspace'),
      paint: { 'line-color': '#3182bd', 'line-width': 1, 'line-dasharray': [3, 2] } },
    { id: 'level1-boxes', type: 'fill', source: 'routes', filter: kind('corridor'),
      paint: { 'fill-color': '#08519c', 'fill-opacity': 0.35 } },
    { id: 'level1-outline', type: 'line', source: 'routes', filter: kind('corridor'),
      paint: { 'line-color': '#08306b', 'line-width': 1 } },
    { id: 'route-line', type: 'line', source: 'routes', filter: kind('route'),
      paint: { 'line-color': ['case', ['==', ['get', 'current'], 'replanned'], '#00a6a6', '#08306b'],
        'line-width': 3, 'line-opacity': 0.9 } },
    { id: 'route-points', type: 'circle', source: 'routes', filter: kind('route_point'),
      paint: { 'circle-radius': 3.5, 'circle-color': '#ffffff', 'circle-stroke-color': '#08306b',
        'circle-stroke-width': 1.5 } },
    { id: 'reasons', type: 'circle', source: 'routes', filter: kind('reason'),
      paint: { 'circle-radius': 6, 'circle-color': '#ffffff', 'circle-stroke-color': '#d7191c',
        'circle-stroke-width': 2 } },
  ];
}

function flightLayers() {
  return [
    { id: 'trails', type: 'line', source: 'trails', paint: { 'line-color': '#525252', 'line-width': 1.5 } },
    { id: 'cylinders', type: 'fill-extrusion', source: 'cylinders',
      paint: { 'fill-extrusion-color': ['get', 'colour'], 'fill-extrusion-base': ['get', 'base_m'],
        'fill-extrusion-height': ['get', 'top_m'], 'fill-extrusion-opacity': 0.8 } },
    { id: 'flight-points', type: 'circle', source: 'flight_points',
      paint: { 'circle-radius': 7, 'circle-color': ['get', 'colour'], 'circle-stroke-color': '#ffffff',
        'circle-stroke-width': 2 } },
    { id: 'violations', type: 'circle', source: 'violations',
      paint: { 'circle-radius': 11, 'circle-opacity': 0, 'circle-stroke-color': kVerdictColours.red,
        'circle-stroke-width': 3 } },
  ];
}

/** Layers a click asks for details, topmost first. */
export const kClickableLayers = ['flight-points', 'cylinders', 'violations', 'reasons', 'route-points',
  'route-line', 'level1-boxes', 'zones-extrusion', 'zones-extrusion-other', 'zones-outline', 'level2-boxes'];
