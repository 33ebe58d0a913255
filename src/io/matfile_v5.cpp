// The v5 pre-check of a .mat file (matfile_v5.hpp; matfile.cpp calls it
// before it hands a level-5 file to libmatio).
//
// libmatio trusts the headers inside a variable: listing a file
// (Mat_VarReadNextInfo) allocates by sizes it reads there — for cells and
// structs one pointer per declared member — so an 1842-byte file with three
// corrupted bytes in its compressed elements made it calloc 1.6 GB
// (fuzz_mat; corpus crash-corrupt-compressed-struct.mat). Before matio sees
// a v5 file, every top-level element is walked here: a compressed element
// is inflated on the fly (zlib, which libmatio's pkg-config already links)
// and must be one whole stream with a verified checksum; in every matrix, at
// any depth, a cell's or struct's declared members must fit the bytes the
// matrix has (8 each at least, plus a small slack for the member-less cells
// libmatio itself writes). Only headers are kept; numeric data is skipped,
// so the walk is one pass over the file.
#include "matfile_v5.hpp"

#include <zlib.h>

#include <algorithm>
#include <fstream>
#include <vector>

#include "texel/error.hpp"

namespace texel::mat::v5 {
namespace {

/// Sequential bytes of one top-level element: the file itself, or the zlib
/// stream of a compressed element inflated through a small buffer.
class ElementSource {
 public:
  ElementSource(std::ifstream& in, std::uintmax_t bytes, bool compressed) : in_(in), left_(bytes), compressed_(compressed) {
    if (compressed_ && inflateInit(&z_) != Z_OK) throw FormatError("zlib cannot start");
  }
  ~ElementSource() {
    if (compressed_) inflateEnd(&z_);
  }
  ElementSource(const ElementSource&) = delete;
  ElementSource& operator=(const ElementSource&) = delete;

  /// Reads exactly n bytes (out may be null: skip); false if the element or
  /// its zlib stream ends first, or the stream is corrupt.
  bool read(unsigned char* out, std::uint64_t n) {
    unsigned char scratch[4096];
    while (n > 0) {
      const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(n, sizeof scratch));
      unsigned char* dst = out ? out : scratch;
      if (!(compressed_ ? inflate_into(dst, take) : file_into(dst, take))) return false;
      if (out) out += take;
      n -= take;
    }
    return true;
  }

  /// A compressed element: its stream ends here, checksum verified, within
  /// `slack` more bytes of output (padding). Uncompressed: always true.
  bool finish(std::size_t slack) {
    if (!compressed_) return true;
    unsigned char rest[16];
    z_.next_out = rest;
    z_.avail_out = static_cast<uInt>(std::min(slack, sizeof rest));
    while (!ended_)
      if (!step()) return false;
    return true;
  }

 private:
  bool file_into(unsigned char* dst, std::size_t n) {
    if (n > left_ || !in_.read(reinterpret_cast<char*>(dst), static_cast<std::streamsize>(n))) return false;
    left_ -= n;
    return true;
  }
  bool inflate_into(unsigned char* dst, std::size_t n) {
    z_.next_out = dst;
    z_.avail_out = static_cast<uInt>(n);
    while (z_.avail_out > 0)
      if (ended_ || !step()) return false;
    return true;
  }
  /// One inflate call, refilling the input first; false on a corrupt or
  /// truncated stream.
  bool step() {
    if (z_.avail_in == 0 && left_ > 0) {
      const std::size_t take = static_cast<std::size_t>(std::min<std::uintmax_t>(left_, sizeof in_buf_));
      if (!in_.read(reinterpret_cast<char*>(in_buf_), static_cast<std::streamsize>(take))) return false;
      left_ -= take;
      z_.next_in = in_buf_;
      z_.avail_in = static_cast<uInt>(take);
    }
    // Z_OK means progress; Z_BUF_ERROR (no progress possible) is a
    // truncated stream here, since the input was just refilled.
    const int r = ::inflate(&z_, Z_NO_FLUSH);
    if (r == Z_STREAM_END) ended_ = true;
    return r == Z_OK || r == Z_STREAM_END;
  }

  std::ifstream& in_;
  std::uintmax_t left_;
  bool compressed_;
  bool ended_ = false;
  z_stream z_{};
  unsigned char in_buf_[16384];
};

constexpr std::uint32_t mi_int8 = 1, mi_int32 = 5, mi_uint32 = 6, mi_matrix = 14, mi_compressed = 15;
constexpr unsigned mx_cell = 1, mx_struct = 2, mx_object = 3;

struct V5Walker {
  const std::string& path;
  bool swap;

  std::uint32_t u32(const unsigned char* b) const {
    return swap ? (std::uint32_t{b[0]} << 24 | std::uint32_t{b[1]} << 16 | std::uint32_t{b[2]} << 8 | b[3])
                : (std::uint32_t{b[3]} << 24 | std::uint32_t{b[2]} << 16 | std::uint32_t{b[1]} << 8 | b[0]);
  }
  [[noreturn]] void fail(const std::string& why) const { throw FormatError("'" + path + "' is corrupt: " + why); }

  /// One sub-element of a matrix, `left` bytes of it remaining: its type and
  /// data (small elements pack up to 4 bytes into the tag); data beyond
  /// `keep` bytes is skipped. Returns the type.
  std::uint32_t element(ElementSource& src, std::uint64_t& left, std::vector<unsigned char>& data, std::size_t keep,
                        std::uint64_t* declared = nullptr) const {
    unsigned char tag[8];
    if (left < 8 || !src.read(tag, 8)) fail("a matrix ends inside an element tag");
    left -= 8;
    std::uint32_t type = u32(tag);
    std::uint64_t bytes = u32(tag + 4);
    if (type >> 16) {  // small data element: [bytes u16][type u16][data ≤ 4 bytes]
      bytes = type >> 16;
      type &= 0xFFFF;
      if (bytes > 4) fail("a small data element declares " + std::to_string(bytes) + " bytes");
      data.assign(tag + 4, tag + 4 + bytes);
      if (declared) *declared = bytes;
      return type;
    }
    const std::uint64_t padded = (bytes + 7) / 8 * 8;
    if (padded > left) fail("an element declares " + std::to_string(bytes) + " bytes, its matrix has " + std::to_string(left));
    if (declared) *declared = bytes;
    data.resize(static_cast<std::size_t>(std::min<std::uint64_t>(bytes, keep)));
    if (!src.read(data.data(), data.size()) || !src.read(nullptr, padded - data.size())) fail("an element is truncated");
    left -= padded;
    return type;
  }

  /// The matrix after its tag, `left` bytes long: header, then for cells and
  /// structs every member, whose count must fit the bytes present.
  void matrix(ElementSource& src, std::uint64_t left, int depth) const {
    if (depth > 32) fail("cells and structs nest deeper than 32 levels");
    if (left == 0) return;  // an empty matrix (MATLAB writes [] cells this way)
    std::vector<unsigned char> d;
    if (element(src, left, d, 8) != mi_uint32 || d.size() < 4) fail("a matrix lacks its array flags");
    const unsigned cls = u32(d.data()) & 0xFF;
    if (element(src, left, d, 4 * 64) != mi_int32 || d.size() < 8 || d.size() % 4 != 0)
      fail("a matrix lacks its dimensions (2 to 64)");
    std::uint64_t count = 1;
    for (std::size_t k = 0; k < d.size(); k += 4) {
      const auto dim = static_cast<std::int32_t>(u32(d.data() + k));
      if (dim < 0) fail("a matrix declares a negative dimension");
      count = static_cast<std::uint64_t>(dim) > (std::uint64_t{1} << 40) / std::max<std::uint64_t>(count, 1)
                  ? std::uint64_t{1} << 40
                  : count * static_cast<std::uint64_t>(dim);
    }
    (void)element(src, left, d, 0);  // name
    if (cls == mx_struct || cls == mx_object) {
      if (cls == mx_object) (void)element(src, left, d, 0);  // class name
      if (element(src, left, d, 4) != mi_int32 || d.size() != 4) fail("a struct lacks its field-name length");
      const std::uint32_t name_len = u32(d.data());
      std::uint64_t names = 0;
      if (element(src, left, d, 0, &names) != mi_int8) fail("a struct lacks its field names");
      const std::uint64_t fields = name_len == 0 ? 0 : names / name_len;
      count = fields == 0 ? 0 : (count > (std::uint64_t{1} << 40) / fields ? std::uint64_t{1} << 40 : count * fields);
    } else if (cls != mx_cell) {
      if (!src.read(nullptr, left))
        fail("a matrix is truncated, or its compressed stream is corrupt");  // numeric, char, sparse: data only
      return;
    }
    // libmatio writes (and reads) a cell without its members, e.g. one created
    // with no data; what it must not do is allocate for members that cannot
    // be there, so the slack is small: 2^16 members, 512 KiB of pointers.
    constexpr std::uint64_t slack = std::uint64_t{1} << 16;
    if (count > left / 8 + slack)
      fail(std::string(cls == mx_cell ? "a cell" : "a struct") + " declares " + std::to_string(count) + " members in " +
           std::to_string(left) + " bytes (each needs at least 8)");
    for (std::uint64_t i = 0; i < count && left > 0; ++i) {
      unsigned char tag[8];
      if (left < 8 || !src.read(tag, 8)) fail("a cell or struct ends inside a member's tag");
      left -= 8;
      const std::uint64_t bytes = u32(tag + 4);
      if (u32(tag) != mi_matrix || bytes > left) fail("a member is not a matrix inside its parent");
      matrix(src, bytes, depth + 1);
      left -= bytes;
    }
    if (!src.read(nullptr, left)) fail("a matrix is truncated, or its compressed stream is corrupt");
  }
};

}  // namespace

std::size_t check_v5_elements(const std::string& path, std::uintmax_t file_size) {
  std::ifstream in(path, std::ios::binary);
  char endian[2];
  in.seekg(126);
  if (!in.read(endian, 2)) throw IoError("cannot read '" + path + "'");
  const bool swap = endian[0] == 'M' && endian[1] == 'I';
  auto u32 = [swap](const unsigned char* b) {
    return swap ? (std::uint32_t{b[0]} << 24 | std::uint32_t{b[1]} << 16 | std::uint32_t{b[2]} << 8 | b[3])
                : (std::uint32_t{b[3]} << 24 | std::uint32_t{b[2]} << 16 | std::uint32_t{b[1]} << 8 | b[0]);
  };
  std::size_t count = 0;
  std::uintmax_t pos = 128;
  while (pos < file_size) {
    unsigned char tag[8];
    in.seekg(static_cast<std::streamoff>(pos));
    if (file_size - pos < 8 || !in.read(reinterpret_cast<char*>(tag), 8))
      throw FormatError("'" + path + "' is truncated: a partial element header at byte " + std::to_string(pos));
    const std::uint32_t type = u32(tag);
    std::uintmax_t bytes = u32(tag + 4);
    if (type != mi_compressed) bytes = (bytes + 7) / 8 * 8;  // uncompressed elements are 8-byte aligned
    if (bytes > file_size - pos - 8)
      throw FormatError("'" + path + "' is truncated: element " + std::to_string(count + 1) + " at byte " + std::to_string(pos) +
                        " declares " + std::to_string(bytes) + " bytes, the file ends " + std::to_string(file_size - pos - 8) +
                        " bytes later");
    // Its matrices, at every depth, before matio allocates by their headers.
    const V5Walker walk{path, swap};
    const std::string which = "element " + std::to_string(count + 1) + " at byte " + std::to_string(pos);
    if (type == mi_compressed) {
      ElementSource src(in, bytes, true);
      unsigned char inner[8];
      if (!src.read(inner, 8) || walk.u32(inner) != mi_matrix) walk.fail(which + " does not inflate to a matrix");
      walk.matrix(src, walk.u32(inner + 4), 0);
      if (!src.finish(8)) walk.fail(which + " is not one whole zlib stream (bad data or checksum)");
    } else if (type == mi_matrix) {
      ElementSource src(in, bytes, false);
      walk.matrix(src, u32(tag + 4), 0);
    }
    pos += 8 + bytes;
    ++count;
  }
  return count;
}

}  // namespace texel::mat::v5
