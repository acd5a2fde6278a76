#pragma once
/// \file
/// \brief A small SVG time-series plotter (no dependency): stacked panels sharing the time axis.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace skylane::cli {

/// \brief One line in a panel.
struct Series {
  std::string label;
  std::string colour;  ///< CSS colour
  std::vector<double> y;  ///< NaN / inf = gap
  bool dashed = false;
  bool step = false;  ///< draw as a staircase (counts)
};

/// \brief One panel: its y-axis label and lines.
struct Panel {
  std::string y_label;
  std::vector<Series> series;
  double height_px = 260;
  /// The y axis ends here when the data reach higher (NaN: at the data's top); values above are
  /// drawn on the panel's top edge. Keeps small limits readable beside large values.
  double y_cap = std::numeric_limits<double>::quiet_NaN();
};

/// \brief Renders panels against x (seconds from the start) as an SVG document; each line is a
/// `path` carrying its label as a `title` (a tooltip).
[[nodiscard]] std::string renderTimeSeriesSvg(const std::string& title, const std::string& x_label,
                                              const std::vector<double>& x_s, const std::vector<Panel>& panels);

/// \brief One grid cell of a world map: centre and value (percent available).
struct MapCell {
  double lat_deg = 0, lon_deg = 0, value = 0;
};

/// \brief Equirectangular world map of grid cells coloured by availability in MAAST's bins
/// (100, ≥ 99.9, ≥ 99.5, ≥ 99, ≥ 95, ≥ 90, ≥ 50, < 50 %), with graticule and colour scale.
[[nodiscard]] std::string renderAvailabilityMapSvg(const std::string& title, const std::vector<MapCell>& cells,
                                                   double cell_deg, const std::string& footer);

/// \brief A polar sky plot (zenith at the centre, horizon on the circle, north up and east to
/// the right, as GNSS sky plots are drawn): each azimuth bin shaded from the horizon up to its blocked
/// elevation [deg] (bins at or below 0° are not shaded); elevation rings every 30°.
/// `bin_deg` is the bins' width, bin k covering [k·bin_deg, (k+1)·bin_deg).
[[nodiscard]] std::string renderSkyPlotSvg(const std::string& title, const std::vector<double>& blocked_deg, double bin_deg,
                                           const std::string& footer);

/// \brief One Stanford diagram: a 2-D histogram of position error (x) against protection level (y).
struct StanfordPanel {
  std::string title;
  std::string error_label;  ///< e.g. "HPE [m]"
  std::string pl_label;     ///< e.g. "HPL [m]"
  double alert_limit_m = 0;
  double max_m = 0;  ///< both axes 0…max_m
  int bins = 0;
  std::vector<std::uint64_t> counts;  ///< bins × bins, row = PL bin, column = error bin
  std::vector<std::string> footer;    ///< region counts, one line each
};

/// \brief Stanford diagrams side by side (two per row): cells coloured by log10(count), the
/// diagonal error = PL, the alert limit on both axes and the regions named (normal, MI, HMI,
/// unavailable), as drawn by Stanford's WAAS lab.
[[nodiscard]] std::string renderStanfordSvg(const std::string& title, const std::vector<StanfordPanel>& panels);

/// \brief A filled outline on a plan map (metres east, north).
struct MapShape {
  std::vector<std::pair<double, double>> xy;
  std::string fill;        ///< CSS colour, "none" for none
  std::string stroke;
  double fill_opacity = 0.3;
  bool dashed = false;
  double stroke_width_px = 1.0;
  std::string legend;      ///< shown once per distinct legend text
};

/// \brief A line on a plan map.
struct MapLine {
  std::vector<std::pair<double, double>> xy;
  std::string stroke;
  double width_px = 2.0;
  std::string legend;
};

/// \brief A labelled point on a plan map.
struct MapMarker {
  double x = 0, y = 0;
  std::string label;
  std::string colour;
};

/// \brief A plan view in metres (equal scale on both axes, north up) of shapes, then lines,
/// then markers, fitted to the lines and markers (plus `margin_m`), with a scale bar, a north
/// arrow and a legend; shapes are clipped to the view.
[[nodiscard]] std::string renderPlanMapSvg(const std::string& title, const std::vector<MapShape>& shapes,
                                           const std::vector<MapLine>& lines, const std::vector<MapMarker>& markers,
                                           double margin_m, const std::vector<std::string>& footer);

}  // namespace skylane::cli
