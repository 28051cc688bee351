#pragma once
// Numeric CSV tables (internal): an optional header line, '#' comments, blank lines ignored, fields
// separated by commas (or by whitespace when a line has no comma), quoted header fields allowed.
// Errors are InputError with input "<path>:<line>".
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "text_util.h"

namespace prizma::spectral::detail {

struct CsvTable {
  std::vector<std::string> header;          // empty when the file has none
  std::vector<std::vector<double>> rows;    // every row has the same number of columns
  std::vector<int> line_numbers;            // 1-based source line of each row
};

inline std::vector<std::string> split_csv_fields(std::string_view line) {
  std::vector<std::string> out;
  if (line.find(',') == std::string_view::npos) {
    std::istringstream is{std::string(line)};
    std::string tok;
    while (is >> tok) out.push_back(tok);
    return out;
  }
  std::string cur;
  bool in_quotes = false;
  for (char c : line) {
    if (c == '"') {
      in_quotes = !in_quotes;
    } else if (c == ',' && !in_quotes) {
      out.emplace_back(trim(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.emplace_back(trim(cur));
  return out;
}

// Drops a '#' comment (outside quotes) from a line.
inline std::string_view strip_comment(std::string_view line) {
  bool in_quotes = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (line[i] == '"') in_quotes = !in_quotes;
    if (line[i] == '#' && !in_quotes) return line.substr(0, i);
  }
  return line;
}

// Reads a numeric table with at least `min_columns` columns (exactly `exact_columns` when > 0).
inline CsvTable read_csv_table(const std::filesystem::path& path, std::size_t min_columns,
                               std::size_t exact_columns = 0) {
  const std::string name = path.string();
  require_regular_file(path, "a CSV file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(name, "cannot open file for reading");
  CsvTable t;
  std::string raw;
  int line_no = 0;
  bool seen_first = false;
  std::size_t ncols = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    std::string_view line = raw;
    if (line_no == 1 && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);  // UTF-8 BOM
    line = trim(strip_comment(line));
    if (line.empty()) continue;
    const std::string where = name + ":" + std::to_string(line_no);
    auto fields = split_csv_fields(line);
    double first = 0.0;
    if (!seen_first) {
      seen_first = true;
      if (!fields.empty() && !parse_double(fields[0], first)) {
        t.header = fields;
        continue;
      }
    }
    if (ncols == 0) {
      ncols = fields.size();
      if (ncols < min_columns || (exact_columns > 0 && ncols != exact_columns)) {
        throw InputError(where, "expected " + std::to_string(exact_columns > 0 ? exact_columns : min_columns) +
                                    (exact_columns > 0 ? "" : " or more") + " columns, got " +
                                    std::to_string(ncols) + ": " + dquote(line));
      }
    } else if (fields.size() != ncols) {
      throw InputError(where, "expected " + std::to_string(ncols) + " columns like the lines before, got " +
                                  std::to_string(fields.size()) + ": " + dquote(line));
    }
    std::vector<double> row(ncols);
    for (std::size_t c = 0; c < ncols; ++c) {
      if (!parse_double(fields[c], row[c])) {
        throw InputError(where, "not a number: " + dquote(fields[c]));
      }
      if (!std::isfinite(row[c])) throw InputError(where, "not a finite number: " + dquote(fields[c]));
    }
    t.rows.push_back(std::move(row));
    t.line_numbers.push_back(line_no);
  }
  if (in.bad()) throw InputError(name, "read error");
  if (t.rows.empty()) throw InputError(name, "no data lines");
  return t;
}

// Column `c` of a table as a spectrum over column 0, with the line of the first offending row in
// the error when wavelengths are not strictly increasing.
inline void check_increasing_wavelengths(const CsvTable& t, const std::filesystem::path& path) {
  for (std::size_t r = 1; r < t.rows.size(); ++r) {
    if (!(t.rows[r][0] > t.rows[r - 1][0])) {
      throw InputError(path.string() + ":" + std::to_string(t.line_numbers[r]),
                       "wavelengths must be strictly increasing: " + format_double(t.rows[r][0]) +
                           " nm follows " + format_double(t.rows[r - 1][0]) + " nm");
    }
  }
}

}  // namespace prizma::spectral::detail
