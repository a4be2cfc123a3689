#include "oobleck/io/csv.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oobleck/core/error.hpp"

namespace oobleck::io {
namespace {
std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(trim(item));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}
}  // namespace

bool CsvTable::has_column(const std::string& name) const {
  return std::find(header.begin(), header.end(), name) != header.end();
}

std::vector<double> CsvTable::column(const std::string& name) const {
  const auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end()) {
    throw InputError(fmt::format("{}: missing column '{}' (columns present: {})", file, name, fmt::join(header, ", ")));
  }
  const auto j = static_cast<std::size_t>(it - header.begin());
  std::vector<double> v;
  v.reserve(rows.size());
  for (const auto& r : rows) v.push_back(r[j]);
  return v;
}

CsvTable read_csv(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw InputError(fmt::format("{}: not a regular file (a directory or device cannot be a data file)", path));
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open data file", path));
  CsvTable t;
  t.file = path;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    const std::string s = trim(line);
    if (s.empty() || s[0] == '#') continue;
    auto cells = split(s);
    if (t.header.empty()) {
      t.header = cells;
      for (const auto& h : t.header) {
        if (h.empty()) throw InputError(fmt::format("{}:{}: empty column name in header", path, lineno));
      }
      continue;
    }
    if (cells.size() != t.header.size()) {
      throw InputError(
          fmt::format("{}:{}: {} values but the header has {} columns", path, lineno, cells.size(), t.header.size()));
    }
    std::vector<double> row;
    for (std::size_t j = 0; j < cells.size(); ++j) {
      double v = 0.0;
      const auto& c = cells[j];
      const auto res = std::from_chars(c.data(), c.data() + c.size(), v);
      if (res.ec != std::errc() || res.ptr != c.data() + c.size() || !std::isfinite(v)) {
        throw InputError(fmt::format("{}:{}: column '{}': '{}' is not a finite number", path, lineno, t.header[j], c));
      }
      row.push_back(v);
    }
    t.rows.push_back(std::move(row));
  }
  if (t.header.empty()) throw InputError(fmt::format("{}: empty file (expected a header row)", path));
  return t;
}

}  // namespace oobleck::io
