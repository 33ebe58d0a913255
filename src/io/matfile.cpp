// MATLAB .mat files through libmatio (BSD-2, Debian's libmatio-dev): the only
// translation unit that includes <matio.h>. libmatio is opened on first use
// (dlopen, `matio()` below), not linked: it brings HDF5 and through it curl,
// TLS and Kerberos, some thirty libraries whose loading was a third of every
// texel command's start-up whether or not it touched a .mat file. Writing builds matio variables
// from texel::mat values (copies: a map is at most a few hundred MB and the
// copy keeps ownership simple); reading first lists every variable's header
// (class, rank, dimensions; no data), checks the chosen one completely, and
// only then allocates a buffer of the checked size and asks matio to fill it
// (Mat_VarReadData), so a hostile file's declared size never reaches an
// allocation unchecked. Before that, a level-5 file's matrices are walked
// at every depth without matio (matfile_v5.cpp).
#include "texel/matfile.hpp"

#include <matio.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "matfile_v5.hpp"
#include "texel/detail/format.hpp"
#include "texel/detail/shared_object.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel::mat {
namespace fs = std::filesystem;
using detail::num;

namespace {

// --- libmatio, opened on first use ---------------------------------------------

#ifndef TEXEL_MATIO_SONAME
#error "TEXEL_MATIO_SONAME (libmatio's shared object name) is set by src/CMakeLists.txt"
#endif

// clang-format off
#define TEXEL_MATIO_FUNCTIONS(X) \
  X(Mat_Open) \
  X(Mat_Close) \
  X(Mat_CreateVer) \
  X(Mat_GetVersion) \
  X(Mat_LogInitFunc) \
  X(Mat_SizeOfClass) \
  X(Mat_VarCreate) \
  X(Mat_VarCreateStruct2) \
  X(Mat_VarFree) \
  X(Mat_VarRead) \
  X(Mat_VarReadData) \
  X(Mat_VarReadNextInfo) \
  X(Mat_VarSetCell) \
  X(Mat_VarSetStructFieldByName) \
  X(Mat_VarWrite)
// clang-format on

/// libmatio, opened on the first .mat read or write (`matio()`); without it
/// the rest of Texel works and .mat files are an IoError naming the library.
TEXEL_SHARED_LIBRARY(Matio, matio, TEXEL_MATIO_SONAME, "MATLAB .mat files", TEXEL_MATIO_FUNCTIONS)

// matio reports through a process-wide log function (stderr by default).
// Route it into the last message of this thread so errors carry matio's
// reason instead of printing a second line. One writer/reader at a time per
// thread; matio itself is not documented as thread-safe, so calls are
// serialized by `matio_mutex`.
thread_local std::string last_matio_message;
std::mutex matio_mutex;

void matio_log(int level, char* message) {
  if ((level & (MATIO_LOG_LEVEL_ERROR | MATIO_LOG_LEVEL_CRITICAL)) != 0 && message != nullptr) last_matio_message = message;
}

void init_matio_logging() {
  static std::once_flag once;
  std::call_once(once, [] { matio().Mat_LogInitFunc("texel", matio_log); });
}

std::string matio_reason() {
  std::string m = last_matio_message;
  last_matio_message.clear();
  return m.empty() ? std::string() : " (libmatio: " + m + ")";
}

struct VarFree {
  void operator()(matvar_t* v) const { matio().Mat_VarFree(v); }
};
using VarPtr = std::unique_ptr<matvar_t, VarFree>;

struct MatClose {
  void operator()(mat_t* m) const { matio().Mat_Close(m); }
};
using MatPtr = std::unique_ptr<mat_t, MatClose>;

// --- writing ------------------------------------------------------------------

bool valid_identifier(const std::string& s) {
  if (s.empty() || s.size() > 63 || !std::isalpha(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

/// UTF-8 → UTF-16 code units (MATLAB's char). Invalid bytes become U+FFFD.
std::vector<std::uint16_t> utf16(const std::string& s) {
  std::vector<std::uint16_t> out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    std::uint32_t cp = 0xFFFD;
    std::size_t len = 1;
    if (b < 0x80) {
      cp = b;
    } else if ((b >> 5) == 0x6 || (b >> 4) == 0xE || (b >> 3) == 0x1E) {
      len = (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : 4;
      if (i + len <= s.size()) {
        cp = b & (0x7F >> len);
        bool ok = true;
        for (std::size_t k = 1; k < len; ++k) {
          const auto c = static_cast<unsigned char>(s[i + k]);
          ok = ok && (c >> 6) == 0x2;
          cp = (cp << 6) | (c & 0x3F);
        }
        if (!ok || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) cp = 0xFFFD, len = 1;
      } else {
        len = 1;
      }
    }
    i += len;
    if (cp >= 0x10000) {
      cp -= 0x10000;
      out.push_back(static_cast<std::uint16_t>(0xD800 + (cp >> 10)));
      out.push_back(static_cast<std::uint16_t>(0xDC00 + (cp & 0x3FF)));
    } else {
      out.push_back(static_cast<std::uint16_t>(cp));
    }
  }
  return out;
}

/// UTF-16 code units (MATLAB's char) → UTF-8. Unpaired surrogates become U+FFFD.
std::string utf8(const std::vector<std::uint32_t>& units) {
  std::string out;
  out.reserve(units.size());
  for (std::size_t i = 0; i < units.size(); ++i) {
    std::uint32_t cp = units[i];
    if (cp >= 0xD800 && cp <= 0xDBFF && i + 1 < units.size() && units[i + 1] >= 0xDC00 && units[i + 1] <= 0xDFFF)
      cp = 0x10000 + ((cp - 0xD800) << 10) + (units[++i] - 0xDC00);
    else if ((cp >= 0xD800 && cp <= 0xDFFF) || cp > 0x10FFFF)
      cp = 0xFFFD;
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (cp >> 18));
      out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }
  return out;
}

class Builder {
 public:
  explicit Builder(std::string path) : path_(std::move(path)) {}

  VarPtr make(const char* name, const Matrix& m) const {
    if (m.rows * m.cols != m.data.size())
      throw InvalidArgument("'" + path_ + "': variable '" + where(name) + "' is " + std::to_string(m.rows) + "x" +
                            std::to_string(m.cols) + " but holds " + std::to_string(m.data.size()) + " values");
    std::size_t dims[2] = {m.rows, m.cols};
    // matio copies `data` (no MAT_F_DONT_COPY_DATA); the const_cast is its C signature.
    return check(matio().Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                                       m.data.empty() ? nullptr : const_cast<double*>(m.data.data()), 0),
                 name);
  }

  VarPtr make(const char* name, const Text& t) const {
    std::vector<std::uint16_t> units = utf16(t.utf8);
    std::size_t dims[2] = {units.empty() ? 0u : 1u, units.size()};
    return check(matio().Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UINT16, 2, dims, units.empty() ? nullptr : units.data(), 0), name);
  }

  VarPtr make(const char* name, const StringColumn& c) const {
    std::size_t dims[2] = {c.values.size(), 1};
    VarPtr cell = check(matio().Mat_VarCreate(name, MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0), name);
    for (std::size_t i = 0; i < c.values.size(); ++i) {
      VarPtr element = make(static_cast<const char*>(nullptr), Text{c.values[i]});
      matio().Mat_VarSetCell(cell.get(), static_cast<int>(i), element.release());  // the cell owns it now
    }
    return cell;
  }

  VarPtr make(const char* name, const Struct& s) const {
    std::vector<const char*> names;
    for (const auto& entry : s.fields) {  // not a structured binding: clang 14 cannot capture one
      const std::string& field = entry.first;
      if (!valid_identifier(field))
        throw InvalidArgument("'" + path_ + "': struct '" + where(name) + "' has field name '" + field +
                              "'; MATLAB names are a letter, then letters, digits or '_' (at most 63)");
      if (std::count_if(s.fields.begin(), s.fields.end(), [&](const auto& f) { return f.first == field; }) > 1)
        throw InvalidArgument("'" + path_ + "': struct '" + where(name) + "' has field '" + field + "' twice");
      names.push_back(field.c_str());
    }
    std::size_t dims[2] = {1, 1};
    names.push_back(nullptr);  // matio takes a null-terminated list
    VarPtr var = check(matio().Mat_VarCreateStruct2(name, 2, dims, names.data()), name);
    for (const auto& entry : s.fields) {  // not a structured binding: clang 14 cannot capture one
      const char* field = entry.first.c_str();
      VarPtr f = std::visit([&](const auto& v) { return make(field, v); }, entry.second);
      matio().Mat_VarSetStructFieldByName(var.get(), field, 0, f.release());  // the struct owns it now
    }
    return var;
  }

 private:
  static std::string where(const char* name) { return name ? name : "(element)"; }
  VarPtr check(matvar_t* v, const char* name) const {
    if (!v) throw InvalidArgument("'" + path_ + "': cannot build variable '" + where(name) + "'" + matio_reason());
    return VarPtr(v);
  }
  std::string path_;
};

/// Makes a file of the usual permissions durable and renames it into place.
void commit(const std::string& tmp, const std::string& path) {
  const int fd = ::open(tmp.c_str(), O_RDWR);
  if (fd < 0) throw IoError("cannot write '" + path + "': " + std::strerror(errno));
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::fchmod(fd, 0666 & ~mask);
  if (::fsync(fd) != 0 || ::close(fd) != 0) throw IoError("cannot write '" + path + "': " + std::strerror(errno));
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw IoError("cannot write '" + path + "': " + std::strerror(errno));
}

// --- reading ------------------------------------------------------------------

const char* class_name(matio_classes c) {
  switch (c) {
    case MAT_C_CELL: return "cell";
    case MAT_C_STRUCT: return "struct";
    case MAT_C_OBJECT: return "object";
    case MAT_C_CHAR: return "char";
    case MAT_C_SPARSE: return "sparse";
    case MAT_C_DOUBLE: return "double";
    case MAT_C_SINGLE: return "single";
    case MAT_C_INT8: return "int8";
    case MAT_C_UINT8: return "uint8";
    case MAT_C_INT16: return "int16";
    case MAT_C_UINT16: return "uint16";
    case MAT_C_INT32: return "int32";
    case MAT_C_UINT32: return "uint32";
    case MAT_C_INT64: return "int64";
    case MAT_C_UINT64: return "uint64";
    case MAT_C_FUNCTION: return "function";
    case MAT_C_OPAQUE: return "opaque";
    case MAT_C_EMPTY: break;
  }
  return "unknown";
}

bool numeric_class(matio_classes c) {
  switch (c) {
    case MAT_C_DOUBLE:
    case MAT_C_SINGLE:
    case MAT_C_INT8:
    case MAT_C_UINT8:
    case MAT_C_INT16:
    case MAT_C_UINT16:
    case MAT_C_INT32:
    case MAT_C_UINT32:
    case MAT_C_INT64:
    case MAT_C_UINT64: return true;
    default: return false;
  }
}

/// Header of one variable, as listed (no data read).
struct Info {
  VarPtr var;
  std::string name;
  std::string shape;                    ///< "19200x1"
  std::optional<std::size_t> elements;  ///< none when a dimension product overflows
  bool vector = false;                  ///< at most one dimension differs from 1
};

Info describe(matvar_t* v) {
  Info i;
  i.var.reset(v);
  i.name = v->name ? v->name : "";
  std::size_t n = 1;
  bool overflow = false;
  int non_unit = 0;
  const int rank = v->dims ? v->rank : 0;
  for (int k = 0; k < rank; ++k) {
    const std::size_t d = v->dims[k];
    i.shape += (k ? "x" : "") + std::to_string(d);
    if (d != 1) ++non_unit;
    if (d != 0 && n > std::numeric_limits<std::size_t>::max() / d)
      overflow = true;
    else
      n *= d;
  }
  if (rank == 0) i.shape = "0x0", n = 0;
  if (!overflow) i.elements = n;
  i.vector = rank >= 2 && non_unit <= 1;
  return i;
}

class Reader {
 public:
  Reader(std::string path, ReadOptions options) : path_(std::move(path)), options_(options) {
    std::error_code ec;
    if (fs::is_directory(path_, ec)) throw IoError("cannot read '" + path_ + "': it is a directory");
    file_size_ = fs::file_size(path_, ec);
    if (ec) throw IoError("cannot read '" + path_ + "': " + ec.message());
    if (::access(path_.c_str(), R_OK) != 0) throw IoError("cannot read '" + path_ + "': " + std::strerror(errno));
    // A v5/v7.3 file starts with a 128-byte header; matio would also try v4,
    // a format Texel does not exchange.
    if (file_size_ < 128)
      throw FormatError("'" + path_ + "' is not a MATLAB v5/v7.3 .mat file (" + std::to_string(file_size_) + " bytes)");
    // Without the v5/v7.3 marker (version 0x0100 or 0x0200 and "IM"/"MI" at
    // bytes 124-127) Mat_Open falls back to v4 and mallocs a name length read
    // from the file: 1.7 GB for a 972-byte file (fuzz_mat; corpus
    // crash-v4-fallback.mat). Texel does not exchange v4, so it never gets there.
    {
      std::ifstream in(path_, std::ios::binary);
      unsigned char mark[4];
      in.seekg(124);
      if (!in.read(reinterpret_cast<char*>(mark), 4)) throw IoError("cannot read '" + path_ + "'");
      const bool le = mark[2] == 'I' && mark[3] == 'M', be = mark[2] == 'M' && mark[3] == 'I';
      const unsigned version = le ? (mark[1] << 8 | mark[0]) : (mark[0] << 8 | mark[1]);
      if (!(le || be) || (version != 0x0100 && version != 0x0200))
        throw FormatError("'" + path_ + "' is not a MATLAB v5/v7.3 .mat file (no version and byte-order mark at bytes 124-127)");
    }
    mat_.reset(matio().Mat_Open(path_.c_str(), MAT_ACC_RDONLY));
    if (!mat_) throw FormatError("'" + path_ + "' is not a MATLAB .mat file" + matio_reason());
    version_ = matio().Mat_GetVersion(mat_.get());
    if (version_ != MAT_FT_MAT5 && version_ != MAT_FT_MAT73)
      throw FormatError("'" + path_ + "' is a MATLAB v4 file; Texel reads v5 (-v7) and v7.3 .mat files");
    const std::size_t elements = version_ == MAT_FT_MAT5 ? v5_elements() : 0;
    constexpr std::size_t max_variables = 4096;
    while (matvar_t* v = matio().Mat_VarReadNextInfo(mat_.get())) {
      infos_.push_back(describe(v));
      if (infos_.size() > max_variables)
        throw FormatError("'" + path_ + "' holds more than " + std::to_string(max_variables) + " variables");
    }
    // matio stops listing at the first variable it cannot parse; say so
    // rather than pretend the file ends there.
    if (infos_.size() < elements)
      throw FormatError("'" + path_ + "': variable " + std::to_string(infos_.size() + 1) + " of " + std::to_string(elements) +
                        " cannot be read (corrupt, or a class libmatio does not read)" + matio_reason());
  }

  const std::vector<Info>& infos() const { return infos_; }

  const Info* find(const std::string& name) const {
    const Info* found = nullptr;
    for (const auto& i : infos_)
      if (i.name == name) {
        if (found) throw FormatError("'" + path_ + "' holds variable '" + name + "' twice");
        found = &i;
      }
    return found;
  }

  /// The numeric vector `info`, as doubles; throws naming file and variable.
  std::vector<double> vector(const Info& info) {
    const matvar_t* v = info.var.get();
    const std::string what = "'" + path_ + "': variable '" + info.name + "'";
    if (v->class_type == MAT_C_SPARSE) throw FormatError(what + " is sparse; save it full (full(x))");
    if (!numeric_class(v->class_type))
      throw FormatError(what + " is of class " + class_name(v->class_type) + "; a map must be a real numeric vector");
    if (v->isLogical) throw FormatError(what + " is logical; a map must be a real numeric vector");
    if (v->isComplex) throw FormatError(what + " is complex; a map must be real");
    if (!info.elements || *info.elements > options_.max_elements)
      throw FormatError(what + " is " + info.shape + ", more than the " + std::to_string(options_.max_elements) +
                        " elements allowed");
    const std::size_t n = *info.elements;
    if (n == 0) throw FormatError(what + " is empty");
    if (!info.vector) throw FormatError(what + " is " + info.shape + "; a map must be a vector (N×1 or 1×N)");
    // v5 data lives in the file: stored uncompressed it needs at least one
    // byte per element (MATLAB may store doubles as uint8), compressed at
    // most deflate's ~1032:1 ratio. A declared size beyond that is a lie.
    if (version_ == MAT_FT_MAT5) {
      const std::size_t ratio = v->compression == MAT_COMPRESSION_NONE ? 1 : 1100;
      if (n / ratio > file_size_)
        throw FormatError(what + " declares " + info.shape + " elements but the file has only " + std::to_string(file_size_) +
                          " bytes");
    }
    const std::size_t width = matio().Mat_SizeOfClass(v->class_type);
    if (width == 0 || width > 8) throw FormatError(what + " has an unsupported element type");
    std::vector<unsigned char> raw(n * width);
    std::vector<int> start(static_cast<std::size_t>(v->rank), 0), stride(start.size(), 1), edge(start.size());
    for (std::size_t k = 0; k < edge.size(); ++k) edge[k] = static_cast<int>(v->dims[k]);
    if (matio().Mat_VarReadData(mat_.get(), const_cast<matvar_t*>(v), raw.data(), start.data(), stride.data(), edge.data()) != 0)
      throw FormatError(what + " cannot be read (truncated or corrupt file)" + matio_reason());
    std::vector<double> out(n);
    auto convert = [&]<typename T>(T) {
      for (std::size_t i = 0; i < n; ++i) {
        T x;
        std::memcpy(&x, raw.data() + i * sizeof(T), sizeof(T));
        out[i] = static_cast<double>(x);
      }
    };
    switch (v->class_type) {
      case MAT_C_DOUBLE: convert(double{}); break;
      case MAT_C_SINGLE: convert(float{}); break;
      case MAT_C_INT8: convert(std::int8_t{}); break;
      case MAT_C_UINT8: convert(std::uint8_t{}); break;
      case MAT_C_INT16: convert(std::int16_t{}); break;
      case MAT_C_UINT16: convert(std::uint16_t{}); break;
      case MAT_C_INT32: convert(std::int32_t{}); break;
      case MAT_C_UINT32: convert(std::uint32_t{}); break;
      case MAT_C_INT64: convert(std::int64_t{}); break;
      case MAT_C_UINT64: convert(std::uint64_t{}); break;
      default: throw FormatError(what + " has an unsupported class");
    }
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isfinite(out[i])) throw FormatError(what + " holds a non-finite value at element " + std::to_string(i + 1));
    return out;
  }

  /// The char row `info` as UTF-8; throws naming file and variable.
  std::string text(const Info& info) {
    const matvar_t* v = info.var.get();
    const std::string what = "'" + path_ + "': variable '" + info.name + "'";
    if (v->class_type != MAT_C_CHAR) throw FormatError(what + " is of class " + class_name(v->class_type) + ", not char");
    if (!info.elements || *info.elements > options_.max_elements)
      throw FormatError(what + " is " + info.shape + ", more than the " + std::to_string(options_.max_elements) +
                        " characters allowed");
    if (*info.elements == 0) return {};
    if (!info.vector) throw FormatError(what + " is " + info.shape + "; text must be a char row");
    // The header was checked (and, in a v5 file, every element's size against
    // the file's) before matio reads the data.
    VarPtr full(matio().Mat_VarRead(mat_.get(), info.name.c_str()));
    if (!full || !full->data) throw FormatError(what + " cannot be read (truncated or corrupt file)" + matio_reason());
    const std::size_t width = full->data_size > 0 ? static_cast<std::size_t>(full->data_size) : 2;
    const std::size_t n = std::min(*info.elements, full->nbytes / width);
    std::vector<std::uint32_t> units(n);
    const auto* bytes = static_cast<const unsigned char*>(full->data);
    for (std::size_t i = 0; i < n; ++i) {
      if (width == 1) {
        units[i] = bytes[i];
      } else if (width == 2) {
        std::uint16_t u;
        std::memcpy(&u, bytes + 2 * i, 2);
        units[i] = u;
      } else if (width == 4) {
        std::uint32_t u;
        std::memcpy(&u, bytes + 4 * i, 4);
        units[i] = u;
      } else {
        throw FormatError(what + " has an unsupported character width (" + std::to_string(width) + " bytes)");
      }
    }
    // 8-bit text (MAT_T_UTF8, or Latin-1 from old writers) is taken as UTF-8 bytes.
    if (width == 1) return std::string(reinterpret_cast<const char*>(bytes), n);
    return utf8(units);
  }

  const std::string& path() const { return path_; }

 private:
  /// The v5 pre-check (matfile_v5.cpp) of this file.
  std::size_t v5_elements() const { return v5::check_v5_elements(path_, file_size_); }

  std::string path_;
  ReadOptions options_;
  std::uintmax_t file_size_ = 0;
  MatPtr mat_;
  mat_ft version_ = MAT_FT_MAT5;
  std::vector<Info> infos_;
};

bool candidate_map(const Info& i) {
  const matvar_t* v = i.var.get();
  return numeric_class(v->class_type) && !v->isComplex && !v->isLogical && i.vector && i.elements && *i.elements > 1 &&
         i.name != "position_mm" && i.name != "spacing_mm";
}

}  // namespace

MatVersion parse_mat_version(const std::string& text) {
  if (text == "5" || text == "v5" || text == "7" || text == "v7") return MatVersion::v5;
  if (text == "7.3" || text == "v7.3" || text == "73") return MatVersion::v73;
  throw InvalidArgument("MAT-file version '" + text + "' is not one of 5, 7 (both: v5 with compression) or 7.3 (HDF5)");
}

Matrix Matrix::column(std::vector<double> values) {
  Matrix m;
  m.rows = values.size();
  m.cols = 1;
  m.data = std::move(values);
  return m;
}

Matrix Matrix::scalar(double v) { return Matrix{1, 1, {v}}; }

void write_mat(const std::string& path, const std::vector<Variable>& variables, const WriteOptions& options) {
  for (std::size_t i = 0; i < variables.size(); ++i) {
    const std::string& name = variables[i].name;
    if (!valid_identifier(name))
      throw InvalidArgument("'" + path + "': variable name '" + name +
                            "' is not a MATLAB name (a letter, then letters, digits or '_', at most 63)");
    for (std::size_t k = 0; k < i; ++k)
      if (variables[k].name == name) throw InvalidArgument("'" + path + "': variable '" + name + "' is given twice");
  }
  check_writable(path);
  const std::lock_guard lock(matio_mutex);
  init_matio_logging();
  last_matio_message.clear();

  const fs::path p(path);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::string tmp = (dir / ("." + p.filename().string() + ".tmp-XXXXXX")).string();
  const int fd = ::mkstemp(tmp.data());
  if (fd < 0) throw IoError("cannot write '" + path + "': " + std::strerror(errno));
  ::close(fd);
  try {
    // A fixed header (matio's default holds the platform and the time), so
    // the same map gives the same v5 bytes.
    const bool v73 = options.version == MatVersion::v73;
    MatPtr mat(matio().Mat_CreateVer(tmp.c_str(),
                                     v73 ? "MATLAB 7.3 MAT-file, written by Texel" : "MATLAB 5.0 MAT-file, written by Texel",
                                     v73 ? MAT_FT_MAT73 : MAT_FT_MAT5));
    if (!mat) throw IoError("cannot write '" + path + "': libmatio cannot create the file" + matio_reason());
    const Builder builder(path);
    const matio_compression compression = options.compress ? MAT_COMPRESSION_ZLIB : MAT_COMPRESSION_NONE;
    for (const Variable& var : variables) {
      VarPtr v = std::visit([&](const auto& value) { return builder.make(var.name.c_str(), value); }, var.value);
      if (matio().Mat_VarWrite(mat.get(), v.get(), compression) != 0)
        throw IoError("cannot write '" + path + "': libmatio failed on variable '" + var.name + "'" + matio_reason());
    }
    if (matio().Mat_Close(mat.release()) != 0)
      throw IoError("cannot write '" + path + "': libmatio cannot close the file" + matio_reason());
    commit(tmp, path);
  } catch (...) {
    ::unlink(tmp.c_str());
    throw;
  }
}

MapData read_map(const std::string& path, const ReadOptions& options) {
  const std::lock_guard lock(matio_mutex);
  init_matio_logging();
  last_matio_message.clear();
  Reader r(path, options);

  const Info* map = r.find("amplitude");
  if (!map) map = r.find("map");
  if (!map) {
    std::vector<const Info*> candidates;
    for (const auto& i : r.infos())
      if (candidate_map(i)) candidates.push_back(&i);
    if (candidates.size() != 1) {
      std::string names;
      for (const auto* c : candidates) names += (names.empty() ? "" : ", ") + c->name;
      throw FormatError("'" + path + "' has no variable 'amplitude' or 'map' and " +
                        (candidates.empty() ? std::string("no real numeric vector")
                                            : std::to_string(candidates.size()) + " real numeric vectors (" + names + ")") +
                        "; name the map 'amplitude'");
    }
    map = candidates.front();
  }
  MapData out;
  out.variable = map->name;
  out.amplitude = r.vector(*map);
  const std::size_t n = out.amplitude.size();

  if (const Info* pos = r.find("position_mm")) {
    out.position_mm = r.vector(*pos);
    const std::string what = "'" + path + "': variable 'position_mm'";
    if (out.position_mm.size() != n)
      throw FormatError(what + " has " + std::to_string(out.position_mm.size()) + " elements, '" + map->name + "' has " +
                        std::to_string(n));
    if (n < 2) throw FormatError(what + " needs at least 2 positions");
    const double step = (out.position_mm.back() - out.position_mm.front()) / static_cast<double>(n - 1);
    if (!(step > 0.0 && std::isfinite(step))) throw FormatError(what + " must increase");
    for (std::size_t i = 1; i < n; ++i)
      if (std::fabs(out.position_mm[i] - out.position_mm[i - 1] - step) > 0.01 * step)
        throw FormatError(what + " is not uniformly sampled at element " + std::to_string(i + 1) + " (step " +
                          num(out.position_mm[i] - out.position_mm[i - 1]) + " mm, expected " + num(step) + " mm)");
    out.spacing_mm = step;
  }
  if (const Info* sp = r.find("spacing_mm")) {
    const std::string what = "'" + path + "': variable 'spacing_mm'";
    if (sp->elements != std::size_t{1}) throw FormatError(what + " is " + sp->shape + "; it must be a scalar (mm)");
    const std::vector<double> v = r.vector(*sp);
    if (!(v[0] > 0.0)) throw FormatError(what + " is " + num(v[0]) + "; it must be > 0 mm");
    if (out.spacing_mm && std::fabs(*out.spacing_mm - v[0]) > 0.01 * v[0])
      throw FormatError(what + " is " + num(v[0]) + " mm but 'position_mm' steps by " + num(*out.spacing_mm) + " mm");
    out.spacing_mm = v[0];
  }
  return out;
}

std::optional<std::string> read_text(const std::string& path, const std::string& name, const ReadOptions& options) {
  const std::lock_guard lock(matio_mutex);
  init_matio_logging();
  last_matio_message.clear();
  Reader r(path, options);
  const Info* info = r.find(name);
  if (!info) return std::nullopt;
  return r.text(*info);
}

std::vector<std::string> list_variables(const std::string& path) {
  const std::lock_guard lock(matio_mutex);
  init_matio_logging();
  last_matio_message.clear();
  Reader r(path, ReadOptions{});
  std::vector<std::string> out;
  for (const auto& i : r.infos()) {
    const matvar_t* v = i.var.get();
    std::string cls = class_name(v->class_type);
    if (v->isLogical) cls = "logical";
    if (v->isComplex) cls += " complex";
    out.push_back(i.name + " " + cls + " " + i.shape);
  }
  return out;
}

}  // namespace texel::mat
