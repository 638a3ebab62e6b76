// voxfield — errors.
//
// Contract: library code never exits, aborts or prints on a runtime error. Every failure that a
// caller can cause (a malformed file, an absurd size, an edit out of bounds, a missing device) is
// reported by throwing voxfield::Error or one of its subclasses, after which the objects the call
// was given are unchanged (strong guarantee) unless the function documents otherwise.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace voxfield {

// Base class of every error voxfield reports.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A caller passed an argument outside the documented range (chunk edge not a power of two,
// coordinates outside a bounded grid, a box with negative extent...).
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

// A file could not be read or written (missing, permission denied, disk full...).
class IoError : public Error {
 public:
  using Error::Error;
};

// An operation would need more memory than the limit allows (voxfield/limits.h): a file whose
// content would take too much once decoded, a dense buffer over a huge box. The message names the
// file or operation, what it needs and the limit; nothing was allocated for it.
class ResourceLimitError : public Error {
 public:
  using Error::Error;
};

// A file was read but its contents are malformed. The message names the file, the byte offset at
// which the problem was found and what is wrong; offset() returns that offset.
class FormatError : public Error {
 public:
  FormatError(const std::string& path, std::uint64_t offset, const std::string& what)
      : Error(path + ": at byte " + std::to_string(offset) + ": " + what), offset_(offset) {}
  std::uint64_t offset() const { return offset_; }

 private:
  std::uint64_t offset_;
};

}  // namespace voxfield
