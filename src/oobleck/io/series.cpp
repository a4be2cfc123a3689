#include "oobleck/io/series.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"
#include "oobleck/io/output_file.hpp"

namespace oobleck::io {

namespace {

std::string header_line(const std::vector<std::string>& columns) {
  std::set<std::string> seen;
  std::string line;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    const auto& c = columns[i];
    if (c.empty() || c.find_first_of(",\"\n\r") != std::string::npos) {
      throw std::invalid_argument(fmt::format("series column name '{}': empty or contains , \" or a line break", c));
    }
    if (!seen.insert(c).second) throw std::invalid_argument(fmt::format("series column '{}' given twice", c));
    if (i > 0) line += ',';
    line += c;
  }
  if (columns.empty()) throw std::invalid_argument("series: no columns");
  return line;
}

/// "# units: a=s, b=1\n" for `units` beside `columns` (nothing when `units` is empty).
std::string units_line(const std::vector<std::string>& columns, const std::vector<std::string>& units) {
  if (units.empty()) return {};
  if (units.size() != columns.size()) {
    throw std::invalid_argument(fmt::format("series: {} units for {} columns", units.size(), columns.size()));
  }
  std::string line = "# units: ";
  for (std::size_t i = 0; i < units.size(); ++i) {
    const auto& u = units[i];
    if (u.empty() || u.find_first_of(",=\n\r") != std::string::npos) {
      throw std::invalid_argument(
          fmt::format("series column '{}': units '{}' empty or contain , = or a line break", columns[i], u));
    }
    if (i > 0) line += ", ";
    line += columns[i] + "=" + u;
  }
  return line + "\n";
}

}  // namespace

SeriesWriter::SeriesWriter(std::string path, std::vector<std::string> columns, std::FILE* f)
    : path_(std::move(path)), columns_(std::move(columns)), file_(f) {}

SeriesWriter::SeriesWriter(std::string path, std::vector<std::string> columns, const std::vector<std::string>& units)
    : path_(std::move(path)), columns_(std::move(columns)) {
  const std::string header = units_line(columns_, units) + header_line(columns_);
  check_writable(path_, "series");
  file_ = std::fopen(path_.c_str(), "w");
  if (file_ == nullptr) throw InputError(fmt::format("series '{}': cannot open for writing", path_));
  if (std::fprintf(file_, "%s\n", header.c_str()) < 0 || std::fflush(file_) != 0) {
    throw std::runtime_error(fmt::format("series '{}': write failed (disk full?)", path_));
  }
}

SeriesWriter SeriesWriter::resume(std::string path, std::vector<std::string> columns, double keep_until,
                                  const std::vector<std::string>& units) {
  const std::string header = header_line(columns);
  const std::string units_text = units_line(columns, units);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("series '{}': cannot resume, the file does not exist", path));
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  in.close();
  // A run killed while writing a row leaves a last line without its line break: drop it.
  if (!text.empty() && text.back() != '\n')
    text.erase(text.rfind('\n') == std::string::npos ? 0 : text.rfind('\n') + 1);
  std::istringstream lines(text);
  std::string line;
  bool read = false;
  std::size_t lineno = 0;
  while ((read = static_cast<bool>(std::getline(lines, line))) && line.starts_with('#')) ++lineno;
  ++lineno;
  if (!read || line != header) {
    throw InputError(fmt::format("series '{}': cannot resume, its header '{}' differs from '{}'", path, line, header));
  }
  std::string kept = units_text + header + "\n";
  std::size_t rows = 0;
  while (std::getline(lines, line)) {
    ++lineno;
    if (line.empty() || line.starts_with('#')) continue;
    const auto fields = static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')) + 1;
    const std::string first = line.substr(0, line.find(','));
    double key = 0;
    bool ok = fields == columns.size();
    try {
      std::size_t used = 0;
      key = std::stod(first, &used);
      ok = ok && used == first.size();
    } catch (const std::exception&) {
      ok = false;
    }
    if (!ok) {
      throw InputError(fmt::format("series '{}': cannot resume, line {} ('{}') is not {} numbers", path, lineno, line,
                                   columns.size()));
    }
    if (key > keep_until) break;
    kept += line + "\n";
    ++rows;
  }
  write_file_atomically(path, kept, "series");
  std::FILE* f = std::fopen(path.c_str(), "a");
  if (f == nullptr) throw InputError(fmt::format("series '{}': cannot open for appending", path));
  SeriesWriter w(std::move(path), std::move(columns), f);
  w.rows_ = rows;
  return w;
}

SeriesWriter::SeriesWriter(SeriesWriter&& o) noexcept
    : path_(std::move(o.path_)), columns_(std::move(o.columns_)), file_(o.file_), rows_(o.rows_) {
  o.file_ = nullptr;
}

SeriesWriter& SeriesWriter::operator=(SeriesWriter&& o) noexcept {
  if (this != &o) {
    if (file_ != nullptr) std::fclose(file_);
    path_ = std::move(o.path_);
    columns_ = std::move(o.columns_);
    file_ = o.file_;
    rows_ = o.rows_;
    o.file_ = nullptr;
  }
  return *this;
}

SeriesWriter::~SeriesWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void SeriesWriter::row(std::span<const double> values) {
  if (values.size() != columns_.size()) {
    throw std::invalid_argument(
        fmt::format("series '{}': row of {} values for {} columns", path_, values.size(), columns_.size()));
  }
  std::string line;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) line += ',';
    line += fmt::format("{}", values[i]);
  }
  line += '\n';
  if (std::fwrite(line.data(), 1, line.size(), file_) != line.size() || std::fflush(file_) != 0) {
    throw std::runtime_error(fmt::format("series '{}': write failed (disk full?)", path_));
  }
  ++rows_;
}

}  // namespace oobleck::io
