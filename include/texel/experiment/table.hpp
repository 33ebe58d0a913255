// A small long-format table read from CSV: the exported trial rows (or any
// R / pandas data frame written with write.csv / to_csv) as strings, with
// typed access to a column. Deliberately minimal: the statistics need named
// columns of numbers and labels, not a data-frame library.
//
// Format: RFC 4180 — comma separated, a header row, fields optionally in
// double quotes with "" for a literal quote and commas/newlines allowed
// inside quotes; CRLF or LF line ends; a final line end is optional; a UTF-8
// byte-order mark is skipped. Every row must have as many fields as the
// header (a ragged row is an error naming its line). Input is bounded
// (max_csv_bytes, max_csv_cells) so a stray huge file fails fast.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace texel::experiment {

inline constexpr std::size_t max_csv_bytes = std::size_t{256} << 20;  ///< 256 MiB
inline constexpr std::size_t max_csv_cells = 10'000'000;

struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> cells;  ///< cells[row][column], rows exclude the header
  std::string origin;                           ///< file name or label used in error messages (may be empty)
  std::vector<std::size_t> lines;               ///< 1-based line where each row starts (may be empty)

  /// Index of a column; throws InvalidArgument naming it and the available ones.
  std::size_t column(std::string_view name) const;
  bool has_column(std::string_view name) const;
  /// The column as numbers: empty, "NA", "NaN" (any case) → NaN; anything
  /// else that is not a whole number token throws FormatError naming the line,
  /// the column and the value.
  std::vector<double> numbers(std::string_view column) const;
  /// The column's strings.
  std::vector<std::string> strings(std::string_view column) const;
  std::size_t rows() const { return cells.size(); }
};

/// Parses CSV text; `origin` names the source in error messages.
/// Throws FormatError (unterminated quote, ragged row, no header, a duplicate
/// non-empty column name, too many cells) or InvalidArgument (too large).
/// An empty column name is allowed: R's write.csv and pandas' to_csv write
/// one for the row-name / index column.
Table parse_csv_table(std::string_view text, std::string_view origin);
/// Reads and parses a file; IoError when unreadable, FormatError as above.
Table load_csv_table(const std::string& path);

}  // namespace texel::experiment
