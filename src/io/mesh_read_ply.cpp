// Reading PLY, Greg Turk's polygon file format (1994): a text header declaring elements and their
// properties, then the elements in ASCII or binary (little- or big-endian). The "vertex" element's
// x, y, z and the "face" element's vertex_indices (or vertex_index) list are kept; every other
// element and property is read past by its declared type, so files with normals, colours, edges
// or custom elements load alike.
#include <algorithm>
#include <cstring>

#include "io/mesh_text.h"
#include "voxfield/mesh_read.h"

namespace voxfield::detail {
namespace {

enum class Encoding { kAscii, kLittle, kBig };

enum class Type { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

std::optional<Type> parse_type(std::string_view w) {
  if (w == "char" || w == "int8") return Type::kI8;
  if (w == "uchar" || w == "uint8") return Type::kU8;
  if (w == "short" || w == "int16") return Type::kI16;
  if (w == "ushort" || w == "uint16") return Type::kU16;
  if (w == "int" || w == "int32") return Type::kI32;
  if (w == "uint" || w == "uint32") return Type::kU32;
  if (w == "float" || w == "float32") return Type::kF32;
  if (w == "double" || w == "float64") return Type::kF64;
  return std::nullopt;
}

std::size_t type_size(Type t) {
  switch (t) {
    case Type::kI8:
    case Type::kU8:
      return 1;
    case Type::kI16:
    case Type::kU16:
      return 2;
    case Type::kI32:
    case Type::kU32:
    case Type::kF32:
      return 4;
    case Type::kF64:
      return 8;
  }
  return 1;
}

struct Property {
  std::string name;
  Type type = Type::kF32;
  bool list = false;
  Type count_type = Type::kU8;  // lists only
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  std::size_t header_offset = 0;
};

// Values of the body, ASCII or binary, with the offset of every problem.
class BodyReader {
 public:
  BodyReader(std::span<const std::uint8_t> bytes, const std::string& name, std::size_t start,
             Encoding encoding)
      : bytes_(bytes), name_(name), pos_(start), encoding_(encoding), text_(bytes, name, start) {}

  std::size_t offset() const { return encoding_ == Encoding::kAscii ? text_.offset() : pos_; }
  // Where the next value begins (past the white space before it, in ASCII).
  std::size_t next_offset() {
    if (encoding_ == Encoding::kAscii) text_.skip_space();
    return offset();
  }
  std::size_t remaining() const { return bytes_.size() - offset(); }

  double value(Type t, const char* what) {
    if (encoding_ == Encoding::kAscii) {
      const double v = text_.number(what, /*across_lines=*/true);
      return v;
    }
    const std::size_t n = type_size(t);
    if (n > bytes_.size() - pos_)
      throw FormatError(name_, pos_, std::string("the file ends inside ") + what);
    std::uint8_t raw[8];
    std::memcpy(raw, bytes_.data() + pos_, n);
    if (encoding_ == Encoding::kBig) std::reverse(raw, raw + n);  // voxfield's hosts: little-endian
    pos_ += n;
    switch (t) {
      case Type::kI8:
        return static_cast<std::int8_t>(raw[0]);
      case Type::kU8:
        return raw[0];
      case Type::kI16:
        return load<std::int16_t>(raw);
      case Type::kU16:
        return load<std::uint16_t>(raw);
      case Type::kI32:
        return load<std::int32_t>(raw);
      case Type::kU32:
        return load<std::uint32_t>(raw);
      case Type::kF32: {
        const float f = load<float>(raw);
        if (!std::isfinite(f))
          throw FormatError(name_, pos_ - n, std::string(what) + " is not finite");
        return f;
      }
      case Type::kF64: {
        const double d = load<double>(raw);
        if (!std::isfinite(d))
          throw FormatError(name_, pos_ - n, std::string(what) + " is not finite");
        return d;
      }
    }
    return 0;
  }
  // An integer value (list counts, indices): a float that is not a whole number is refused.
  std::int64_t integer(Type t, const char* what) {
    const std::size_t at = next_offset();
    const double v = value(t, what);
    if (v != std::floor(v) || v < -9.0e15 || v > 9.0e15)
      throw FormatError(name_, at, std::string(what) + " is not an integer");
    return static_cast<std::int64_t>(v);
  }

 private:
  template <typename T>
  static T load(const std::uint8_t* raw) {
    T v;
    std::memcpy(&v, raw, sizeof v);
    return v;
  }
  std::span<const std::uint8_t> bytes_;
  const std::string& name_;
  std::size_t pos_;
  Encoding encoding_;
  TextCursor text_;
};

}  // namespace

TriangleMesh parse_ply(std::span<const std::uint8_t> bytes, const std::string& name,
                       std::uint64_t memory_limit) {
  TextCursor in(bytes, name);
  if (in.word() != "ply") in.fail_at(0, "not a PLY file (it does not begin with \"ply\")");
  in.next_line();
  std::optional<Encoding> encoding;
  std::vector<Element> elements;
  for (;;) {
    if (in.at_end()) in.fail("the header has no end_header");
    const std::size_t at = in.offset();
    const std::string_view keyword = in.word();
    if (keyword == "end_header") {
      in.next_line();
      break;
    }
    if (keyword == "format") {
      const std::string_view f = in.word();
      if (f == "ascii")
        encoding = Encoding::kAscii;
      else if (f == "binary_little_endian")
        encoding = Encoding::kLittle;
      else if (f == "binary_big_endian")
        encoding = Encoding::kBig;
      else
        in.fail_at(at, "unknown format \"" + TextCursor::printable(f) + "\"");
    } else if (keyword == "element") {
      Element e;
      e.header_offset = at;
      e.name = std::string(in.word());
      const std::int64_t count = in.integer("the element's count");
      if (count < 0) in.fail_at(at, "a negative element count");
      e.count = static_cast<std::uint64_t>(count);
      elements.push_back(std::move(e));
    } else if (keyword == "property") {
      if (elements.empty()) in.fail_at(at, "a property before any element");
      Property p;
      std::string_view t = in.word();
      if (t == "list") {
        p.list = true;
        const auto ct = parse_type(in.word());
        if (!ct || *ct == Type::kF32 || *ct == Type::kF64)
          in.fail_at(at, "a list count must be an integer type");
        p.count_type = *ct;
        t = in.word();
      }
      const auto type = parse_type(t);
      if (!type) in.fail_at(at, "unknown property type \"" + TextCursor::printable(t) + "\"");
      p.type = *type;
      p.name = std::string(in.word());
      elements.back().properties.push_back(std::move(p));
    } else if (keyword != "comment" && keyword != "obj_info" && !keyword.empty()) {
      in.fail_at(at, "unknown header line \"" + TextCursor::printable(keyword) + "\"");
    }
    in.next_line();
  }
  if (!encoding) in.fail_at(0, "the header has no format line");

  // What the vertices and faces are made of, and whether the counts can fit the bytes left.
  const Element* vertex = nullptr;
  const Element* face = nullptr;
  for (const Element& e : elements) {
    if (e.name == "vertex" && !vertex) vertex = &e;
    if (e.name == "face" && !face) face = &e;
    std::uint64_t min_bytes = 0;  // per element: scalars whole, lists with a zero count
    for (const Property& p : e.properties)
      min_bytes += *encoding == Encoding::kAscii ? 2 : type_size(p.list ? p.count_type : p.type);
    if (min_bytes > 0 && e.count > (bytes.size() - in.offset()) / min_bytes)
      in.fail_at(e.header_offset,
                 std::to_string(e.count) + " " + e.name + " elements cannot fit in the " +
                     std::to_string(bytes.size() - in.offset()) + " bytes after the header");
  }
  if (!vertex) in.fail_at(0, "no vertex element");
  if (vertex->count > 0xFFFFFFFFull)
    in.fail_at(vertex->header_offset, "more vertices than 32-bit indices can name");
  if (!face) in.fail_at(0, "no face element (a point cloud is not a mesh)");
  int xyz[3] = {-1, -1, -1}, indices = -1;
  for (std::size_t i = 0; i < vertex->properties.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (!vertex->properties[i].list && vertex->properties[i].name == std::string(1, "xyz"[k]))
        xyz[k] = static_cast<int>(i);
  for (int k = 0; k < 3; ++k)
    if (xyz[k] < 0)
      in.fail_at(vertex->header_offset, std::string("the vertex has no ") + "xyz"[k] + " property");
  for (std::size_t i = 0; i < face->properties.size(); ++i)
    if (face->properties[i].list && (face->properties[i].name == "vertex_indices" ||
                                     face->properties[i].name == "vertex_index"))
      indices = static_cast<int>(i);
  if (indices < 0) in.fail_at(face->header_offset, "the face has no vertex_indices list");

  MeshBuilder out(name, memory_limit);
  out.reserve(vertex->count, face->count);
  BodyReader body(bytes, name, in.offset(), *encoding);
  std::vector<std::uint32_t> corners;
  for (const Element& e : elements) {
    if (e.properties.empty()) continue;  // nothing stored: however many, they take no bytes
    for (std::uint64_t n = 0; n < e.count; ++n) {
      double position[3] = {0, 0, 0};
      corners.clear();
      for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const Property& p = e.properties[i];
        if (!p.list) {
          const double v = body.value(p.type, "a property value");
          if (&e == vertex)
            for (int k = 0; k < 3; ++k)
              if (xyz[k] == static_cast<int>(i)) position[k] = v;
          continue;
        }
        const std::size_t at = body.next_offset();
        const std::int64_t count = body.integer(p.count_type, "a list's count");
        const bool is_faces = &e == face && static_cast<int>(i) == indices;
        if (count < 0 || static_cast<std::uint64_t>(count) > body.remaining())
          throw FormatError(name, at, "a list of " + std::to_string(count) + " values");
        if (is_faces && count < 3)
          throw FormatError(name, at,
                            "a face of " + std::to_string(count) + " corners (3 at least)");
        for (std::int64_t k = 0; k < count; ++k) {
          const std::size_t vat = body.next_offset();
          const std::int64_t v = body.integer(p.type, "a list value");
          if (!is_faces) continue;
          if (v < 0 || static_cast<std::uint64_t>(v) >= vertex->count)
            throw FormatError(name, vat,
                              "the face names vertex " + std::to_string(v) + " of " +
                                  std::to_string(vertex->count));
          corners.push_back(static_cast<std::uint32_t>(v));
        }
      }
      if (&e == vertex) out.vertex(position[0], position[1], position[2]);
      for (std::size_t k = 1; k + 1 < corners.size(); ++k)
        out.triangle(corners[0], corners[k], corners[k + 1]);
    }
  }
  return out.take();
}

}  // namespace voxfield::detail
