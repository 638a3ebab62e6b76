// voxfield CSG — the model language's syntax tree: numbers, symbols, strings and lists, each with
// where it was written. Both readers (S-expressions and JSON) produce it, so the model is built and
// checked by one piece of code (build_model.cpp) whatever the notation.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "voxfield/csg.h"

namespace voxfield::csg::detail {

struct Datum {
  enum class Type { kList, kNumber, kSymbol, kString };
  Type type = Type::kList;
  double number = 0;
  std::string text;  // symbol or string
  std::vector<Datum> items;
  SourcePos pos;
};

// Limits every reader enforces, so that hostile text costs bounded time and stack.
inline constexpr std::size_t kMaxModelBytes = std::size_t{64} << 20;
inline constexpr int kMaxNesting = 256;
// Numbers must be finite and at most this large in magnitude: sizes, offsets and angles beyond it
// are mistakes, and the compiler's arithmetic stays finite.
inline constexpr double kMaxMagnitude = 1e12;

// The top-level forms of an S-expression text (';' starts a comment to the end of the line).
std::vector<Datum> read_sexpr(std::string_view text, const std::string& name);
// The top-level forms of a JSON text: an array whose first element is a string is one form,
// otherwise an array of forms.
std::vector<Datum> read_json(std::string_view text, const std::string& name);

// The 1-based line and column of byte `offset` in `text`.
SourcePos position_of(std::string_view text, std::size_t offset);

// Positions of offsets asked for in increasing order, found by advancing one cursor, so that a
// reader naming every token's position costs time linear in the text (an offset behind the
// cursor, as an error may ask, is found from the start).
class PositionCursor {
 public:
  explicit PositionCursor(std::string_view text) : text_(text) {}
  SourcePos at(std::size_t offset) {
    if (offset < offset_) return position_of(text_, offset);
    for (; offset_ < offset && offset_ < text_.size(); ++offset_) {
      if (text_[offset_] == '\n') {
        ++pos_.line;
        pos_.column = 1;
      } else {
        ++pos_.column;
      }
    }
    return pos_;
  }

 private:
  std::string_view text_;
  std::size_t offset_ = 0;
  SourcePos pos_{1, 1};
};

// The model from its forms: (define NAME EXPR) forms, then exactly one model expression.
Model build_model(const std::vector<Datum>& forms, const std::string& name);

}  // namespace voxfield::csg::detail
