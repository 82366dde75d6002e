// SVG grouped bar charts (bench/suite/plot.h).
#include "plot.h"

#include <crep/core/error.h>
#include <crep/support/output_file.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace crep::bench {

namespace {

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else
      out += c;
  }
  return out;
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

} // namespace

void writeBarChartSvg(const std::string& path, const std::string& title,
                      const std::vector<BarPanel>& panels) {
  const double panelW = 460, panelH = 300, left = 50, top = 60, plotH = 200, gap = 30;
  const double width = panels.size() * (panelW + gap) + gap;
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << num(width) << "\" height=\""
      << num(panelH + top + 20) << "\" font-family=\"sans-serif\" font-size=\"11\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text x=\"" << num(gap) << "\" y=\"24\" font-size=\"14\">" << escape(title) << "</text>\n";
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const BarPanel& panel = panels[p];
    const double x0 = gap + p * (panelW + gap), y0 = top + plotH; // axis origin
    double maxValue = 1.0;
    for (const BarSeries& s : panel.series)
      for (double v : s.values)
        maxValue = std::max(maxValue, v);
    maxValue = std::ceil(maxValue);
    const auto Y = [&](double v) { return y0 - v / maxValue * plotH; };
    svg << "<text x=\"" << num(x0) << "\" y=\"" << num(top - 14) << "\" font-size=\"12\">"
        << escape(panel.title) << "</text>\n";
    for (int t = 0; t <= static_cast<int>(maxValue); ++t) {
      svg << "<line x1=\"" << num(x0 + left) << "\" x2=\"" << num(x0 + panelW) << "\" y1=\"" << num(Y(t))
          << "\" y2=\"" << num(Y(t)) << "\" stroke=\"#ddd\"/>\n"
          << "<text x=\"" << num(x0 + left - 6) << "\" y=\"" << num(Y(t) + 4) << "\" text-anchor=\"end\">"
          << t << "</text>\n";
    }
    svg << "<line x1=\"" << num(x0 + left) << "\" x2=\"" << num(x0 + panelW) << "\" y1=\"" << num(Y(1))
        << "\" y2=\"" << num(Y(1)) << "\" stroke=\"#555\" stroke-dasharray=\"4 3\"/>\n";
    const std::size_t n = panel.categories.size(), k = panel.series.size();
    const double slot = (panelW - left) / std::max<std::size_t>(n, 1),
                 bar = slot * 0.8 / std::max<std::size_t>(k, 1);
    for (std::size_t c = 0; c < n; ++c) {
      const double cx = x0 + left + c * slot;
      for (std::size_t s = 0; s < k; ++s) {
        const double v = c < panel.series[s].values.size() ? panel.series[s].values[c] : -1.0;
        if (!(v >= 0.0)) continue;
        svg << "<rect x=\"" << num(cx + slot * 0.1 + s * bar) << "\" y=\"" << num(Y(v)) << "\" width=\""
            << num(bar * 0.95) << "\" height=\"" << num(y0 - Y(v)) << "\" fill=\"" << panel.series[s].color
            << "\"><title>" << escape(panel.series[s].name + " " + panel.categories[c]) << ": " << v
            << "</title></rect>\n";
      }
      svg << "<text x=\"" << num(cx + slot / 2) << "\" y=\"" << num(y0 + 14) << "\" text-anchor=\"middle\">"
          << escape(panel.categories[c]) << "</text>\n";
    }
    for (std::size_t s = 0; s < k; ++s)
      svg << "<rect x=\"" << num(x0 + left + s * 150) << "\" y=\"" << num(y0 + 30)
          << "\" width=\"10\" height=\"10\" fill=\"" << panel.series[s].color << "\"/><text x=\""
          << num(x0 + left + s * 150 + 14) << "\" y=\"" << num(y0 + 39) << "\">"
          << escape(panel.series[s].name) << "</text>\n";
  }
  svg << "</svg>\n";
  writeTextFile(path, svg.str()); // the output rule of crep/support/output_file.h
}

} // namespace crep::bench
