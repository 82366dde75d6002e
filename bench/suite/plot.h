// A grouped bar chart as SVG (no dependency): the bench's Table 1 / Table 2 shapes beside the paper's.
#pragma once

#include <string>
#include <vector>

namespace crep::bench {

struct BarSeries {
  std::string name;           ///< legend
  std::string color;          ///< SVG colour
  std::vector<double> values; ///< one per category; < 0 = no value (not drawn)
};

struct BarPanel {
  std::string title;
  std::vector<std::string> categories;
  std::vector<BarSeries> series;
};

/// Writes panels side by side as one SVG file: each a grouped bar chart with a y axis from 0 to the largest
/// value (rounded up), a dashed line at 1 (the reference row), category labels and a legend. Throws
/// crep::IoError naming the path if it cannot be written.
void writeBarChartSvg(const std::string& path, const std::string& title, const std::vector<BarPanel>& panels);

} // namespace crep::bench
