// The accuracy benchmark's plot: log-log scatter with polylines, drawn with OpenImageIO.
#pragma once

#include <string>
#include <vector>

namespace nmbake::bench {

struct PlotPoint {
  double x = 0, y = 0;  // data units, both > 0 (log axes)
  std::string label;    // drawn beside the point
};

struct PlotSeries {
  std::string name;                           // legend entry
  std::vector<std::vector<PlotPoint>> lines;  // each one polyline, points in drawing order
  bool dashed = false;
};

struct PlotHLine {
  double y = 0;
  std::string label;
};

// Writes a PNG (width x height) to `path`; `font` is a TTF file (text is skipped when it cannot be
// used). Throws OutputError when the file cannot be written.
void write_log_log_plot(const std::string& path, const std::string& title, const std::string& x_label, const std::string& y_label,
                        const std::vector<PlotSeries>& series, const std::vector<PlotHLine>& hlines, const std::string& footer,
                        const std::string& font, int width = 1400, int height = 900);

}  // namespace nmbake::bench
