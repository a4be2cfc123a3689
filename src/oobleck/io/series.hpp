#pragma once
// CSV time series of global quantities (kinetic energy per body, momentum, total mass, max |v|,
// ...): with units, first the comment line "# units: time=s, step=1, ..." (every column, in
// order), then a header of named columns, then one row per sample, flushed as it is written so
// that a run killed mid-way keeps every row before the kill. Numbers are written in the shortest
// form that reads back to the same double ("nan", "inf" for non-finite values). Readers skip the
// '#' line (pandas: comment='#').
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

namespace oobleck::io {

class SeriesWriter {
 public:
  /// Create (truncate) `path` and write the units line (when `units` is not empty: one per
  /// column) and the header. Column names: non-empty, no ',', '"' or line breaks, unique; units:
  /// non-empty, no ',', '=' or line breaks (std::invalid_argument). InputError when the folder is
  /// missing or read-only.
  SeriesWriter(std::string path, std::vector<std::string> columns, const std::vector<std::string>& units = {});

  /// Continue the series of a restarted run: `path` must exist with exactly these columns
  /// (InputError naming the file otherwise; its '#' lines are not compared); rows whose first
  /// column is > `keep_until` (the restart step or time) are dropped, the units line is written
  /// anew, atomically, and new rows are appended.
  static SeriesWriter resume(std::string path, std::vector<std::string> columns, double keep_until,
                             const std::vector<std::string>& units = {});

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
