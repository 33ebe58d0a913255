// MATLAB .mat interchange (library texel_mat, over libmatio; docs/format.md
// "MATLAB .mat"). Writing: named variables — real double matrices, char
// strings, cell columns of strings and scalar structs of those — to a v5
// file (MATLAB's default `save`, zlib-compressed elements) or a v7.3 file
// (HDF5) on request, atomically (temporary + rename, like io.hpp). Reading:
// the map an encoder takes, with its optional positions or spacing.
//
// MATLAB is column-major: a `Matrix` holds its values column by column, a
// map is an N×1 column and a table of N rows and k columns is N·k values,
// first column first. Trade-off: only the classes Texel exchanges are
// supported (double in, double/single/integer out of files; no sparse,
// complex, logical, cell or struct maps), so every file the reader accepts
// means exactly one thing. libmatio stays a private dependency: this header
// does not include <matio.h>.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace texel::mat {

/// v5 (MATLAB 7 "-v7": compressed level-5 elements; every MATLAB, Octave,
/// scipy.io.loadmat) or v7.3 (HDF5; MATLAB ≥ 7.3, h5py; needed for
/// variables over 2 GiB).
enum class MatVersion { v5, v73 };

/// Parses "5", "7" (also v5 / v7) → v5 and "7.3" / "v7.3" → v73; throws
/// InvalidArgument naming the value and the allowed ones.
MatVersion parse_mat_version(const std::string& text);

/// A real double matrix, column-major: element (r, c) is data[c·rows + r].
struct Matrix {
  std::size_t rows = 0;
  std::size_t cols = 0;
  std::vector<double> data;

  /// An N×1 column.
  static Matrix column(std::vector<double> values);
  /// A 1×1 scalar.
  static Matrix scalar(double v);
};

/// An N×1 cell array of char rows (MATLAB's column of strings).
struct StringColumn {
  std::vector<std::string> values;  ///< UTF-8
};

/// A char row (1×n, stored as UTF-16 code units the way MATLAB stores char).
struct Text {
  std::string utf8;
};

using FieldValue = std::variant<Matrix, Text, StringColumn>;

/// A 1×1 struct; field names follow MATLAB's rules (a letter, then letters,
/// digits or '_', at most 63 characters) and must be unique.
struct Struct {
  std::vector<std::pair<std::string, FieldValue>> fields;

  Struct& add(std::string name, FieldValue value) {
    fields.emplace_back(std::move(name), std::move(value));
    return *this;
  }
};

using Value = std::variant<Matrix, Text, StringColumn, Struct>;

struct Variable {
  std::string name;  ///< MATLAB identifier (same rules as field names)
  Value value;
};

struct WriteOptions {
  MatVersion version = MatVersion::v5;
  bool compress = true;  ///< zlib (v5: compressed elements; v7.3: HDF5 deflate)
};

/// Writes `variables` to `path` atomically: a temporary beside `path`,
/// renamed over it once libmatio has closed it, so readers never see a
/// partial file. Throws InvalidArgument (bad names, shapes), IoError (the
/// file system) naming the path and the variable.
void write_mat(const std::string& path, const std::vector<Variable>& variables, const WriteOptions& options = {});

// --- reading ------------------------------------------------------------------

struct ReadOptions {
  /// Largest accepted variable, in elements; checked before anything is
  /// allocated (and, for uncompressed v5 data, against the file's size).
  std::size_t max_elements = std::size_t{1} << 27;
};

/// A map read from a .mat file.
struct MapData {
  std::string variable;              ///< the variable the amplitudes came from
  std::vector<double> amplitude;     ///< as stored (integers as their values)
  std::optional<double> spacing_mm;  ///< from `spacing_mm`, else from `position_mm`
  std::vector<double> position_mm;   ///< empty when the file has none
};

/// Reads the map of a .mat file (v5 or v7.3). The map is the variable named
/// `amplitude`, else `map`, else the only real numeric vector in the file.
/// `position_mm` (same length, increasing, uniform within 1 % of a step) and
/// `spacing_mm` (a positive scalar) are optional; when both are present they
/// must agree within 1 %. Throws FormatError naming the file and variable
/// for anything else (complex, sparse, cell, struct, char, logical data;
/// arrays that are not vectors; sizes over options.max_elements; non-finite
/// values), IoError when the file cannot be opened.
MapData read_map(const std::string& path, const ReadOptions& options = {});

/// The char row named `name` in a .mat file (v5 or v7.3) as UTF-8, or
/// nothing when the file has no such variable (e.g. the `document` a map
/// Texel wrote carries). Throws FormatError naming the file and variable when
/// it is not a char row (or is over options.max_elements characters), IoError
/// when the file cannot be opened.
std::optional<std::string> read_text(const std::string& path, const std::string& name, const ReadOptions& options = {});

/// The names, classes and sizes in a .mat file, e.g. "amplitude double
/// 19200x1", one entry per variable (for diagnostics and tests).
std::vector<std::string> list_variables(const std::string& path);

}  // namespace texel::mat
