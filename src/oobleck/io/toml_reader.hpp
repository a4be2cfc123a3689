#pragma once
// Validated reading of TOML input (presets, scenes). Every accessor records the key it used;
// finish() turns every key that nobody asked for into an error with a "did you mean" hint.
// Errors name the file, the full key path, the value and the rule (oobleck::InputError).
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

namespace oobleck::io {

/// Parse a TOML file; a missing file or a syntax error becomes an InputError naming the file
/// (and line/column for syntax errors).
toml::table parse_toml_file(const std::string& path);

class TomlReader {
 public:
  /// `path` is the dotted key path of this table inside the file ("" for the root).
  TomlReader(const toml::table& table, std::string file, std::string path = "");

  const std::string& file() const { return file_; }
  std::string key_path(std::string_view key) const;
  bool has(std::string_view key) const;

  double number(std::string_view key);                      // required
  double number_or(std::string_view key, double fallback);  // optional with default
  std::optional<double> optional_number(std::string_view key);
  std::string string(std::string_view key);
  std::string string_or(std::string_view key, std::string fallback);
  bool boolean_or(std::string_view key, bool fallback);
  std::optional<TomlReader> optional_table(std::string_view key);
  TomlReader table(std::string_view key);
  /// An array of tables ([[key]]); empty when absent.
  std::vector<TomlReader> table_array(std::string_view key);

  /// Throw InputError "<file>: key '<path.key>' = <value>: <rule>" unless `ok`.
  void require(bool ok, std::string_view key, double value, std::string_view rule) const;
  /// Throw InputError "<file>: key '<path.key>': <message>".
  [[noreturn]] void fail(std::string_view key, std::string_view message) const;

  /// The raw node of `key` (nullptr when absent); records the key as known.
  const toml::node* raw(std::string_view key) { return lookup(key); }

  /// Error on any key of this table that was never read (typos, unsupported options).
  void finish() const;

 private:
  const toml::node* lookup(std::string_view key);
  std::string misspelled_hint(std::string_view key) const;
  const toml::table* table_;
  std::string file_;
  std::string path_;
  std::set<std::string, std::less<>> used_;
};

}  // namespace oobleck::io
