// voxfield CLI — grouped bar charts for the benchmarks' --plot: one group per case (a source count,
// a resolution...), one bar per series (an algorithm) in each, a logarithmic value axis when the
// values span more than two decades. The chart is laid out once as rectangles, lines and labels,
// then written as SVG (text stays sharp; browsers and GitHub's Markdown show it) or as PNG, drawn
// by cairo (Debian's libcairo2: antialiased shapes and text, and its own PNG writer).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace voxfield::cli {

struct BarChart {
  std::string title, value_label, group_label;
  std::vector<std::string> groups, series;
  // values[s][g]: series s in group g; a value <= 0 or missing draws no bar.
  std::vector<std::vector<double>> values;
};

std::string render_svg(const BarChart& chart);
// The PNG file's bytes. Throws IoError when cairo cannot draw or encode it.
std::vector<std::uint8_t> render_png(const BarChart& chart);

}  // namespace voxfield::cli
