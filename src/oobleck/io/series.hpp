#pragma once
// CSV time series of global quantities (kinetic energy per body, momentum, total mass, max |v|,
// ...): a header of named columns, then one row per sample, flushed as it is written so that a
// run killed mid-way keeps every row before the kill. Numbers are written in the shortest form
// that reads back to the same double ("nan", "inf" for non-finite values).
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

namespace oobleck::io {

class SeriesWriter {
 public:
  /// Create (truncate) `path` and write the header. Column names: non-empty, no ',', '"' or
  /// line breaks, unique (std::invalid_argument). InputError when the folder is missing or
  /// read-only.
  SeriesWriter(std::string path, std::vector<std::string> columns);

  /// Continue the series of a restarted run: `path` must exist with exactly these columns
  /// (InputError naming the file otherwise); rows whose first column is > `keep_until` (the
  /// restart step or time) are dropped, atomically, and new rows are appended.
  static SeriesWriter resume(std::string path, std::vector<std::string> columns, double keep_until);

  SeriesWriter(SeriesWriter&& o) noexcept;
  SeriesWriter& operator=(SeriesWriter&& o) noexcept;
  SeriesWriter(const SeriesWriter&) = delete;
  SeriesWriter& operator=(const SeriesWriter&) = delete;
  ~SeriesWriter();

  /// Append one row; values.size() must equal the number of columns (std::invalid_argument).
  /// A failed write (disk full) throws std::runtime_error naming the file.
  void row(std::span<const double> values);
  void row(std::initializer_list<double> values) { row(std::span<const double>(values.begin(), values.size())); }

  const std::string& path() const { return path_; }
  const std::vector<std::string>& columns() const { return columns_; }
  std::size_t rows_written() const { return rows_; }

 private:
  SeriesWriter(std::string path, std::vector<std::string> columns, std::FILE* f);
  std::string path_;
  std::vector<std::string> columns_;
  std::FILE* file_ = nullptr;
  std::size_t rows_ = 0;
};

}  // namespace oobleck::io
