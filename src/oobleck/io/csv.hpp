#pragma once
// Minimal CSV table reading for user data (rheometer curves): a header row of names, then rows
// of numbers. Errors name the file, line and column.
#include <map>
#include <string>
#include <vector>

namespace oobleck::io {

struct CsvTable {
  std::string file;
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  /// Values of column `name`; InputError naming the file and the columns present if missing.
  std::vector<double> column(const std::string& name) const;
  bool has_column(const std::string& name) const;
};

/// Read a comma-separated file with a header; blank lines and lines starting with '#' are skipped.
CsvTable read_csv(const std::string& path);

}  // namespace oobleck::io
