#include "cli/svg_plot.hpp"

#include "cli/coastlines.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace skylane::cli {
namespace {

/// A "nice" tick step (1, 2 or 5 × 10^k) for about `target` ticks over `span`.
double niceStep(double span, int target) {
  if (!(span > 0)) return 1.0;
  const double raw = span / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * mag;
}

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else o += c;
  }
  return o;
}

}  // namespace

std::string renderTimeSeriesSvg(const std::string& title, const std::string& x_label, const std::vector<double>& x,
                                const std::vector<Panel>& panels) {
  const double width = 960, left = 70, right = 160, top = 40, gap = 40, bottom = 50;
  double height = top + bottom;
  for (const Panel& p : panels) height += p.height_px + gap;
  const double plot_w = width - left - right;
  const double x0 = x.empty() ? 0 : x.front(), x1 = x.empty() ? 1 : std::max(x.back(), x0 + 1e-9);
  const bool hours = (x1 - x0) > 3 * 3600;
  const double xscale = hours ? 3600.0 : 60.0;
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s << "<text x=\"" << width / 2 << "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">" << escape(title) << "</text>\n";
  double y_top = top;
  for (const Panel& p : panels) {
    const double h = p.height_px;
    double lo = 0, hi = 0;
    bool any = false;
    for (const Series& se : p.series) {
      for (double v : se.y) {
        if (!std::isfinite(v)) continue;
        hi = any ? std::max(hi, v) : v;
        lo = std::min(lo, v);
        any = true;
      }
    }
    if (std::isfinite(p.y_cap) && hi > p.y_cap) hi = p.y_cap;
    if (!any || hi <= lo) hi = lo + 1;
    const double ystep = niceStep(hi - lo, 5);
    hi = std::ceil(hi / ystep) * ystep;
    auto X = [&](double v) { return left + (v - x0) / (x1 - x0) * plot_w; };
    auto Y = [&](double v) { return y_top + h - (v - lo) / (hi - lo) * h; };
    s << "<rect x=\"" << left << "\" y=\"" << y_top << "\" width=\"" << plot_w << "\" height=\"" << h
      << "\" fill=\"none\" stroke=\"#444\"/>\n";
    for (double v = lo; v <= hi + 1e-9; v += ystep) {
      s << "<line x1=\"" << left << "\" x2=\"" << left + plot_w << "\" y1=\"" << Y(v) << "\" y2=\"" << Y(v)
        << "\" stroke=\"#ddd\"/><text x=\"" << left - 6 << "\" y=\"" << Y(v) + 4 << "\" text-anchor=\"end\">" << fmt(v)
        << "</text>\n";
    }
    const double xstep = niceStep((x1 - x0) / xscale, 8) * xscale;
    for (double v = x0; v <= x1 + 1e-9; v += xstep) {
      s << "<line x1=\"" << X(v) << "\" x2=\"" << X(v) << "\" y1=\"" << y_top << "\" y2=\"" << y_top + h
        << "\" stroke=\"#eee\"/><text x=\"" << X(v) << "\" y=\"" << y_top + h + 15 << "\" text-anchor=\"middle\">"
        << fmt((v - x0) / xscale) << "</text>\n";
    }
    s << "<text transform=\"translate(18," << y_top + h / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
      << escape(p.y_label) << "</text>\n";
    double legend_y = y_top + 14;
    for (const Series& se : p.series) {
      std::ostringstream d;
      bool pen = false;
      double prev_y = 0;
      for (std::size_t i = 0; i < x.size() && i < se.y.size(); ++i) {
        if (!std::isfinite(se.y[i])) { pen = false; continue; }
        const double yv = std::clamp(se.y[i], lo, hi);
        if (pen && se.step) d << " L" << fmt(X(x[i])) << "," << fmt(Y(prev_y));
        d << (pen ? " L" : " M") << fmt(X(x[i])) << "," << fmt(Y(yv));
        prev_y = yv;
        pen = true;
      }
      s << "<path d=\"" << d.str() << "\" fill=\"none\" stroke=\"" << se.colour << "\" stroke-width=\"1.6\""
        << (se.dashed ? " stroke-dasharray=\"6,4\"" : "") << "><title>" << escape(se.label) << "</title></path>\n";
      s << "<line x1=\"" << left + plot_w + 12 << "\" x2=\"" << left + plot_w + 36 << "\" y1=\"" << legend_y - 4
        << "\" y2=\"" << legend_y - 4 << "\" stroke=\"" << se.colour << "\" stroke-width=\"2\""
        << (se.dashed ? " stroke-dasharray=\"6,4\"" : "") << "/><text x=\"" << left + plot_w + 42 << "\" y=\""
        << legend_y << "\">" << escape(se.label) << "</text>\n";
      legend_y += 18;
    }
    y_top += h + gap;
  }
  s << "<text x=\"" << left + plot_w / 2 << "\" y=\"" << height - 12 << "\" text-anchor=\"middle\">"
    << escape(x_label) << (hours ? " [h]" : " [min]") << "</text>\n</svg>\n";
  return s.str();
}

namespace {

struct Bin {
  double min_pct;
  const char* colour;
  const char* label;
};
constexpr Bin kBins[] = {{100.0, "#1a9850", "100 %"},   {99.9, "#66bd63", "≥ 99.9 %"}, {99.5, "#a6d96a", "≥ 99.5 %"},
                         {99.0, "#d9ef8b", "≥ 99 %"},   {95.0, "#fee08b", "≥ 95 %"},   {90.0, "#fdae61", "≥ 90 %"},
                         {50.0, "#f46d43", "≥ 50 %"},   {-1.0, "#d73027", "< 50 %"}};

const char* binColour(double pct) {
  for (const Bin& b : kBins) {
    if (pct >= b.min_pct - 1e-9) return b.colour;
  }
  return kBins[7].colour;
}

}  // namespace

std::string renderAvailabilityMapSvg(const std::string& title, const std::vector<MapCell>& cells, double cell_deg,
                                     const std::string& footer) {
  const double scale = 2.5;  // px per degree
  const double left = 50, top = 40, w = 360 * scale, h = 180 * scale, legend_w = 130;
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << left + w + legend_w + 20 << "\" height=\"" << top + h + 60
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s << "<text x=\"" << left + w / 2 << "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">" << escape(title) << "</text>\n";
  for (const MapCell& c : cells) {
    const double x = left + (c.lon_deg - cell_deg / 2 + 180) * scale;
    const double y = top + (90 - c.lat_deg - cell_deg / 2) * scale;
    s << "<rect x=\"" << fmt(x) << "\" y=\"" << fmt(y) << "\" width=\"" << fmt(cell_deg * scale + 0.3) << "\" height=\""
      << fmt(cell_deg * scale + 0.3) << "\" fill=\"" << binColour(c.value) << "\"/>\n";
  }
  // Coastlines (GSHHG crude) drawn over the cells so that a reader can place them.
  s << "<g fill=\"none\" stroke=\"#1b1b1b\" stroke-width=\"0.8\" stroke-opacity=\"0.8\">\n";
  for (const Coastline& line : worldCoastlines()) {
    s << "<polyline points=\"";
    for (const auto& [lon, lat] : line) s << fmt(left + (lon + 180) * scale) << ',' << fmt(top + (90 - lat) * scale) << ' ';
    s << "\"/>\n";
  }
  s << "</g>\n";
  for (int lon = -180; lon <= 180; lon += 30) {
    const double x = left + (lon + 180) * scale;
    s << "<line x1=\"" << x << "\" x2=\"" << x << "\" y1=\"" << top << "\" y2=\"" << top + h
      << "\" stroke=\"#333\" stroke-opacity=\"0.25\"/><text x=\"" << x << "\" y=\"" << top + h + 15
      << "\" text-anchor=\"middle\">" << lon << "°</text>\n";
  }
  for (int lat = -90; lat <= 90; lat += 30) {
    const double y = top + (90 - lat) * scale;
    s << "<line x1=\"" << left << "\" x2=\"" << left + w << "\" y1=\"" << y << "\" y2=\"" << y
      << "\" stroke=\"#333\" stroke-opacity=\"0.25\"/><text x=\"" << left - 6 << "\" y=\"" << y + 4
      << "\" text-anchor=\"end\">" << lat << "°</text>\n";
  }
  s << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << w << "\" height=\"" << h
    << "\" fill=\"none\" stroke=\"#222\"/>\n";
  double ly = top + 10;
  s << "<text x=\"" << left + w + 15 << "\" y=\"" << ly << "\">availability</text>\n";
  for (const Bin& b : kBins) {
    ly += 22;
    s << "<rect x=\"" << left + w + 15 << "\" y=\"" << ly - 12 << "\" width=\"24\" height=\"16\" fill=\"" << b.colour
      << "\" stroke=\"#444\"/><text x=\"" << left + w + 46 << "\" y=\"" << ly << "\">" << escape(b.label) << "</text>\n";
  }
  s << "<text x=\"" << left << "\" y=\"" << top + h + 40 << "\">" << escape(footer) << "</text>\n</svg>\n";
  return s.str();
}

std::string renderSkyPlotSvg(const std::string& title, const std::vector<double>& blocked_deg, double bin_deg,
                             const std::string& footer) {
  const double size = 560, cx = size / 2, cy = 60 + size / 2 - 20, r_horizon = size / 2 - 50;
  // Radius of an elevation: linear in zenith angle (equidistant polar plot, as sky plots are drawn).
  const auto radius = [&](double el_deg) { return r_horizon * (90.0 - std::clamp(el_deg, 0.0, 90.0)) / 90.0; };
  const auto X = [&](double az_deg, double rr) { return cx + rr * std::sin(az_deg * M_PI / 180.0); };
  const auto Y = [&](double az_deg, double rr) { return cy - rr * std::cos(az_deg * M_PI / 180.0); };
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << size << "\" height=\"" << cy + r_horizon + 60
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s << "<text x=\"" << cx << "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">" << escape(title) << "</text>\n";
  // The blocked sky: one wedge per bin, from the horizon circle in to the blocked elevation.
  s << "<g fill=\"#8c8c8c\" stroke=\"#8c8c8c\" stroke-width=\"0.5\">\n";  // the stroke closes the seams between wedges
  for (std::size_t k = 0; k < blocked_deg.size(); ++k) {
    if (!(blocked_deg[k] > 0.0)) continue;
    const double a0 = static_cast<double>(k) * bin_deg, a1 = a0 + bin_deg, r_in = radius(blocked_deg[k]);
    s << "<path d=\"M" << fmt(X(a0, r_horizon)) << "," << fmt(Y(a0, r_horizon)) << " A" << fmt(r_horizon) << ","
      << fmt(r_horizon) << " 0 0 1 " << fmt(X(a1, r_horizon)) << "," << fmt(Y(a1, r_horizon)) << " L" << fmt(X(a1, r_in))
      << "," << fmt(Y(a1, r_in));
    if (r_in > 0.0) s << " A" << fmt(r_in) << "," << fmt(r_in) << " 0 0 0 " << fmt(X(a0, r_in)) << "," << fmt(Y(a0, r_in));
    s << " Z\"/>\n";
  }
  s << "</g>\n";
  for (int el = 0; el < 90; el += 30) {
    s << "<circle cx=\"" << cx << "\" cy=\"" << cy << "\" r=\"" << fmt(radius(el)) << "\" fill=\"none\" stroke=\""
      << (el == 0 ? "#222" : "#bbb") << "\"/>\n";
    if (el > 0) s << "<text x=\"" << cx + 3 << "\" y=\"" << fmt(cy - radius(el) - 3) << "\" fill=\"#444\">" << el << "°</text>\n";
  }
  for (int az = 0; az < 360; az += 30) {
    s << "<line x1=\"" << cx << "\" y1=\"" << cy << "\" x2=\"" << fmt(X(az, r_horizon)) << "\" y2=\"" << fmt(Y(az, r_horizon))
      << "\" stroke=\"#ddd\"/>\n";
    static const char* kNames[] = {"N", "30°", "60°", "E", "120°", "150°", "S", "210°", "240°", "W", "300°", "330°"};
    s << "<text x=\"" << fmt(X(az, r_horizon + 16)) << "\" y=\"" << fmt(Y(az, r_horizon + 16) + 4)
      << "\" text-anchor=\"middle\">" << kNames[az / 30] << "</text>\n";
  }
  s << "<text x=\"" << 20 << "\" y=\"" << fmt(cy + r_horizon + 45) << "\">" << escape(footer) << "</text>\n</svg>\n";
  return s.str();
}

namespace {

/// A sequential palette (dark blue → yellow), indexed by log10(count) / log10(max count).
const char* const kStanfordPalette[] = {"#30123b", "#4145ab", "#4675ed", "#39a2fc", "#1bcfd4",
                                        "#24eca6", "#61fc6c", "#a4fc3b", "#d1e834", "#f3c63a", "#fe9b2d"};
constexpr int kStanfordColours = 11;

/// Where one Stanford panel sits: its top-left corner, side and the metres → pixels map.
struct StanfordFrame {
  double ox, oy, side;
  double max_m;
  double scale;  ///< px per metre
  [[nodiscard]] double X(double v) const { return ox + std::min(v, max_m) * scale; }
  [[nodiscard]] double Y(double v) const { return oy + side - std::min(v, max_m) * scale; }
};

/// The 2-D histogram: one cell per non-empty bin, coloured by its log count.
void drawStanfordCounts(std::ostream& s, const StanfordPanel& p, const StanfordFrame& f) {
  std::uint64_t peak = 0;
  for (std::uint64_t c : p.counts) peak = std::max(peak, c);
  const double cell = f.side / std::max(1, p.bins);
  for (int r = 0; r < p.bins; ++r) {
    for (int c = 0; c < p.bins; ++c) {
      const std::uint64_t n = p.counts[static_cast<std::size_t>(r) * static_cast<std::size_t>(p.bins) + static_cast<std::size_t>(c)];
      if (n == 0) continue;
      const double fr = peak > 1 ? std::log10(static_cast<double>(n)) / std::log10(static_cast<double>(peak)) : 1.0;
      const int idx = std::clamp(static_cast<int>(fr * (kStanfordColours - 1) + 0.5), 0, kStanfordColours - 1);
      s << "<rect x=\"" << fmt(f.ox + c * cell) << "\" y=\"" << fmt(f.oy + f.side - (r + 1) * cell) << "\" width=\""
        << fmt(cell + 0.3) << "\" height=\"" << fmt(cell + 0.3) << "\" fill=\"" << kStanfordPalette[idx] << "\"/>\n";
    }
  }
}

/// Regions: diagonal error = PL, alert limit on both axes, and their names.
void drawStanfordRegions(std::ostream& s, const StanfordPanel& p, const StanfordFrame& f) {
  const double al = p.alert_limit_m;
  s << "<line x1=\"" << f.X(0) << "\" y1=\"" << f.Y(0) << "\" x2=\"" << f.X(p.max_m) << "\" y2=\"" << f.Y(p.max_m)
    << "\" stroke=\"black\"/>\n";
  s << "<line x1=\"" << f.X(al) << "\" y1=\"" << f.Y(0) << "\" x2=\"" << f.X(al) << "\" y2=\"" << f.Y(p.max_m)
    << "\" stroke=\"#c00000\" stroke-dasharray=\"5,3\"/>\n";
  s << "<line x1=\"" << f.X(0) << "\" y1=\"" << f.Y(al) << "\" x2=\"" << f.X(p.max_m) << "\" y2=\"" << f.Y(al)
    << "\" stroke=\"#c00000\" stroke-dasharray=\"5,3\"/>\n";
  auto label = [&](double ex, double pl, const char* text) {
    s << "<text x=\"" << fmt(f.X(ex)) << "\" y=\"" << fmt(f.Y(pl)) << "\" text-anchor=\"middle\" fill=\"#303030\">"
      << text << "</text>\n";
  };
  label(al * 0.3, al * 0.75, "Normal");
  label(al * 0.75, al * 0.3, "MI");
  label(al + (p.max_m - al) * 0.5, al * 0.5, "HMI");
  label(al * 0.5, al + (p.max_m - al) * 0.6, "Unavailable");
}

/// Axis ticks and labels, and the panel's footer lines.
void drawStanfordAxes(std::ostream& s, const StanfordPanel& p, const StanfordFrame& f) {
  const double step = niceStep(p.max_m, 5);
  for (double v = 0; v <= p.max_m + 1e-9; v += step) {
    s << "<text x=\"" << fmt(f.X(v)) << "\" y=\"" << f.oy + f.side + 15 << "\" text-anchor=\"middle\">" << fmt(v) << "</text>\n";
    s << "<text x=\"" << f.ox - 6 << "\" y=\"" << fmt(f.Y(v) + 4) << "\" text-anchor=\"end\">" << fmt(v) << "</text>\n";
  }
  s << "<text x=\"" << f.ox + f.side / 2 << "\" y=\"" << f.oy + f.side + 32 << "\" text-anchor=\"middle\">"
    << escape(p.error_label) << "</text>\n";
  s << "<text transform=\"translate(" << f.ox - 42 << "," << f.oy + f.side / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
    << escape(p.pl_label) << "</text>\n";
  double fy = f.oy + f.side + 52;
  for (const std::string& line : p.footer) {
    s << "<text x=\"" << f.ox << "\" y=\"" << fy << "\" font-size=\"11\">" << escape(line) << "</text>\n";
    fy += 15;
  }
}

void drawStanfordPanel(std::ostream& s, const StanfordPanel& p, const StanfordFrame& f) {
  s << "<text x=\"" << f.ox + f.side / 2 << "\" y=\"" << f.oy - 10 << "\" text-anchor=\"middle\" font-size=\"13\">"
    << escape(p.title) << "</text>\n";
  s << "<rect x=\"" << f.ox << "\" y=\"" << f.oy << "\" width=\"" << f.side << "\" height=\"" << f.side
    << "\" fill=\"#f4f4f4\" stroke=\"black\"/>\n";
  drawStanfordCounts(s, p, f);
  drawStanfordRegions(s, p, f);
  drawStanfordAxes(s, p, f);
}

/// The colour scale at x = lx, from the top of the panels down.
void drawStanfordColourScale(std::ostream& s, double lx, double top) {
  s << "<text x=\"" << lx << "\" y=\"" << top - 8 << "\">epochs</text>\n";
  for (int i = 0; i < kStanfordColours; ++i) {
    s << "<rect x=\"" << lx << "\" y=\"" << top + (kStanfordColours - 1 - i) * 18 << "\" width=\"16\" height=\"18\" fill=\""
      << kStanfordPalette[i] << "\"/>\n";
  }
  s << "<text x=\"" << lx + 20 << "\" y=\"" << top + 12 << "\">max</text>\n";
  s << "<text x=\"" << lx + 20 << "\" y=\"" << top + kStanfordColours * 18 - 4 << "\">1</text>\n";
  s << "<text x=\"" << lx << "\" y=\"" << top + kStanfordColours * 18 + 16 << "\" font-size=\"10\">log scale</text>\n";
}

}  // namespace

std::string renderStanfordSvg(const std::string& title, const std::vector<StanfordPanel>& panels) {
  const double side = 330, left = 70, top = 60, gap_x = 110, gap_y = 150, legend = 80;
  const int columns = panels.size() > 1 ? 2 : 1;
  const int rows = static_cast<int>((panels.size() + 1) / 2);
  const double width = left + columns * (side + gap_x) + legend;
  const double height = top + rows * (side + gap_y);
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s << "<text x=\"" << width / 2 << "\" y=\"26\" text-anchor=\"middle\" font-size=\"15\">" << escape(title) << "</text>\n";
  for (std::size_t k = 0; k < panels.size(); ++k) {
    const StanfordPanel& p = panels[k];
    const double ox = left + static_cast<double>(k % 2) * (side + gap_x);
    const double oy = top + static_cast<double>(k / 2) * (side + gap_y);
    drawStanfordPanel(s, p, StanfordFrame{ox, oy, side, p.max_m, side / p.max_m});
  }
  drawStanfordColourScale(s, width - legend + 20, top);
  s << "</svg>\n";
  return s.str();
}

namespace {

/// The plan map's view: the data's box grown by the margin, and metres → pixels.
struct MapView {
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;  ///< the box [m]
  double left = 20, top = 50;                               ///< the plot's corner [px]
  double scale = 1.0;                                       ///< px per metre
  double w = 0.0, h = 0.0;                                  ///< the plot's size [px]

  void grow(double x, double y) {
    x0 = std::min(x0, x);
    x1 = std::max(x1, x);
    y0 = std::min(y0, y);
    y1 = std::max(y1, y);
  }
  [[nodiscard]] double X(double x) const { return left + (x - x0) * scale; }
  [[nodiscard]] double Y(double y) const { return top + (y1 - y) * scale; }
};

/// The box of the lines and markers (the origin when there are none), grown by margin_m and
/// fitted into a square plot of `plot` pixels.
MapView mapView(const std::vector<MapLine>& lines, const std::vector<MapMarker>& markers, double margin_m, double plot) {
  MapView v;
  for (const MapLine& l : lines) {
    for (const auto& [x, y] : l.xy) v.grow(x, y);
  }
  for (const MapMarker& m : markers) v.grow(m.x, m.y);
  if (v.x0 > v.x1) v.grow(0, 0);
  v.x0 -= margin_m;
  v.x1 += margin_m;
  v.y0 -= margin_m;
  v.y1 += margin_m;
  v.scale = plot / std::max(v.x1 - v.x0, v.y1 - v.y0);
  v.w = (v.x1 - v.x0) * v.scale;
  v.h = (v.y1 - v.y0) * v.scale;
  return v;
}

/// Legend entries in order of first appearance: text, svg swatch.
using MapLegend = std::vector<std::pair<std::string, std::string>>;

void remember(MapLegend& legend, const std::string& text, const std::string& swatch) {
  if (text.empty()) return;
  for (const auto& l : legend) {
    if (l.first == text) return;
  }
  legend.emplace_back(text, swatch);
}

void drawMapShapes(std::ostream& s, const MapView& v, const std::vector<MapShape>& shapes, MapLegend& legend) {
  for (const MapShape& sh : shapes) {
    if (sh.xy.size() < 2) continue;
    s << "<polygon points=\"";
    for (const auto& [x, y] : sh.xy) s << fmt(v.X(x)) << "," << fmt(v.Y(y)) << " ";
    const std::string width = sh.stroke_width_px == 1.0 ? "" : " stroke-width=\"" + fmt(sh.stroke_width_px) + "\"";
    s << "\" fill=\"" << sh.fill << "\" fill-opacity=\"" << sh.fill_opacity << "\" stroke=\"" << sh.stroke << "\"" << width
      << (sh.dashed ? " stroke-dasharray=\"5,3\"" : "") << "/>\n";
    remember(legend, sh.legend, "<rect width=\"16\" height=\"12\" fill=\"" + sh.fill + "\" fill-opacity=\"" +
                                    std::to_string(sh.fill_opacity) + "\" stroke=\"" + sh.stroke + "\"" + width + "/>");
  }
}

void drawMapLines(std::ostream& s, const MapView& v, const std::vector<MapLine>& lines, MapLegend& legend) {
  for (const MapLine& l : lines) {
    s << "<polyline fill=\"none\" stroke=\"" << l.stroke << "\" stroke-width=\"" << l.width_px << "\" points=\"";
    for (const auto& [x, y] : l.xy) s << fmt(v.X(x)) << "," << fmt(v.Y(y)) << " ";
    s << "\"/>\n";
    remember(legend, l.legend, "<line x1=\"0\" y1=\"6\" x2=\"16\" y2=\"6\" stroke=\"" + l.stroke + "\" stroke-width=\"" +
                                   fmt(l.width_px) + "\"/>");
  }
}

void drawMapMarkers(std::ostream& s, const MapView& v, const std::vector<MapMarker>& markers) {
  for (const MapMarker& m : markers) {
    s << "<circle cx=\"" << fmt(v.X(m.x)) << "\" cy=\"" << fmt(v.Y(m.y)) << "\" r=\"5\" fill=\"" << m.colour << "\"/>\n";
    s << "<text x=\"" << fmt(v.X(m.x) + 8) << "\" y=\"" << fmt(v.Y(m.y) - 6) << "\">" << escape(m.label) << "</text>\n";
  }
}

/// Scale bar (a nice length near a fifth of the view) and north arrow.
void drawScaleBarAndNorth(std::ostream& s, const MapView& v) {
  const double bar_m = niceStep((v.x1 - v.x0) / 5.0 * 2.0, 2);
  const double bx = v.left + 12, by = v.top + v.h - 14;
  s << "<line x1=\"" << fmt(bx) << "\" y1=\"" << fmt(by) << "\" x2=\"" << fmt(bx + bar_m * v.scale) << "\" y2=\"" << fmt(by)
    << "\" stroke=\"black\" stroke-width=\"3\"/>\n<text x=\"" << fmt(bx) << "\" y=\"" << fmt(by - 6) << "\">" << fmt(bar_m)
    << " m</text>\n";
  const double nx = v.left + v.w - 24, ny = v.top + 16;
  s << "<path d=\"M" << fmt(nx) << "," << fmt(ny - 10) << " l7,20 l-7,-5 l-7,5 z\" fill=\"black\"/><text x=\"" << fmt(nx)
    << "\" y=\"" << fmt(ny + 24) << "\" text-anchor=\"middle\">N</text>\n";
}

/// The legend right of the map and the footer lines below it.
void drawMapLegendAndFooter(std::ostream& s, const MapView& v, const MapLegend& legend,
                            const std::vector<std::string>& footer) {
  double ly = v.top + 10;
  for (const auto& [text, swatch] : legend) {
    s << "<g transform=\"translate(" << fmt(v.left + v.w + 14) << "," << fmt(ly) << ")\">" << swatch << "<text x=\"22\" y=\"11\">"
      << escape(text) << "</text></g>\n";
    ly += 20;
  }
  double fy = v.top + v.h + 22;
  for (const std::string& line : footer) {
    s << "<text x=\"" << fmt(v.left) << "\" y=\"" << fmt(fy) << "\" font-size=\"11\">" << escape(line) << "</text>\n";
    fy += 16;
  }
}

}  // namespace

std::string renderPlanMapSvg(const std::string& title, const std::vector<MapShape>& shapes,
                             const std::vector<MapLine>& lines, const std::vector<MapMarker>& markers, double margin_m,
                             const std::vector<std::string>& footer) {
  const double plot = 720, legend_w = 240;
  const MapView v = mapView(lines, markers, margin_m, plot);
  const double width = v.left + v.w + legend_w, height = v.top + v.h + 40 + 16.0 * static_cast<double>(footer.size());
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << fmt(width) << "\" height=\"" << fmt(height)
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s << "<text x=\"" << fmt(width / 2) << "\" y=\"26\" text-anchor=\"middle\" font-size=\"15\">" << escape(title) << "</text>\n";
  s << "<defs><clipPath id=\"view\"><rect x=\"" << fmt(v.left) << "\" y=\"" << fmt(v.top) << "\" width=\"" << fmt(v.w)
    << "\" height=\"" << fmt(v.h) << "\"/></clipPath></defs>\n";
  s << "<rect x=\"" << fmt(v.left) << "\" y=\"" << fmt(v.top) << "\" width=\"" << fmt(v.w) << "\" height=\"" << fmt(v.h)
    << "\" fill=\"#fbfbf8\" stroke=\"#999\"/>\n<g clip-path=\"url(#view)\">\n";
  MapLegend legend;
  drawMapShapes(s, v, shapes, legend);
  drawMapLines(s, v, lines, legend);
  s << "</g>\n";
  drawMapMarkers(s, v, markers);
  drawScaleBarAndNorth(s, v);
  drawMapLegendAndFooter(s, v, legend, footer);
  s << "</svg>\n";
  return s.str();
}

}  // namespace skylane::cli
