// voxfield CLI — grouped bar charts (chart.h): a layout of shapes, then SVG or PNG (cairo).
#include "chart.h"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "voxfield/error.h"

namespace voxfield::cli {
namespace {

struct Colour {
  double r, g, b;
  std::string hex() const {
    char s[8];
    std::snprintf(s, sizeof s, "#%02X%02X%02X", static_cast<int>(std::lround(r * 255)),
                  static_cast<int>(std::lround(g * 255)), static_cast<int>(std::lround(b * 255)));
    return s;
  }
};
constexpr Colour kBlack{0, 0, 0}, kGrid{0.867, 0.867, 0.867};
// Colour-blind-friendly series colours (Okabe and Ito).
constexpr Colour kSeries[] = {
    {0, 0.447, 0.698},     {0.902, 0.624, 0},     {0, 0.620, 0.451},     {0.835, 0.369, 0},
    {0.800, 0.475, 0.655}, {0.337, 0.706, 0.914}, {0.941, 0.894, 0.259}, {0, 0, 0}};

struct Rect {
  double x, y, w, h;
  Colour fill;
  std::string tooltip;
};
struct Line {
  double x1, y1, x2, y2;
  Colour stroke;
};
enum class Anchor { kStart, kMiddle, kEnd };
struct Label {
  double x, y;
  std::string text;
  Anchor anchor = Anchor::kStart;
  double size = 12;
  bool vertical = false;  // rotated a quarter turn counter-clockwise
};
struct Layout {
  double width = 0, height = 0;
  std::vector<Rect> rects;
  std::vector<Line> lines;
  std::vector<Label> labels;
};

std::string number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, v >= 100 ? "%.0f" : v >= 1 ? "%.3g" : "%.2g", v);
  return b;
}

Layout lay_out(const BarChart& c) {
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
  Layout l;
  l.width = left + plot_w + right;
  l.height = top + plot_h + bottom;
  auto y_of = [&](double v) {
    const double f = log_axis ? (std::log10(v) - std::log10(axis_lo)) /
                                    (std::log10(axis_hi) - std::log10(axis_lo))
                              : (v - axis_lo) / (axis_hi - axis_lo);
    return top + plot_h * (1 - std::clamp(f, 0.0, 1.0));
  };
  l.labels.push_back({l.width / 2, 24, c.title, Anchor::kMiddle, 15});
  // Value axis: gridlines at each decade (log) or at five even steps.
  std::vector<double> ticks;
  if (log_axis) {
    for (double t = axis_lo; t <= axis_hi * 1.0001; t *= 10) ticks.push_back(t);
  } else {
    for (int i = 0; i <= 5; ++i) ticks.push_back(axis_lo + (axis_hi - axis_lo) * i / 5);
  }
  for (double t : ticks) {
    const double y = y_of(t);
    l.lines.push_back({left, y, left + plot_w, y, kGrid});
    l.labels.push_back({left - 6, y + 4, number(t), Anchor::kEnd});
  }
  l.labels.push_back({18, top + plot_h / 2, c.value_label + (log_axis ? " (log scale)" : ""),
                      Anchor::kMiddle, 12, true});
  for (std::size_t g = 0; g < c.groups.size(); ++g) {
    const double x0 = left + group_w * static_cast<double>(g) + 10;
    for (std::size_t s = 0; s < c.series.size(); ++s) {
      if (s >= c.values.size() || g >= c.values[s].size() || !(c.values[s][g] > 0)) continue;
      const double v = c.values[s][g];
      const double y = y_of(v);
      l.rects.push_back({x0 + 22.0 * static_cast<double>(s), y, 18, top + plot_h - y,
                         kSeries[s % 8], c.series[s] + ", " + c.groups[g] + ": " + number(v)});
    }
    l.labels.push_back({x0 + group_w / 2 - 10, top + plot_h + 18, c.groups[g], Anchor::kMiddle});
  }
  l.lines.push_back({left, top + plot_h, left + plot_w, top + plot_h, kBlack});
  l.labels.push_back({left + plot_w / 2, top + plot_h + 44, c.group_label, Anchor::kMiddle});
  for (std::size_t s = 0; s < c.series.size(); ++s) {
    const double y = top + 10 + 20.0 * static_cast<double>(s);
    l.rects.push_back({left + plot_w + 20, y, 14, 14, kSeries[s % 8], ""});
    l.labels.push_back({left + plot_w + 40, y + 11, c.series[s]});
  }
  return l;
}

std::string escape(const std::string& text) {
  std::string out;
  for (char ch : text) {
    if (ch == '<')
      out += "&lt;";
    else if (ch == '>')
      out += "&gt;";
    else if (ch == '&')
      out += "&amp;";
    else if (ch == '"')
      out += "&quot;";
    else
      out += ch;
  }
  return out;
}

}  // namespace

std::string render_svg(const BarChart& chart) {
  const Layout l = lay_out(chart);
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << l.width << "\" height=\"" << l.height
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  for (const Line& s : l.lines)
    o << "<line x1=\"" << s.x1 << "\" x2=\"" << s.x2 << "\" y1=\"" << s.y1 << "\" y2=\"" << s.y2
      << "\" stroke=\"" << s.stroke.hex() << "\"/>\n";
  for (const Rect& r : l.rects) {
    o << "<rect x=\"" << r.x << "\" y=\"" << r.y << "\" width=\"" << r.w << "\" height=\"" << r.h
      << "\" fill=\"" << r.fill.hex() << "\">";
    if (!r.tooltip.empty()) o << "<title>" << escape(r.tooltip) << "</title>";
    o << "</rect>\n";
  }
  for (const Label& t : l.labels) {
    const char* anchor = t.anchor == Anchor::kMiddle ? "middle"
                         : t.anchor == Anchor::kEnd  ? "end"
                                                     : "start";
    if (t.vertical)
      o << "<text transform=\"translate(" << t.x << "," << t.y << ") rotate(-90)\"";
    else
      o << "<text x=\"" << t.x << "\" y=\"" << t.y << "\"";
    o << " text-anchor=\"" << anchor << "\"";
    if (t.size != 12) o << " font-size=\"" << t.size << "\"";
    o << ">" << escape(t.text) << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

std::vector<std::uint8_t> render_png(const BarChart& chart) {
  const Layout l = lay_out(chart);
  const int w = static_cast<int>(std::ceil(l.width)), h = static_cast<int>(std::ceil(l.height));
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h), cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()), cairo_destroy);
  cairo_t* c = cr.get();
  cairo_set_source_rgb(c, 1, 1, 1);
  cairo_paint(c);
  cairo_set_line_width(c, 1);
  for (const Line& s : l.lines) {
    cairo_set_source_rgb(c, s.stroke.r, s.stroke.g, s.stroke.b);
    cairo_move_to(c, s.x1, std::floor(s.y1) + 0.5);  // on the pixel grid: a crisp 1-pixel line
    cairo_line_to(c, s.x2, std::floor(s.y2) + 0.5);
    cairo_stroke(c);
  }
  for (const Rect& r : l.rects) {
    cairo_set_source_rgb(c, r.fill.r, r.fill.g, r.fill.b);
    cairo_rectangle(c, r.x, r.y, r.w, r.h);
    cairo_fill(c);
  }
  cairo_select_font_face(c, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_source_rgb(c, 0, 0, 0);
  for (const Label& t : l.labels) {
    cairo_set_font_size(c, t.size);
    cairo_text_extents_t e;
    cairo_text_extents(c, t.text.c_str(), &e);
    const double shift = t.anchor == Anchor::kMiddle ? e.x_advance / 2
                         : t.anchor == Anchor::kEnd  ? e.x_advance
                                                     : 0;
    cairo_save(c);
    cairo_translate(c, t.x, t.y);
    if (t.vertical) cairo_rotate(c, -M_PI / 2);
    cairo_move_to(c, -shift, 0);
    cairo_show_text(c, t.text.c_str());
    cairo_restore(c);
  }
  cairo_surface_flush(surface.get());
  if (cairo_status(c) != CAIRO_STATUS_SUCCESS)
    throw IoError(std::string("plot: cairo cannot draw it: ") +
                  cairo_status_to_string(cairo_status(c)));
  std::vector<std::uint8_t> bytes;
  const cairo_status_t written = cairo_surface_write_to_png_stream(
      surface.get(),
      [](void* out, const unsigned char* data, unsigned int length) {
        auto* v = static_cast<std::vector<std::uint8_t>*>(out);
        v->insert(v->end(), data, data + length);
        return CAIRO_STATUS_SUCCESS;
      },
      &bytes);
  if (written != CAIRO_STATUS_SUCCESS)
    throw IoError(std::string("plot: cairo cannot encode the PNG: ") +
                  cairo_status_to_string(written));
  return bytes;
}

}  // namespace voxfield::cli
