// RFC 4180 CSV reader for long-format tables (include/texel/experiment/table.hpp).
// A single pass over the bytes with a two-state machine (in quotes or not);
// line numbers are counted as we go so every error can point at the line.
#include "texel/experiment/table.hpp"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel::experiment {
namespace {

std::string quoted_list(const std::vector<std::string>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) s += ", ";
    s += "'" + v[i] + "'";
  }
  return s;
}

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  return true;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

}  // namespace

bool Table::has_column(std::string_view name) const {
  for (const auto& c : columns)
    if (c == name) return true;
  return false;
}

std::size_t Table::column(std::string_view name) const {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return i;
  throw InvalidArgument("column '" + std::string(name) + "' is not in " + (origin.empty() ? "the table" : origin) +
                        "; available columns: " + quoted_list(columns));
}

std::vector<std::string> Table::strings(std::string_view name) const {
  const std::size_t c = column(name);
  std::vector<std::string> r;
  r.reserve(cells.size());
  for (const auto& row : cells) r.push_back(row[c]);
  return r;
}

std::vector<double> Table::numbers(std::string_view name) const {
  const std::size_t c = column(name);
  std::vector<double> r;
  r.reserve(cells.size());
  for (std::size_t i = 0; i < cells.size(); ++i) {
    std::string_view s = trim(cells[i][c]);
    if (s.empty() || iequals(s, "NA") || iequals(s, "NaN")) {
      r.push_back(std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    double v = 0;
    if (!parse_csv_number(s, v))  // the numeric CSV files' number rule (texel/io.hpp)
      throw FormatError((origin.empty() ? std::string("table") : origin) + ":" +
                        std::to_string(i < lines.size() ? lines[i] : i + 2) + ": column '" + std::string(name) + "' has '" +
                        cells[i][c] + "', which is not a number (empty, NA or NaN mark a missing value)");
    r.push_back(v);
  }
  return r;
}

Table parse_csv_table(std::string_view text, std::string_view origin) {
  const std::string where = std::string(origin);
  if (text.size() > max_csv_bytes)
    throw InvalidArgument(where + ": " + std::to_string(text.size()) + " bytes is larger than the " +
                          std::to_string(max_csv_bytes >> 20) + " MiB a CSV table may have");
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte-order mark (Excel)

  Table t;
  t.origin = where;
  std::vector<std::vector<std::string>> rows;
  std::vector<std::size_t> row_lines;
  std::vector<std::string> row;
  std::string field;
  std::size_t line = 1, row_line = 1, total_cells = 0;
  bool in_quotes = false, was_quoted = false, after_quote = false;

  const auto end_field = [&] {
    row.push_back(std::move(field));
    field.clear();
    was_quoted = after_quote = false;
    if (++total_cells > max_csv_cells)
      throw FormatError(where + ":" + std::to_string(line) + ": more than " + std::to_string(max_csv_cells) +
                        " cells; a CSV table is limited to that many");
  };
  const auto end_row = [&] {
    // A line with nothing on it is skipped (as pandas does), not read as a row of one empty field.
    if (row.empty() && field.empty() && !was_quoted) return;
    end_field();
    rows.push_back(std::move(row));
    row_lines.push_back(row_line);
    row.clear();
  };

  for (std::size_t i = 0; i < text.size(); ++i) {
    const char ch = text[i];
    if (in_quotes) {
      if (ch == '"') {
        if (i + 1 < text.size() && text[i + 1] == '"') {
          field += '"';
          ++i;
        } else {
          in_quotes = false;
          after_quote = true;
        }
      } else {
        if (ch == '\n') ++line;
        field += ch;
      }
      continue;
    }
    if (ch == ',') {
      end_field();
    } else if (ch == '\n' || ch == '\r') {
      if (ch == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
      end_row();
      ++line;
      row_line = line;
    } else if (after_quote) {
      throw FormatError(where + ":" + std::to_string(line) + ": unexpected '" + std::string(1, ch) +
                        "' after a closing quote; a quoted field must end at a comma or line end");
    } else if (ch == '"' && field.empty() && !was_quoted) {
      in_quotes = was_quoted = true;
    } else {
      field += ch;  // a quote inside an unquoted field is taken literally
    }
  }
  if (in_quotes)
    throw FormatError(where + ":" + std::to_string(row_line) + ": a quoted field starting on this line is never closed");
  end_row();

  if (rows.empty()) throw FormatError(where + ": empty; a CSV table needs a header row");
  t.columns = std::move(rows.front());
  std::set<std::string> seen;
  for (const auto& c : t.columns)
    if (!c.empty() && !seen.insert(c).second)
      throw FormatError(where + ":" + std::to_string(row_lines.front()) + ": column '" + c + "' appears twice in the header");
  for (std::size_t r = 1; r < rows.size(); ++r) {
    if (rows[r].size() != t.columns.size())
      throw FormatError(where + ":" + std::to_string(row_lines[r]) + ": row has " + std::to_string(rows[r].size()) +
                        " field(s) but the header has " + std::to_string(t.columns.size()));
    t.cells.push_back(std::move(rows[r]));
    t.lines.push_back(row_lines[r]);
  }
  return t;
}

Table load_csv_table(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw IoError("cannot read '" + path + "': " + ec.message());
  if (size > max_csv_bytes)
    throw InvalidArgument("'" + path + "': " + std::to_string(size) + " bytes is larger than the " +
                          std::to_string(max_csv_bytes >> 20) + " MiB a CSV table may have");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open '" + path + "' for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw IoError("error reading '" + path + "'");
  const std::string text = ss.str();
  return parse_csv_table(text, "'" + path + "'");
}

}  // namespace texel::experiment
