// voxfield CLI — grouped bar charts as SVG, for the benchmarks' --plot: one group per case (a
// source count, a resolution...), one bar per series (an algorithm) in each, a logarithmic value
// axis when the values span more than two decades. SVG keeps the text sharp and needs no
// rasteriser; browsers and GitHub's Markdown show it.
#pragma once

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

}  // namespace voxfield::cli
