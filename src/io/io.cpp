#include "texel/io.hpp"

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel {
namespace fs = std::filesystem;

std::string read_file(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw IoError("cannot read '" + path + "': it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot read '" + path + "': " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw IoError("error while reading '" + path + "'");
  return ss.str();
}

void check_writable(const std::string& path) {
  if (path.empty()) throw IoError("output path is empty");
  const fs::path p(path);
  std::error_code ec;
  if (fs::is_directory(p, ec)) throw IoError("cannot write '" + path + "': it is a directory");
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) throw IoError("cannot write '" + path + "': directory '" + dir.string() + "' does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw IoError("cannot write '" + path + "': directory '" + dir.string() + "' is not writable");
}

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  check_writable(path_);
  const fs::path p(path_);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  tmp_ = (dir / ("." + p.filename().string() + ".tmp-XXXXXX")).string();
  fd_ = ::mkstemp(tmp_.data());
  if (fd_ < 0) throw IoError("cannot write '" + path_ + "': " + std::strerror(errno));
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!tmp_.empty()) ::unlink(tmp_.c_str());
}

void AtomicFile::fail(const std::string& why) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  ::unlink(tmp_.c_str());
  tmp_.clear();
  throw IoError("cannot write '" + path_ + "': " + why);
}

void AtomicFile::write(std::string_view data) {
  if (fd_ < 0) throw IoError("cannot write '" + path_ + "': the file is already committed or failed");
  const char* ptr = data.data();
  std::size_t left = data.size();
  while (left > 0) {
    const ssize_t w = ::write(fd_, ptr, left);
    if (w < 0) {
      if (errno == EINTR) continue;
      fail(std::strerror(errno));
    }
    ptr += w;
    left -= static_cast<std::size_t>(w);
  }
  written_ += data.size();
#if defined(__linux__)
  // Start writing back what has piled up, so commit()'s fsync finds most of
  // the file already on its way to the disk instead of all of it. Only a
  // hint: its result is ignored, and fsync still decides.
  if (written_ - kicked_ >= writeback_step) {
    (void)::sync_file_range(fd_, static_cast<off_t>(kicked_), static_cast<off_t>(written_ - kicked_), SYNC_FILE_RANGE_WRITE);
    kicked_ = written_;
  }
#endif
}

void AtomicFile::write(std::span<const std::byte> data) {
  write(std::string_view(reinterpret_cast<const char*>(data.data()), data.size()));
}

void AtomicFile::commit() {
  if (fd_ < 0) throw IoError("cannot write '" + path_ + "': the file is already committed or failed");
  // mkstemp creates 0600; give the file the usual permissions (umask applies).
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::fchmod(fd_, 0666 & ~mask);
  const int synced = ::fsync(fd_);
  const int closed = ::close(fd_);
  fd_ = -1;
  if (synced != 0 || closed != 0) fail(std::strerror(errno));
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0) fail(std::strerror(errno));
  tmp_.clear();
}

void write_file_atomic(const std::string& path, std::string_view data) {
  AtomicFile f(path);
  f.write(data);
  f.commit();
}

void write_file_atomic(const std::string& path, std::span<const std::byte> data) {
  write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(data.data()), data.size()));
}

std::string output_extension(const std::string& path) {
  std::string name = fs::path(path).filename().string();
  for (auto& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const char* compound : {".texel.json"})
    if (name.size() > std::strlen(compound) && name.ends_with(compound)) return compound;
  const auto dot = name.rfind('.');
  return dot == std::string::npos || dot == 0 ? std::string() : name.substr(dot);
}

std::string npy_bytes(std::span<const double> values) {
  std::string out = npy_header(values.size());
  out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
  return out;
}

std::string npy_header(std::size_t count) { return npy_header_for_shape(std::to_string(count) + ","); }

std::string npy_header(std::size_t rows, std::size_t columns) {
  return npy_header_for_shape(std::to_string(rows) + ", " + std::to_string(columns));
}

std::string npy_header_for_shape(const std::string& shape) {
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" + shape + "), }";
  // Magic (6) + version (2) + header length (2) + header, padded with spaces
  // and a final newline to a multiple of 64 bytes (NEP 1).
  const std::size_t unpadded = 10 + header.size() + 1;
  header.append((64 - unpadded % 64) % 64, ' ');
  header.push_back('\n');
  std::string out("\x93NUMPY\x01\x00", 8);
  out.push_back(static_cast<char>(header.size() & 0xFF));
  out.push_back(static_cast<char>((header.size() >> 8) & 0xFF));
  out += header;
  return out;
}

std::vector<double> parse_npy(std::string_view b, std::string_view origin) { return parse_npy_array(b, origin, 1).values; }

NpyArray parse_npy_array(std::string_view b, std::string_view origin, int dimensions) {
  const std::string where(origin);
  if (b.size() < 10 || b.substr(0, 6) != std::string_view("\x93NUMPY", 6))
    throw FormatError(where + ": not a .npy file (bad magic)");
  const auto major = static_cast<unsigned char>(b[6]);
  std::size_t header_len = 0;
  std::size_t offset = 0;
  if (major == 1) {
    header_len = static_cast<unsigned char>(b[8]) | (static_cast<std::size_t>(static_cast<unsigned char>(b[9])) << 8);
    offset = 10;
  } else if (major == 2 || major == 3) {
    if (b.size() < 12) throw FormatError(where + ": truncated .npy header");
    header_len = 0;
    for (int i = 0; i < 4; ++i) header_len |= static_cast<std::size_t>(static_cast<unsigned char>(b[8 + i])) << (8 * i);
    offset = 12;
  } else {
    throw FormatError(where + ": unsupported .npy version " + std::to_string(major));
  }
  if (b.size() < offset + header_len) throw FormatError(where + ": truncated .npy header");
  const std::string header(b.substr(offset, header_len));
  const std::size_t data_at = offset + header_len;
  auto value_of = [&](const std::string& key) -> std::string {
    const auto k = header.find("'" + key + "'");
    if (k == std::string::npos) throw FormatError(where + ": .npy header lacks '" + key + "'");
    auto v = header.find(':', k);
    if (v == std::string::npos) throw FormatError(where + ": malformed .npy header");
    ++v;
    while (v < header.size() && header[v] == ' ') ++v;
    if (header[v] == '(') return header.substr(v, header.find(')', v) - v + 1);
    const auto end = header.find_first_of(",}", v);
    return header.substr(v, end - v);
  };
  std::string descr = value_of("descr");
  std::erase(descr, '\'');
  std::erase(descr, ' ');
  // A 1-D or (n,1) array reads the same either way; a 2-D one is transposed.
  const bool fortran = value_of("fortran_order").find("True") != std::string::npos;
  const std::string shape = value_of("shape");
  // The shape is outside input: every dimension is checked against the data
  // the file actually holds before any size arithmetic, so a declared
  // (2**62,) or a product that overflows size_t is a FormatError, never a
  // wrapped count or an allocation sized by the header alone.
  const std::size_t data_bytes = b.size() - data_at;
  std::vector<std::size_t> dims;
  for (std::size_t i = 0; i < shape.size();) {
    if (std::isdigit(static_cast<unsigned char>(shape[i]))) {
      std::size_t v = 0;
      auto r = std::from_chars(shape.data() + i, shape.data() + shape.size(), v);
      if (r.ec != std::errc() || v > data_bytes)
        throw FormatError(where + ": .npy shape " + shape + " declares a dimension of " + std::string(shape.data() + i, r.ptr) +
                          " elements; the file holds only " + std::to_string(data_bytes) + " data bytes");
      dims.push_back(v);
      i = static_cast<std::size_t>(r.ptr - shape.data());
    } else {
      ++i;
    }
  }
  int non_unit = 0;
  std::size_t n = 1;
  for (auto d : dims) {
    if (d == 1) continue;
    ++non_unit;
    // Each factor is at most data_bytes, and so is the running product
    // (checked before multiplying): no overflow.
    if (non_unit > 1 && d != 0 && n > data_bytes / d)
      throw FormatError(where + ": .npy shape " + shape + " holds more elements than the file's " + std::to_string(data_bytes) +
                        " data bytes");
    n = non_unit > 1 ? n * d : d;
  }
  NpyArray array;
  if (dimensions == 1) {
    if (dims.empty() || non_unit > 1) throw FormatError(where + ": .npy array of shape " + shape + " is not one-dimensional");
    array.rows = n;
  } else {
    if (dims.size() != 2 || dims[0] == 0 || dims[1] == 0 || dims[0] > data_bytes / dims[1])
      throw FormatError(where + ": .npy array of shape " + shape + " is not a non-empty two-dimensional array");
    array.rows = dims[0];
    array.columns = dims[1];
    n = dims[0] * dims[1];
  }
  std::size_t width = 0;
  if (descr == "<f8")
    width = 8;
  else if (descr == "<f4")
    width = 4;
  else if (descr == "<u2" || descr == "<i2")
    width = 2;
  else if (descr == "|u1" || descr == "<u1")
    width = 1;
  else
    throw FormatError(where + ": .npy dtype '" + descr + "' is not supported (use float64, float32, int16, uint16 or uint8)");
  if (b.size() - data_at != n * width)
    throw FormatError(where + ": .npy data holds " + std::to_string(b.size() - data_at) + " bytes, shape needs " +
                      std::to_string(n * width));
  std::vector<double>& out = array.values;
  out.resize(n);
  const char* p = b.data() + data_at;
  for (std::size_t k = 0; k < n; ++k, p += width) {
    // Fortran order stores columns first: element k is (k % rows, k / rows).
    const std::size_t i = fortran && dimensions == 2 ? (k % array.rows) * array.columns + k / array.rows : k;
    if (descr == "<f8")
      std::memcpy(&out[i], p, 8);
    else if (descr == "<f4") {
      float f;
      std::memcpy(&f, p, 4);
      out[i] = f;
    } else if (descr == "<u2") {
      std::uint16_t u;
      std::memcpy(&u, p, 2);
      out[i] = u / 65535.0;
    } else if (descr == "<i2") {
      std::int16_t s;
      std::memcpy(&s, p, 2);
      out[i] = s / 32768.0;
    } else
      out[i] = static_cast<unsigned char>(*p) / 255.0;
  }
  return array;
}

std::string csv_columns(std::string_view ha, std::string_view hb, std::span<const double> a, std::span<const double> b) {
  std::string out;
  out.reserve(a.size() * 28 + 32);
  out.append(ha).append(",").append(hb).append("\n");
  char buf[64];
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    auto r = std::to_chars(buf, buf + sizeof buf, a[i]);
    out.append(buf, r.ptr);
    out.push_back(',');
    r = std::to_chars(buf, buf + sizeof buf, b[i]);
    out.append(buf, r.ptr);
    out.push_back('\n');
  }
  return out;
}

bool parse_csv_number(std::string_view s, double& v) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  if (s.size() > 1 && s.front() == '+' && s[1] != '-') s.remove_prefix(1);  // from_chars rejects a leading '+'
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

std::string read_numeric_csv(std::string_view text, std::string_view origin, std::size_t min_columns, std::size_t max_columns,
                             std::string_view expected,
                             const std::function<void(std::size_t line, std::span<const double> values)>& row) {
  constexpr std::size_t most = 16;
  if (max_columns > most || min_columns < 1 || min_columns > max_columns)
    throw InvalidArgument("read_numeric_csv: columns must satisfy 1 <= min <= max <= 16");
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte-order mark (Excel)
  const auto at = [&](std::size_t line) { return std::string(origin) + ":" + std::to_string(line) + ": "; };
  std::string header;
  double values[most];
  std::size_t line_no = 0;
  while (!text.empty()) {
    const auto nl = text.find('\n');
    std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.find_first_not_of(" \t") == std::string_view::npos || line.front() == '#') continue;
    std::size_t n = 0;
    bool numeric = true;
    for (std::size_t pos = 0;;) {
      const auto sep = line.find_first_of(",;\t", pos);
      const auto field = line.substr(pos, sep == std::string_view::npos ? std::string_view::npos : sep - pos);
      if (n == max_columns)
        throw FormatError(at(line_no) + "more than " + std::to_string(max_columns) + " columns; expected " +
                          std::string(expected));
      if (!parse_csv_number(field, values[n])) numeric = false;
      ++n;
      if (sep == std::string_view::npos) break;
      pos = sep + 1;
    }
    if (!numeric) {
      if (line_no == 1) {
        header = std::string(line);
        continue;
      }
      throw FormatError(at(line_no) + "'" + std::string(line) + "' is not numeric; expected " + std::string(expected));
    }
    if (n < min_columns)
      throw FormatError(at(line_no) + std::to_string(n) + " column" + (n == 1 ? "" : "s") + "; expected " +
                        std::string(expected));
    row(line_no, std::span<const double>(values, n));
  }
  return header;
}

std::pair<std::vector<double>, std::vector<double>> parse_csv_columns(std::string_view text, std::string_view origin) {
  std::vector<double> a;
  std::vector<double> b;
  read_numeric_csv(text, origin, 2, 2, "two columns of numbers", [&](std::size_t, std::span<const double> v) {
    a.push_back(v[0]);
    b.push_back(v[1]);
  });
  if (a.empty()) throw FormatError(std::string(origin) + ": no numeric rows");
  return {std::move(a), std::move(b)};
}

}  // namespace texel
