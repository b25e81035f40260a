// An output directory that is either complete or untouched: files are written into a staging
// folder inside it and moved in place only when the run finishes.
#pragma once

#include <filesystem>
#include <functional>
#include <iosfwd>
#include <stdexcept>
#include <string>

namespace rocklab {

/// An output that cannot be written (disk full, file-size limit, no permission): exit status 4,
/// with what was staged removed (docs/errors.md).
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class OutputDir {
public:
  explicit OutputDir(const std::string& path);
  ~OutputDir();
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  /// Where to write a file now (inside the staging folder).
  std::filesystem::path staged(const std::string& name) const { return staging_ / name; }
  /// Move every staged file into the directory; after this the destructor keeps everything.
  void commit();
  const std::filesystem::path& path() const { return dir_; }

private:
  std::filesystem::path dir_, staging_;
  bool created_dir_ = false;
  bool committed_ = false;
};

/// Write a file by handing its stream to `write`; throws OutputError naming the file when
/// it cannot be opened or the write fails (disk full).
void write_file(const std::filesystem::path& p, const std::function<void(std::ostream&)>& write);
/// write_file to PATH.partial, then rename it to PATH: readers never see half a file, and a failed
/// write leaves nothing behind (the old PATH, if any, stays).
void write_file_atomically(const std::filesystem::path& p,
                           const std::function<void(std::ostream&)>& write);
/// Write text to a file (write_file).
void write_text_file(const std::filesystem::path& p, const std::string& text);

} // namespace rocklab
