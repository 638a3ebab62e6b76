// voxfield CSG — the S-expression reader: text to Datum trees, with the line and column of every
// token. Lists in parentheses, numbers in any decimal float notation, symbols, "strings" (with \"
// and \\ escapes), comments from ';' to the end of the line.
#include <cctype>
#include <charconv>
#include <cmath>

#include "csg/datum.h"

namespace voxfield::csg::detail {

SourcePos position_of(std::string_view text, std::size_t offset) {
  SourcePos p{1, 1};
  for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++p.line;
      p.column = 1;
    } else {
      ++p.column;
    }
  }
  return p;
}

namespace {

class Reader {
 public:
  Reader(std::string_view text, const std::string& name) : text_(text), name_(name) {}

  std::vector<Datum> read_all() {
    std::vector<Datum> forms;
    for (skip_blank(); i_ < text_.size(); skip_blank()) forms.push_back(read(0));
    return forms;
  }

 private:
  [[noreturn]] void fail(std::size_t offset, const std::string& what) const {
    const SourcePos p = position_of(text_, offset);
    throw ModelError(name_, p.line, p.column, what);
  }

  void skip_blank() {
    while (i_ < text_.size()) {
      const char c = text_[i_];
      if (c == ';') {
        while (i_ < text_.size() && text_[i_] != '\n') ++i_;
      } else if (std::isspace(static_cast<unsigned char>(c))) {
        ++i_;
      } else {
        return;
      }
    }
  }

  Datum make(Datum::Type type, std::size_t at) {
    Datum d;
    d.type = type;
    d.pos = cursor_.at(at);  // tokens are made in text order
    return d;
  }

  Datum read(int depth) {
    const std::size_t start = i_;
    const char c = text_[i_];
    if (c == ')') fail(start, "unexpected ')'");
    if (c == '(') {
      if (depth >= kMaxNesting)
        fail(start, "lists nested deeper than " + std::to_string(kMaxNesting) + " levels");
      Datum list = make(Datum::Type::kList, start);
      ++i_;
      for (skip_blank(); i_ < text_.size() && text_[i_] != ')'; skip_blank())
        list.items.push_back(read(depth + 1));
      if (i_ >= text_.size()) fail(start, "'(' is never closed");
      ++i_;
      return list;
    }
    if (c == '"') {
      Datum s = make(Datum::Type::kString, start);
      for (++i_; i_ < text_.size() && text_[i_] != '"'; ++i_) {
        if (text_[i_] == '\n') fail(start, "string not closed on its line");
        if (text_[i_] == '\\' && i_ + 1 < text_.size() &&
            (text_[i_ + 1] == '"' || text_[i_ + 1] == '\\'))
          ++i_;
        s.text += text_[i_];
      }
      if (i_ >= text_.size()) fail(start, "string never closed");
      ++i_;
      return s;
    }
    while (i_ < text_.size()) {
      const char a = text_[i_];
      if (std::isspace(static_cast<unsigned char>(a)) || a == '(' || a == ')' || a == '"' ||
          a == ';')
        break;
      ++i_;
    }
    const std::string_view atom = text_.substr(start, i_ - start);
    const bool numeric = std::isdigit(static_cast<unsigned char>(atom[0])) ||
                         ((atom[0] == '-' || atom[0] == '+' || atom[0] == '.') && atom.size() > 1 &&
                          (std::isdigit(static_cast<unsigned char>(atom[1])) || atom[1] == '.'));
    if (!numeric) {
      Datum sym = make(Datum::Type::kSymbol, start);
      sym.text = std::string(atom);
      return sym;
    }
    Datum num = make(Datum::Type::kNumber, start);
    const std::string_view digits = atom[0] == '+' ? atom.substr(1) : atom;
    const auto [end, ec] =
        std::from_chars(digits.data(), digits.data() + digits.size(), num.number);
    if (ec == std::errc::result_out_of_range || (ec == std::errc() && !std::isfinite(num.number)))
      fail(start, "number " + std::string(atom) + " is out of range");
    if (ec != std::errc() || end != digits.data() + digits.size())
      fail(start, "\"" + std::string(atom) + "\" is not a number");
    if (std::abs(num.number) > kMaxMagnitude)
      fail(start, "number " + std::string(atom) + " is larger than 1e12 in magnitude");
    return num;
  }

  std::string_view text_;
  const std::string& name_;
  std::size_t i_ = 0;
  PositionCursor cursor_{text_};
};

}  // namespace

std::vector<Datum> read_sexpr(std::string_view text, const std::string& name) {
  if (text.size() > kMaxModelBytes)
    throw ModelError(
        name, 1, 1,
        "model text of " + std::to_string(text.size()) + " bytes is over the 64 MiB limit");
  return Reader(text, name).read_all();
}

}  // namespace voxfield::csg::detail
