#include "oobleck/io/toml_reader.hpp"

#include <filesystem>
#include <sstream>

#include <fmt/format.h>

#include "oobleck/core/error.hpp"

namespace oobleck::io {

toml::table parse_toml_file(const std::string& path) {
  if (!std::filesystem::exists(path)) throw InputError(fmt::format("{}: file not found", path));
  if (!std::filesystem::is_regular_file(path))
    throw InputError(fmt::format("{}: not a regular file (a directory or device cannot be a TOML file)", path));
  try {
    return toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    const auto& where = e.source().begin;
    throw InputError(fmt::format("{}:{}:{}: TOML syntax error: {}", path, where.line, where.column, e.description()));
  }
}

TomlReader::TomlReader(const toml::table& table, std::string file, std::string path)
    : table_(&table), file_(std::move(file)), path_(std::move(path)) {}

std::string TomlReader::key_path(std::string_view key) const {
  return path_.empty() ? std::string(key) : fmt::format("{}.{}", path_, key);
}

bool TomlReader::has(std::string_view key) const { return table_->contains(key); }

const toml::node* TomlReader::lookup(std::string_view key) {
  used_.emplace(key);
  return table_->get(key);
}

void TomlReader::fail(std::string_view key, std::string_view message) const {
  throw InputError(fmt::format("{}: key '{}': {}", file_, key_path(key), message));
}

void TomlReader::require(bool ok, std::string_view key, double value, std::string_view rule) const {
  if (!ok) throw InputError(fmt::format("{}: key '{}' = {}: {}", file_, key_path(key), value, rule));
}

std::optional<double> TomlReader::optional_number(std::string_view key) {
  const toml::node* node = lookup(key);
  if (node == nullptr) return std::nullopt;
  if (auto v = node->value<double>(); v && (node->is_floating_point() || node->is_integer())) {
    return *v;
  }
  std::ostringstream got;
  got << node->type();
  fail(key, fmt::format("must be a number (got {})", got.str()));
}

double TomlReader::number(std::string_view key) {
  auto v = optional_number(key);
  if (!v) fail(key, "missing (required number)" + misspelled_hint(key));
  return *v;
}

std::string TomlReader::misspelled_hint(std::string_view key) const {
  std::vector<std::string> unknown;
  for (const auto& [k, v] : *table_) {
    if (used_.count(k.str()) == 0) unknown.emplace_back(k.str());
  }
  const std::string near = closest_match(std::string(key), unknown);
  return near.empty() ? std::string() : fmt::format("; found unknown key '{}' — a misspelling?", key_path(near));
}

double TomlReader::number_or(std::string_view key, double fallback) { return optional_number(key).value_or(fallback); }

std::string TomlReader::string(std::string_view key) {
  const toml::node* node = lookup(key);
  if (node == nullptr) fail(key, "missing (required string)" + misspelled_hint(key));
  if (!node->is_string()) fail(key, "must be a string");
  return *node->value<std::string>();
}

std::string TomlReader::string_or(std::string_view key, std::string fallback) {
  return has(key) ? string(key) : (used_.emplace(key), std::move(fallback));
}

bool TomlReader::boolean_or(std::string_view key, bool fallback) {
  const toml::node* node = lookup(key);
  if (node == nullptr) return fallback;
  if (!node->is_boolean()) fail(key, "must be true or false");
  return *node->value<bool>();
}

std::optional<TomlReader> TomlReader::optional_table(std::string_view key) {
  const toml::node* node = lookup(key);
  if (node == nullptr) return std::nullopt;
  if (!node->is_table()) fail(key, "must be a table ([section])");
  return TomlReader(*node->as_table(), file_, key_path(key));
}

TomlReader TomlReader::table(std::string_view key) {
  auto t = optional_table(key);
  if (!t) fail(key, "missing (required section)");
  return *t;
}

std::vector<TomlReader> TomlReader::table_array(std::string_view key) {
  std::vector<TomlReader> out;
  const toml::node* node = lookup(key);
  if (node == nullptr) return out;
  const toml::array* arr = node->as_array();
  if (arr == nullptr) fail(key, "must be an array of tables ([[section]])");
  std::size_t i = 0;
  for (const toml::node& item : *arr) {
    if (!item.is_table()) fail(key, fmt::format("element {} must be a table", i));
    out.emplace_back(*item.as_table(), file_, fmt::format("{}[{}]", key_path(key), i));
    ++i;
  }
  return out;
}

void TomlReader::finish() const {
  std::vector<std::string> known(used_.begin(), used_.end());
  for (const auto& [k, v] : *table_) {
    const std::string key(k.str());
    if (used_.count(key) != 0) continue;
    const std::string hint = closest_match(key, known);
    throw InputError(fmt::format("{}: key '{}': unknown key{}", file_, key_path(key),
                                 hint.empty() ? std::string() : fmt::format(" (did you mean '{}'?)", key_path(hint))));
  }
}

}  // namespace oobleck::io
