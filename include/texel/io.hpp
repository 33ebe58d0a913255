// File I/O shared by every front door: atomic writes (never a half-written
// output), whole-file reads, and the array formats Texel exchanges (.npy,
// .csv). Errors are IoError / FormatError naming the path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace texel {

/// The bytes of a text or file buffer, as the byte spans the parsers take.
inline std::span<const std::byte> byte_view(std::string_view s) { return std::as_bytes(std::span(s.data(), s.size())); }

/// Reads a whole file; throws IoError naming the path.
std::string read_file(const std::string& path);
/// Writes `data` to a temporary file beside `path`, then renames it over
/// `path`: readers see the old file or the new one, never a partial one.
void write_file_atomic(const std::string& path, std::string_view data);
void write_file_atomic(const std::string& path, std::span<const std::byte> data);
/// A file written in pieces that appears atomically: the pieces go to a
/// temporary file beside `path` (mkstemp), and commit() flushes it to disk
/// and renames it over `path`. Destroyed without commit() — an exception on
/// the way — it removes the temporary, so a failed command leaves nothing.
/// Streaming writers (write_map) use it to keep memory bounded whatever the
/// length; write_file_atomic is one write and a commit.
class AtomicFile {
 public:
  explicit AtomicFile(std::string path);  ///< throws IoError naming the path
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  void write(std::string_view data);
  void write(std::span<const std::byte> data);
  void commit();
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  [[noreturn]] void fail(const std::string& why);
  std::string path_;
  std::string tmp_;
  int fd_ = -1;
  std::uint64_t written_ = 0;  // bytes written so far
  std::uint64_t kicked_ = 0;   // bytes whose write-back has been started
  static constexpr std::uint64_t writeback_step = std::uint64_t{8} << 20;
};

/// Throws IoError if `path`'s directory does not exist or is not writable,
/// so a command can fail before doing any work.
void check_writable(const std::string& path);

/// Lower-case extension including compound ones: "a.texel.json" -> ".texel.json".
std::string output_extension(const std::string& path);

/// NumPy .npy (format 1.0, little-endian float64, 1-D).
std::string npy_bytes(std::span<const double> values);
/// The header of that file for `count` values (the data follows it).
std::string npy_header(std::size_t count);
/// The header of a float64 (rows, columns) C-order array.
std::string npy_header(std::size_t rows, std::size_t columns);
/// The header for a shape written out ("12," or "3, 4").
std::string npy_header_for_shape(const std::string& shape);
/// Reads a 1-D or single-column .npy of float64/float32/int16/uint16 (little-endian).
std::vector<double> parse_npy(std::string_view bytes, std::string_view origin);
/// A .npy array of the same dtypes with its shape: `dimensions` 1 (as
/// parse_npy: rows = the length, columns = 1) or 2 (rows × columns,
/// row-major values whatever the file's order).
struct NpyArray {
  std::size_t rows = 0, columns = 1;
  std::vector<double> values;
};
NpyArray parse_npy_array(std::string_view bytes, std::string_view origin, int dimensions);

/// Two-column CSV with a header: "position_mm,amplitude" and one row per sample.
std::string csv_columns(std::string_view header_a, std::string_view header_b, std::span<const double> a,
                        std::span<const double> b);
/// Reads a two-column numeric CSV (optional header), returning the columns.
std::pair<std::vector<double>, std::vector<double>> parse_csv_columns(std::string_view text, std::string_view origin);

/// One number of a CSV field: spaces and tabs around it are ignored, a
/// leading '+' is allowed, the rest must be a whole decimal number (or
/// nan/inf, which callers reject where they mean nothing).
bool parse_csv_number(std::string_view field, double& out);

/// The one reader of the numeric CSV files (signals, finger traces, coarse
/// profiles; the trial tables of experiments are RFC 4180 tables with named
/// columns, a different format: experiment/table.hpp). Fields are separated
/// by ',', ';' or a tab; CR LF line ends, blank lines and lines starting with
/// '#' are allowed; a first line that is not numeric is the header. Calls
/// `row(line, values)` for each row (line is 1-based) and returns the header
/// ("" when there is none). Throws FormatError "origin:line: ..." for a
/// non-numeric field or a row with fewer than `min_columns` or more than
/// `max_columns` (at most 16) fields, `expected` naming the columns
/// ("time_s,position_mm[,touch]"). An empty file is not an error here.
std::string read_numeric_csv(std::string_view text, std::string_view origin, std::size_t min_columns, std::size_t max_columns,
                             std::string_view expected,
                             const std::function<void(std::size_t line, std::span<const double> values)>& row);

}  // namespace texel
