// voxfield CLI — grouped bar charts as SVG (svg_chart.h).
#include "svg_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace voxfield::cli {
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
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

std::string number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, v >= 100 ? "%.0f" : v >= 1 ? "%.3g" : "%.2g", v);
  return b;
}

// Colour-blind-friendly series colours (Okabe and Ito).
const char* kColours[] = {"#0072B2", "#E69F00", "#009E73", "#D55E00",
                          "#CC79A7", "#56B4E9", "#F0E442", "#000000"};

}  // namespace

std::string render_svg(const BarChart& c) {
  double lo = INFINITY, hi = 0;
  for (const auto& s : c.values)
    for (double v : s)
      if (v > 0) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
  if (!(hi > 0)) lo = hi = 1;
  const bool log_axis = hi / lo > 100;
  double axis_lo = 0, axis_hi = hi * 1.1;
  if (log_axis) {
    axis_lo = std::pow(10, std::floor(std::log10(lo)));
    axis_hi = std::pow(10, std::ceil(std::log10(hi)));
  }
  const double left = 80, right = 160, top = 50, bottom = 70;
  const double group_w = std::max(60.0, 22.0 * static_cast<double>(c.series.size()) + 20);
  const double plot_w = group_w * static_cast<double>(std::max<std::size_t>(1, c.groups.size()));
  const double plot_h = 320;
  const double width = left + plot_w + right, height = top + plot_h + bottom;
  auto y_of = [&](double v) {
    const double f = log_axis ? (std::log10(v) - std::log10(axis_lo)) /
                                    (std::log10(axis_hi) - std::log10(axis_lo))
                              : (v - axis_lo) / (axis_hi - axis_lo);
    return top + plot_h * (1 - std::clamp(f, 0.0, 1.0));
  };
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << width / 2 << "\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">"
    << escape(c.title) << "</text>\n";
  // Value axis: gridlines at each decade (log) or at five even steps.
  std::vector<double> ticks;
  if (log_axis) {
    for (double t = axis_lo; t <= axis_hi * 1.0001; t *= 10) ticks.push_back(t);
  } else {
    for (int i = 0; i <= 5; ++i) ticks.push_back(axis_lo + (axis_hi - axis_lo) * i / 5);
  }
  for (double t : ticks) {
    const double y = y_of(t);
    o << "<line x1=\"" << left << "\" x2=\"" << left + plot_w << "\" y1=\"" << y << "\" y2=\"" << y
      << "\" stroke=\"#ddd\"/>\n<text x=\"" << left - 6 << "\" y=\"" << y + 4
      << "\" text-anchor=\"end\">" << number(t) << "</text>\n";
  }
  o << "<text transform=\"translate(18," << top + plot_h / 2
    << ") rotate(-90)\" text-anchor=\"middle\">" << escape(c.value_label)
    << (log_axis ? " (log scale)" : "") << "</text>\n";
  for (std::size_t g = 0; g < c.groups.size(); ++g) {
    const double x0 = left + group_w * static_cast<double>(g) + 10;
    for (std::size_t s = 0; s < c.series.size(); ++s) {
      if (s >= c.values.size() || g >= c.values[s].size() || !(c.values[s][g] > 0)) continue;
      const double v = c.values[s][g];
      const double y = y_of(v);
      o << "<rect x=\"" << x0 + 22.0 * static_cast<double>(s) << "\" y=\"" << y
        << "\" width=\"18\" height=\"" << top + plot_h - y << "\" fill=\"" << kColours[s % 8]
        << "\"><title>" << escape(c.series[s]) << ", " << escape(c.groups[g]) << ": " << number(v)
        << "</title></rect>\n";
    }
    o << "<text x=\"" << x0 + group_w / 2 - 10 << "\" y=\"" << top + plot_h + 18
      << "\" text-anchor=\"middle\">" << escape(c.groups[g]) << "</text>\n";
  }
  o << "<line x1=\"" << left << "\" x2=\"" << left + plot_w << "\" y1=\"" << top + plot_h
    << "\" y2=\"" << top + plot_h << "\" stroke=\"black\"/>\n"
    << "<text x=\"" << left + plot_w / 2 << "\" y=\"" << top + plot_h + 44
    << "\" text-anchor=\"middle\">" << escape(c.group_label) << "</text>\n";
  for (std::size_t s = 0; s < c.series.size(); ++s) {
    const double y = top + 10 + 20.0 * static_cast<double>(s);
    o << "<rect x=\"" << left + plot_w + 20 << "\" y=\"" << y
      << "\" width=\"14\" height=\"14\" fill=\"" << kColours[s % 8] << "\"/>\n<text x=\""
      << left + plot_w + 40 << "\" y=\"" << y + 11 << "\">" << escape(c.series[s]) << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace voxfield::cli
