// voxfield CSG — the JSON notation of the model language: the same forms as arrays
// (["move", 1, 0, 0, ["sphere", 2]]), strings for keywords, names and colours. nlohmann::json
// checks the syntax; a second, linear scan of the (then valid) text finds where each value starts,
// so that every error carries a line and column as in the S-expression notation.
#include <cmath>
#include <nlohmann/json.hpp>

#include "csg/datum.h"

namespace voxfield::csg::detail {
namespace {

// The start of every JSON value, in document order (the order of a pre-order walk of the parsed
// tree, since arrays keep their order).
std::vector<SourcePos> value_positions(std::string_view text) {
  std::vector<SourcePos> out;
  SourcePos pos{1, 1};
  std::size_t i = 0;
  auto step = [&] {
    if (text[i] == '\n') {
      ++pos.line;
      pos.column = 1;
    } else {
      ++pos.column;
    }
    ++i;
  };
  while (i < text.size()) {
    const char c = text[i];
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ',' || c == ':' || c == ']' ||
        c == '}') {
      step();
    } else if (c == '[' || c == '{') {
      out.push_back(pos);
      step();
    } else if (c == '"') {
      out.push_back(pos);
      step();
      while (i < text.size() && text[i] != '"') {
        if (text[i] == '\\' && i + 1 < text.size()) step();
        step();
      }
      if (i < text.size()) step();
    } else {
      out.push_back(pos);
      while (i < text.size() &&
             std::string_view(" \t\r\n,]}:").find(text[i]) == std::string_view::npos)
        step();
    }
  }
  return out;
}

class Converter {
 public:
  Converter(std::vector<SourcePos> positions, const std::string& name)
      : positions_(std::move(positions)), name_(name) {}

  Datum convert(const nlohmann::json& j, int depth) {
    const SourcePos pos = next_position();
    if (depth >= kMaxNesting)
      throw ModelError(name_, pos.line, pos.column,
                       "arrays nested deeper than " + std::to_string(kMaxNesting) + " levels");
    Datum d;
    d.pos = pos;
    if (j.is_array()) {
      d.type = Datum::Type::kList;
      for (const auto& item : j) d.items.push_back(convert(item, depth + 1));
    } else if (j.is_number()) {
      d.type = Datum::Type::kNumber;
      d.number = j.get<double>();
      if (!std::isfinite(d.number) || std::abs(d.number) > kMaxMagnitude)
        throw ModelError(name_, pos.line, pos.column,
                         "number " + j.dump() + " is larger than 1e12 in magnitude");
    } else if (j.is_string()) {
      // Keywords, names and colours alike: the model builder tells them apart by place.
      d.type = Datum::Type::kSymbol;
      d.text = j.get<std::string>();
    } else {
      throw ModelError(
          name_, pos.line, pos.column,
          std::string("a ") + j.type_name() +
              " has no meaning in a model (forms are arrays of strings, numbers and forms)");
    }
    return d;
  }

 private:
  SourcePos next_position() {
    // The scan and the parser agree on a valid text; the guard only keeps a disagreement safe.
    return next_ < positions_.size() ? positions_[next_++] : SourcePos{1, 1};
  }

  std::vector<SourcePos> positions_;
  const std::string& name_;
  std::size_t next_ = 0;
};

}  // namespace

std::vector<Datum> read_json(std::string_view text, const std::string& name) {
  if (text.size() > kMaxModelBytes)
    throw ModelError(
        name, 1, 1,
        "model text of " + std::to_string(text.size()) + " bytes is over the 64 MiB limit");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::parse_error& e) {
    const SourcePos p = position_of(text, e.byte > 0 ? e.byte - 1 : 0);
    std::string what = e.what();
    if (const auto colon = what.rfind(": "); colon != std::string::npos)
      what = what.substr(colon + 2);
    throw ModelError(name, p.line, p.column, "invalid JSON: " + what);
  } catch (const nlohmann::json::exception& e) {
    throw ModelError(name, 1, 1, std::string("invalid JSON: ") + e.what());
  }
  Converter converter(value_positions(text), name);
  Datum top = converter.convert(j, 0);
  if (top.type != Datum::Type::kList)
    throw ModelError(name, top.pos.line, top.pos.column,
                     "a JSON model is an array: one form or an array of forms");
  if (!top.items.empty() && top.items[0].type == Datum::Type::kSymbol) return {top};
  return top.items;
}

}  // namespace voxfield::csg::detail
