#pragma once
// Output files that appear complete or not at all: content goes to a temporary file beside the
// target and is renamed over it only on commit(). A run that fails (bad input, NaN) therefore
// never leaves a partial file nor overwrites an earlier good one.
#include <fstream>
#include <string>

namespace oobleck::io {

/// Throws InputError "cannot write output '<path>': <reason>" when the folder is missing or not
/// writable. Call it for every output path before any computation starts.
void check_writable(const std::string& path, const std::string& option);

class OutputFile {
 public:
  explicit OutputFile(std::string path, std::string option = "output");
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile();  // removes the temporary unless committed

  std::ofstream& stream() { return out_; }
  const std::string& temp_path() const { return tmp_; }
  /// Flush, close and atomically rename to the target path.
  void commit();

 private:
  std::string path_, tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

/// Write `content` to `path` atomically.
void write_file_atomically(const std::string& path, const std::string& content, const std::string& option = "output");

}  // namespace oobleck::io
