// voxfield — bounds-checked little-endian reader for binary parsers (internal).
//
// Every read checks the remaining length first and throws FormatError naming the file and the
// absolute offset, so a parser built on it cannot read out of bounds whatever the input.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include "voxfield/error.h"

namespace voxfield::detail {

class ByteReader {
 public:
  ByteReader(std::span<const std::uint8_t> bytes, const std::string& name, std::uint64_t base = 0)
      : bytes_(bytes), name_(&name), base_(base) {}

  std::uint64_t offset() const { return base_ + pos_; }  // absolute offset in the file
  const std::string& name() const { return *name_; }
  std::size_t remaining() const { return bytes_.size() - pos_; }
  bool at_end() const { return pos_ == bytes_.size(); }

  [[noreturn]] void fail(const std::string& what) const {
    throw FormatError(*name_, offset(), what);
  }
  [[noreturn]] void fail_at(std::uint64_t absolute_offset, const std::string& what) const {
    throw FormatError(*name_, absolute_offset, what);
  }

  void need(std::size_t n, const char* what) const {
    if (n > remaining()) {
      fail(std::string("truncated ") + what + ": needs " + std::to_string(n) + " bytes, " +
           std::to_string(remaining()) + " left");
    }
  }
  std::uint8_t u8(const char* what = "byte") {
    need(1, what);
    return bytes_[pos_++];
  }
  std::uint32_t u32(const char* what = "integer") {
    need(4, what);
    std::uint32_t v;
    std::memcpy(&v, bytes_.data() + pos_, 4);  // voxfield targets little-endian hosts
    pos_ += 4;
    return v;
  }
  std::int32_t i32(const char* what = "integer") { return static_cast<std::int32_t>(u32(what)); }
  std::uint64_t u64(const char* what = "integer") {
    need(8, what);
    std::uint64_t v;
    std::memcpy(&v, bytes_.data() + pos_, 8);
    pos_ += 8;
    return v;
  }
  std::int64_t i64(const char* what = "integer") { return static_cast<std::int64_t>(u64(what)); }
  double f64(const char* what = "number") {
    const std::uint64_t bits = u64(what);
    double v;
    std::memcpy(&v, &bits, 8);
    return v;
  }
  std::uint16_t u16(const char* what = "integer") {
    need(2, what);
    std::uint16_t v;
    std::memcpy(&v, bytes_.data() + pos_, 2);
    pos_ += 2;
    return v;
  }
  std::span<const std::uint8_t> take(std::size_t n, const char* what) {
    need(n, what);
    auto s = bytes_.subspan(pos_, n);
    pos_ += n;
    return s;
  }
  // A sub-reader over the next n bytes, reporting offsets in the same file.
  ByteReader sub(std::size_t n, const char* what) {
    const std::uint64_t at = offset();
    auto s = take(n, what);
    return ByteReader(s, *name_, at);
  }
  void skip(std::size_t n, const char* what) { take(n, what); }
  // Moves to an absolute offset in this reader's span (as offset() reports it); throws when the
  // offset lies outside it.
  void seek(std::uint64_t absolute_offset, const char* what) {
    if (absolute_offset < base_ || absolute_offset - base_ > bytes_.size())
      fail(std::string(what) + " at offset " + std::to_string(absolute_offset) +
           " lies outside the " + std::to_string(bytes_.size()) + "-byte input");
    pos_ = static_cast<std::size_t>(absolute_offset - base_);
  }

 private:
  std::span<const std::uint8_t> bytes_;
  const std::string* name_;
  std::uint64_t base_;
  std::size_t pos_ = 0;
};

}  // namespace voxfield::detail
