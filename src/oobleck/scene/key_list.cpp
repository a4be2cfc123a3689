#include "oobleck/scene/key_list.hpp"

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "oobleck/io/toml_reader.hpp"

namespace oobleck::scene {
namespace {

/// The trailing comment of the node's last line, after its value.
std::string trailing_comment(const std::vector<std::string>& lines, const toml::source_region& where) {
  const auto line = static_cast<std::size_t>(where.end.line);
  if (line == 0 || line > lines.size()) return "";
  const std::string& text = lines[line - 1];
  const auto from = std::min<std::size_t>(where.end.column > 0 ? where.end.column - 1 : 0, text.size());
  const auto hash = text.find('#', from);
  if (hash == std::string::npos) return "";
  const auto start = text.find_first_not_of(" \t", hash + 1);
  return start == std::string::npos ? "" : text.substr(start);
}

/// The value as the file writes it ("0.47", not 0.46999999999999997); TOML's own text for a
/// value over several lines.
std::string toml_text(const std::vector<std::string>& lines, const toml::node& node) {
  const auto& where = node.source();
  if (where.begin.line == where.end.line && where.begin.line >= 1 && where.begin.line <= lines.size() &&
      where.begin.column >= 1 && where.end.column > where.begin.column) {
    const std::string& text = lines[where.begin.line - 1];
    if (where.end.column - 1 <= text.size())
      return text.substr(where.begin.column - 1, where.end.column - where.begin.column);
  }
  std::ostringstream os;
  node.visit([&](const auto& v) { os << v; });
  return os.str();
}

struct Walker {
  const std::vector<std::string>& lines;
  std::vector<std::pair<std::size_t, SceneKey>> found;  // (source line, key) to sort in file order

  void leaf(const std::string& key, const toml::node& node) {
    found.push_back({node.source().begin.line, {key, toml_text(lines, node), trailing_comment(lines, node.source())}});
  }
  void walk(const std::string& prefix, const toml::node& node) {
    if (const auto* t = node.as_table()) {
      if (t->is_inline()) return leaf(prefix, node);
      for (const auto& [k, v] : *t)
        walk(prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str()), v);
    } else if (const auto* a = node.as_array(); a != nullptr && a->is_array_of_tables()) {
      for (std::size_t i = 0; i < a->size(); ++i) walk(fmt::format("{}.{}", prefix, i), *a->get(i));
    } else {
      leaf(prefix, node);
    }
  }
};

}  // namespace

SceneKeyList list_scene_keys(const std::string& path) {
  const toml::table root = io::parse_toml_file(path);
  std::vector<std::string> lines;
  {
    std::ifstream in(path);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  Walker w{lines, {}};
  for (const auto& [k, v] : root) {
    if (k.str() != "aliases" && k.str() != "variants") w.walk(std::string(k.str()), v);
  }
  std::stable_sort(w.found.begin(), w.found.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  SceneKeyList list;
  std::map<std::string, std::string> values;
  for (auto& [line, key] : w.found) {
    values[key.key] = key.value;
    list.keys.push_back(std::move(key));
  }
  std::vector<std::pair<std::size_t, SceneAlias>> aliases;
  if (const auto* al = root.get_as<toml::table>("aliases")) {
    for (const auto& [k, v] : *al) {
      const std::string target = v.value<std::string>().value_or("");
      const auto it = values.find(target);
      aliases.push_back(
          {v.source().begin.line,
           {std::string(k.str()), target, it == values.end() ? "" : it->second, trailing_comment(lines, v.source())}});
    }
  }
  std::stable_sort(aliases.begin(), aliases.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& [line, a] : aliases) list.aliases.push_back(std::move(a));
  if (const auto* vt = root.get_as<toml::table>("variants")) {
    for (const auto& [k, v] : *vt) list.variants.emplace_back(k.str());
  }
  return list;
}

std::string format_scene_keys(const SceneKeyList& list) {
  std::string out;
  if (!list.aliases.empty()) {
    std::size_t wn = 0, wv = 0, wk = 0;
    for (const auto& a : list.aliases) {
      wn = std::max(wn, a.name.size());
      wv = std::max(wv, a.value.size());
      wk = std::max(wk, a.key.size());
    }
    out += "Short names (--set NAME=VALUE), with this scene's value, the key and [unit] meaning:\n";
    for (const auto& a : list.aliases) {
      out += fmt::format("  {:<{}}  {:<{}}  {:<{}}  {}\n", a.name, wn, a.value.empty() ? "(default)" : a.value,
                         std::max<std::size_t>(wv, 9), a.key, wk, a.comment);
    }
  }
  if (!list.variants.empty()) {
    out += "\nVariants (--set NAME=true):";
    for (const auto& v : list.variants) out += " " + v;
    out += "\n";
  }
  std::size_t wk = 0;
  for (const auto& k : list.keys) wk = std::max(wk, k.key.size() + 3 + std::min<std::size_t>(k.value.size(), 40));
  out += "\nKeys of the scene file (--set KEY=VALUE); every other key keeps the default docs/scenes.md gives:\n";
  for (const auto& k : list.keys) {
    const std::string kv = fmt::format("{} = {}", k.key, k.value);
    out += k.comment.empty() ? fmt::format("  {}\n", kv) : fmt::format("  {:<{}}  # {}\n", kv, wk, k.comment);
  }
  return out;
}

}  // namespace oobleck::scene
