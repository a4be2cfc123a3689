#pragma once
// `oobleck run SCENE --list-keys`: the keys a scene file sets, with their values and the unit and
// meaning its comments give, and its [aliases] (the short names --set takes) with the key each
// stands for. Keys a scene leaves at the reader's default are listed in docs/scenes.md.
#include <string>
#include <vector>

namespace oobleck::scene {

struct SceneKey {
  std::string key;      ///< dotted path as --set takes it ("region.0.phi")
  std::string value;    ///< TOML text of the value in the file
  std::string comment;  ///< the line's trailing comment ("[m] 50 x 35 cells of 1 mm"), may be empty
};

struct SceneAlias {
  std::string name;     ///< short name ("phi")
  std::string key;      ///< the key it stands for
  std::string value;    ///< the key's value in the file ("" if the file leaves it at its default)
  std::string comment;  ///< the alias line's comment ("[-] granular volume fraction of the bed")
};

struct SceneKeyList {
  std::vector<SceneAlias> aliases;  ///< in file order
  std::vector<SceneKey> keys;       ///< in file order, [aliases] and [variants] left out
  std::vector<std::string> variants;
};

/// Reads `path` (InputError naming the file on a syntax error).
SceneKeyList list_scene_keys(const std::string& path);

/// The list as text for a terminal.
std::string format_scene_keys(const SceneKeyList& list);

}  // namespace oobleck::scene
