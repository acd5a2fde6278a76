#include "maps/gtx_grid.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

namespace skylane::maps::detail {
namespace {

/// Bytes of the GTX header.
constexpr std::size_t kHeaderBytes = 40;
/// The nodata value GDAL's GTX driver reports for every GTX band.
constexpr double kGtxNoData = -88.8888;
/// One degree in radians, as GDAL (through PROJ) reports the angular unit of WGS-84.
constexpr double kDegree_rad = M_PI / 180.0;

std::uint64_t bigEndian64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return v;
}

double bigEndianDouble(const unsigned char* p) {
  const std::uint64_t bits = bigEndian64(p);
  double d;
  std::memcpy(&d, &bits, sizeof d);
  return d;
}

std::int32_t bigEndianInt32(const unsigned char* p) {
  const std::uint32_t v = (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
  std::int32_t i;
  std::memcpy(&i, &v, sizeof i);
  return i;
}

float bigEndianFloat(const unsigned char* p) {
  const std::uint32_t v = (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
  float f;
  std::memcpy(&f, &v, sizeof f);
  return f;
}

bool hasGtxExtension(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".gtx";
}

bool fileExists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

class GtxGrid final : public RasterDataset {
 public:
  GtxGrid(int rows, int cols, const double gt[6], std::vector<unsigned char> nodes, int node_bytes)
      : rows_(rows), cols_(cols), nodes_(std::move(nodes)), node_bytes_(node_bytes) {
    std::copy(gt, gt + 6, gt_);
  }

  std::string driver() const override { return "GTX"; }
  int cols() const override { return cols_; }
  int rows() const override { return rows_; }
  bool geoTransform(double gt[6]) const override {
    std::copy(gt_, gt_ + 6, gt);
    return true;
  }
  bool invertGeoTransform(const double gt[6], double inv_gt[6]) const override {
    // Axis-aligned (GTX): x = gt0 + u·gt1, y = gt3 + v·gt5.
    if (gt[2] != 0.0 || gt[4] != 0.0 || gt[1] == 0.0 || gt[5] == 0.0) return false;
    inv_gt[0] = -gt[0] / gt[1];
    inv_gt[1] = 1.0 / gt[1];
    inv_gt[2] = 0.0;
    inv_gt[3] = -gt[3] / gt[5];
    inv_gt[4] = 0.0;
    inv_gt[5] = 1.0 / gt[5];
    return true;
  }
  RasterCrs crs() const override {
    RasterCrs c;
    c.present = true;
    c.name = "WGS 84";
    c.geographic = true;
    c.angular_unit_rad = kDegree_rad;
    c.same_as_wgs84 = true;
    return c;
  }
  std::unique_ptr<CrsTransform> wgs84Transform(bool /*to_raster*/) const override { return nullptr; }
  BandScaling band1Scaling() const override {
    BandScaling s;
    s.has_nodata = true;
    s.nodata = kGtxNoData;
    return s;
  }
  /// GDAL's row `row` (north-up) is the file's row rows − 1 − row (stored south to north).
  bool readBand1Row(int row, double* out) override {
    if (row < 0 || row >= rows_) return false;
    const std::size_t stride = static_cast<std::size_t>(cols_) * static_cast<std::size_t>(node_bytes_);
    const unsigned char* p = nodes_.data() + static_cast<std::size_t>(rows_ - 1 - row) * stride;
    for (int c = 0; c < cols_; ++c, p += node_bytes_) {
      out[c] = node_bytes_ == 4 ? static_cast<double>(bigEndianFloat(p)) : bigEndianDouble(p);
    }
    return true;
  }
  std::string lastError(const char* fallback) const override { return fallback; }

 private:
  int rows_;
  int cols_;
  double gt_[6];
  std::vector<unsigned char> nodes_;  ///< The file's nodes as stored (big-endian, south row first).
  int node_bytes_;                    ///< 4 (float32) or 8 (float64).
};

}  // namespace

std::unique_ptr<RasterDataset> openGtxGrid(const std::string& path) {
  if (!hasGtxExtension(path) || fileExists(path + ".aux.xml")) return nullptr;
  std::ifstream in(path, std::ios::binary);
  if (!in) return nullptr;
  unsigned char h[kHeaderBytes];
  if (!in.read(reinterpret_cast<char*>(h), kHeaderBytes)) return nullptr;
  // GDAL's GTX geotransform: header (lat0, lon0, dlat, dlon) of the south-west node; the
  // origin moved to the north-west corner of the north-west cell, rows north-up.
  double gt[6] = {bigEndianDouble(h + 8), bigEndianDouble(h + 24), 0.0, bigEndianDouble(h + 0), 0.0,
                  bigEndianDouble(h + 16)};
  const std::int32_t rows = bigEndianInt32(h + 32), cols = bigEndianInt32(h + 36);
  if (rows <= 0 || cols <= 0 || cols > INT_MAX / 8) return nullptr;
  gt[3] += gt[5] * (static_cast<double>(rows) - 1);
  gt[0] -= gt[1] * 0.5;
  gt[3] += gt[5] * 0.5;
  gt[5] *= -1;
  in.seekg(0, std::ios::end);
  const auto size = static_cast<unsigned long long>(in.tellg());
  const unsigned long long nodes = static_cast<unsigned long long>(rows) * static_cast<unsigned long long>(cols);
  // Float64 when the file has exactly that many bytes of data, else float32 (as GDAL decides).
  const int node_bytes = size - kHeaderBytes == 8 * nodes ? 8 : 4;
  if (size < kHeaderBytes + nodes * static_cast<unsigned long long>(node_bytes)) return nullptr;  // GDAL: read errors
  std::vector<unsigned char> data(static_cast<std::size_t>(nodes) * static_cast<std::size_t>(node_bytes));
  in.seekg(static_cast<std::streamoff>(kHeaderBytes));
  if (!in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(data.size()))) return nullptr;
  return std::make_unique<GtxGrid>(rows, cols, gt, std::move(data), node_bytes);
}

}  // namespace skylane::maps::detail
