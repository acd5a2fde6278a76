#pragma once
/// \file
/// \brief NOAA's .gtx vertical datum grids read without GDAL, internal to maps/.
///
/// The EGM96 grid every AMSL limit needs (Debian proj-data's egm96_15.gtx) is a GTX file: a
/// 40-byte big-endian header (latitude and longitude of the south-west node, the latitude and
/// longitude spacing in degrees as float64, then rows and columns as int32) and the nodes as
/// big-endian float32 (float64 for files written before October 2009), rows from south to
/// north. Reading it here keeps GDAL (maps/raster_module.hpp) out of every process that needs
/// only the geoid. The dataset reports exactly what GDAL's GTX driver reports — the same
/// geotransform arithmetic (node origin moved out by half a cell, rows flipped to north-up),
/// CRS WGS-84 in degrees, nodata −88.8888 — so the Geoid built from it is the same to the bit
/// (tests/maps/geoid_test.cpp compares both readers node by node).

#include "maps/raster_module.hpp"

#include <memory>
#include <string>

namespace skylane::maps::detail {

/// \brief The GTX file at `path` as a RasterDataset, or null when it is not one this reader
/// takes without GDAL (not named *.gtx, shorter than its header, sizes out of range, or
/// with a GDAL side-car `path.aux.xml` that may override nodata, scale or offset): then GDAL
/// reads it.
[[nodiscard]] std::unique_ptr<RasterDataset> openGtxGrid(const std::string& path);

}  // namespace skylane::maps::detail
