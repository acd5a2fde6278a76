// Builds the map page into an output folder, offline, from the installed npm packages:
//   node build.mjs [--out DIR] [--modules NODE_MODULES_DIR]
// DIR gets index.html, style.css, js/, vendor/ (MapLibre GL JS's ES module, its worker and CSS)
// and basemap/countries.geojson (Natural Earth 1:50m countries from world-atlas, converted from
// TopoJSON with topojson-client). Nothing is fetched: every file comes from this folder or the
// packages `npm ci` installed.

import { cpSync, mkdirSync, readFileSync, rmSync, writeFileSync, existsSync } from 'node:fs';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { createRequire } from 'node:module';

const here = dirname(fileURLToPath(import.meta.url));

function parseArgs(argv) {
  const args = { out: join(here, 'dist'), modules: join(here, 'node_modules') };
  for (let i = 0; i < argv.length; ++i) {
    const key = argv[i];
    if ((key === '--out' || key === '--modules') && i + 1 < argv.length) args[key.slice(2)] = resolve(argv[++i]);
    else throw new Error(`build.mjs: argument ${key}: expected --out DIR or --modules DIR`);
  }
  return args;
}

/** Natural Earth countries as a GeoJSON FeatureCollection (name and ISO numeric code kept). */
function basemapGeojson(modules) {
  const require = createRequire(join(modules, 'noop.js'));
  const topojson = require('topojson-client');
  const topology = JSON.parse(readFileSync(join(modules, 'world-atlas', 'countries-50m.json'), 'utf8'));
  const countries = topojson.feature(topology, topology.objects.countries);
  // Six decimals (~0.1 m) is far beyond the 1:50m source's accuracy; it keeps the file small.
  return JSON.stringify(countries, (k, v) => (typeof v === 'number' ? Math.round(v * 1e6) / 1e6 : v));
}

function build({ out, modules }) {
  const maplibre = join(modules, 'maplibre-gl', 'dist');
  if (!existsSync(maplibre)) throw new Error(`build.mjs: ${maplibre} is missing: run npm ci in web/ (or pass --modules)`);
  for (const entry of ['index.html', 'style.css', 'js', 'vendor', 'basemap']) rmSync(join(out, entry), { recursive: true, force: true });
  mkdirSync(join(out, 'vendor'), { recursive: true });
  mkdirSync(join(out, 'basemap'), { recursive: true });
  cpSync(join(here, 'src'), out, { recursive: true });
  for (const f of ['maplibre-gl.mjs', 'maplibre-gl-worker.mjs', 'maplibre-gl.css']) {
    cpSync(join(maplibre, f), join(out, 'vendor', f));
  }
  cpSync(join(modules, 'maplibre-gl', 'LICENSE.txt'), join(out, 'vendor', 'maplibre-gl.LICENSE.txt'));
  writeFileSync(join(out, 'basemap', 'countries.geojson'), basemapGeojson(modules));
  const version = JSON.parse(readFileSync(join(modules, 'maplibre-gl', 'package.json'), 'utf8')).version;
  console.log(`skylane web map built in ${out} (maplibre-gl ${version}, Natural Earth 1:50m countries)`);
}

build(parseArgs(process.argv.slice(2)));
