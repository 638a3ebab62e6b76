// voxfield CSG — the tokenizer and parser of OpenSCAD's flattened CSG tree (the .csg file
// `openscad -o model.csg` writes; internal to the OpenSCAD import, openscad_reader.cpp): statements
// with positional and named arguments, values (numbers, booleans, strings, undef, vectors) and
// modifiers, each statement with its position for errors. Limits: the model language's nesting
// depth and text size (datum.h).
#pragma once

#include <cctype>
#include <charconv>
#include <cmath>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "csg/datum.h"
#include "voxfield/csg.h"

namespace voxfield::csg::openscad {

struct Value {
  enum class Type { kNumber, kBool, kString, kUndef, kVector };
  Type type = Type::kUndef;
  double number = 0;
  bool boolean = false;
  std::string text;
  std::vector<Value> items;
};

struct Statement {
  char modifier = 0;  // OpenSCAD's '%' (background), '*' (disabled), '#' (highlight), '!' (root)
  std::string name;
  std::vector<std::pair<std::string, Value>> args;  // key empty for positional arguments
  std::vector<Statement> children;
  SourcePos pos;
};

class Parser {
 public:
  Parser(std::string_view text, const std::string& name) : text_(text), name_(name) {}

  std::vector<Statement> file() {
    std::vector<Statement> out;
    for (skip(); i_ < text_.size(); skip()) out.push_back(statement(0));
    return out;
  }

  [[noreturn]] void fail(SourcePos p, const std::string& what) const {
    throw ModelError(name_, p.line, p.column, what);
  }
  const std::string& name() const { return name_; }

 private:
  SourcePos here() const { return at(i_); }
  SourcePos at(std::size_t offset) const { return cursor_.at(offset); }
  [[noreturn]] void fail(const std::string& what) const { fail(here(), what); }

  void skip() {
    while (i_ < text_.size()) {
      if (std::isspace(static_cast<unsigned char>(text_[i_]))) {
        ++i_;
      } else if (text_.substr(i_, 2) == "//") {
        while (i_ < text_.size() && text_[i_] != '\n') ++i_;
      } else {
        return;
      }
    }
  }
  void expect(char c) {
    skip();
    if (i_ >= text_.size() || text_[i_] != c) fail(std::string("expected '") + c + "'");
    ++i_;
  }
  bool accept(char c) {
    skip();
    if (i_ < text_.size() && text_[i_] == c) {
      ++i_;
      return true;
    }
    return false;
  }
  std::string identifier() {
    skip();
    const std::size_t start = i_;
    while (i_ < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[i_])) ||
                                 text_[i_] == '_' || text_[i_] == '$'))
      ++i_;
    if (i_ == start) fail("expected a name");
    return std::string(text_.substr(start, i_ - start));
  }

  Statement statement(int depth) {
    if (depth > detail::kMaxNesting) fail("statements nested deeper than 256 levels");
    skip();
    Statement s;
    s.pos = here();
    if (i_ < text_.size() && std::string_view("%*#!").find(text_[i_]) != std::string_view::npos) {
      s.modifier = text_[i_++];
      skip();
    }
    s.name = identifier();
    expect('(');
    if (!accept(')')) {
      do {
        skip();
        std::string key;
        const std::size_t save = i_;
        if (i_ < text_.size() &&
            (std::isalpha(static_cast<unsigned char>(text_[i_])) || text_[i_] == '$')) {
          key = identifier();
          if (!accept('=')) {  // a bare word is a value (true, false, undef)
            i_ = save;
            key.clear();
          }
        }
        s.args.push_back({key, value(0)});
      } while (accept(','));
      expect(')');
    }
    if (accept(';')) return s;
    expect('{');
    while (!accept('}')) {
      if (i_ >= text_.size()) fail(s.pos, "'{' of " + s.name + "() is never closed");
      s.children.push_back(statement(depth + 1));
    }
    return s;
  }

  Value value(int depth) {
    if (depth > detail::kMaxNesting) fail("vectors nested deeper than 256 levels");
    skip();
    if (i_ >= text_.size()) fail("expected a value");
    Value v;
    const char c = text_[i_];
    if (c == '[') {
      ++i_;
      v.type = Value::Type::kVector;
      if (!accept(']')) {
        do v.items.push_back(value(depth + 1));
        while (accept(','));
        expect(']');
      }
      return v;
    }
    if (c == '"') {
      v.type = Value::Type::kString;
      for (++i_; i_ < text_.size() && text_[i_] != '"'; ++i_) {
        if (text_[i_] == '\\' && i_ + 1 < text_.size()) ++i_;
        v.text += text_[i_];
      }
      if (i_ >= text_.size()) fail("string never closed");
      ++i_;
      return v;
    }
    if (std::isalpha(static_cast<unsigned char>(c))) {
      const std::string word = identifier();
      if (word == "true" || word == "false") {
        v.type = Value::Type::kBool;
        v.boolean = word == "true";
      } else if (word != "undef") {
        fail("unexpected word \"" + word + "\"");
      }
      return v;
    }
    const std::size_t start = i_;
    while (i_ < text_.size() &&
           (std::isdigit(static_cast<unsigned char>(text_[i_])) ||
            std::string_view("+-.eE").find(text_[i_]) != std::string_view::npos))
      ++i_;
    std::string_view digits = text_.substr(start, i_ - start);
    if (!digits.empty() && digits[0] == '+') digits.remove_prefix(1);
    v.type = Value::Type::kNumber;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v.number);
    if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size() ||
        !std::isfinite(v.number))
      fail(at(start), "expected a number");
    return v;
  }

  std::string_view text_;
  const std::string& name_;
  std::size_t i_ = 0;
  mutable detail::PositionCursor cursor_{text_};
};

}  // namespace voxfield::csg::openscad
