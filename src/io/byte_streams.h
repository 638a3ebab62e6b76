// voxfield — standard streams over bytes voxfield holds (internal to the io module).
//
// OpenVDB reads and writes its files through std::istream and std::ostream. A string stream copies:
// the bytes into its string, and its string out again. A .vdb of a large field is hundreds of
// megabytes, and voxfield-mpi's rank 0 holds the parts and the joined file at once, so these
// buffers read the caller's bytes where they are and write straight into the caller's vector.
#pragma once

#include <cstdint>
#include <ios>
#include <span>
#include <streambuf>
#include <vector>

namespace voxfield::detail {

// Reads `bytes` in place (which must outlive the buffer); seeks within them.
class ByteSource : public std::streambuf {
 public:
  explicit ByteSource(std::span<const std::uint8_t> bytes) {
    // The get area is only ever read: std::streambuf writes to it only through a putback of a
    // different character, which pbackfail (not overridden) refuses.
    char* begin = const_cast<char*>(reinterpret_cast<const char*>(bytes.data()));
    setg(begin, begin, begin + bytes.size());
  }

 protected:
  pos_type seekoff(off_type off, std::ios_base::seekdir dir,
                   std::ios_base::openmode which) override {
    if (!(which & std::ios_base::in)) return pos_type(off_type(-1));
    const off_type size = egptr() - eback();
    const off_type from = dir == std::ios_base::beg   ? 0
                          : dir == std::ios_base::cur ? gptr() - eback()
                                                      : size;
    const off_type at = from + off;
    if (at < 0 || at > size) return pos_type(off_type(-1));
    setg(eback(), eback() + at, egptr());
    return pos_type(at);
  }
  pos_type seekpos(pos_type at, std::ios_base::openmode which) override {
    return seekoff(off_type(at), std::ios_base::beg, which);
  }
};

// Appends what is written to `out`; tells its position (the bytes written), seeks nowhere.
class ByteSink : public std::streambuf {
 public:
  explicit ByteSink(std::vector<std::uint8_t>& out) : out_(out) {}

 protected:
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    out_.push_back(static_cast<std::uint8_t>(traits_type::to_char_type(c)));
    return c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    const auto* p = reinterpret_cast<const std::uint8_t*>(s);
    out_.insert(out_.end(), p, p + n);
    return n;
  }
  pos_type seekoff(off_type off, std::ios_base::seekdir dir,
                   std::ios_base::openmode which) override {
    if (off == 0 && dir == std::ios_base::cur && (which & std::ios_base::out))
      return pos_type(static_cast<off_type>(out_.size()));
    return pos_type(off_type(-1));
  }

 private:
  std::vector<std::uint8_t>& out_;
};

}  // namespace voxfield::detail
