#include "io/output_dir.hpp"

#include "io/input_error.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <unistd.h>

namespace rocklab {

namespace fs = std::filesystem;

OutputDir::OutputDir(const std::string& path) : dir_(path) {
  std::error_code ec;
  if (fs::exists(dir_, ec)) {
    if (!fs::is_directory(dir_, ec))
      throw InputError(path + ": the output path (-o) exists and is not a directory; give a "
                              "folder, new or existing");
  } else {
    fs::create_directories(dir_, ec);
    if (ec)
      throw OutputError(path + ": cannot create output directory: " + ec.message());
    created_dir_ = true;
  }
  staging_ = dir_ / (".partial-" + std::to_string(::getpid()));
  fs::remove_all(staging_, ec);
  fs::create_directories(staging_, ec);
  if (ec)
    throw OutputError(staging_.string() + ": cannot create staging folder: " + ec.message());
}

OutputDir::~OutputDir() {
  std::error_code ec;
  fs::remove_all(staging_, ec);
  if (!committed_ && created_dir_)
    fs::remove_all(dir_, ec);
}

void OutputDir::commit() {
  for (const auto& entry : fs::directory_iterator(staging_)) {
    const fs::path dest = dir_ / entry.path().filename();
    std::error_code ec;
    if (fs::is_directory(dest, ec) && entry.is_directory())
      fs::remove_all(dest, ec);
    fs::rename(entry.path(), dest);
  }
  committed_ = true;
}

void write_file(const fs::path& p, const std::function<void(std::ostream&)>& write) {
  std::ofstream out(p, std::ios::binary);
  if (!out)
    throw OutputError(p.string() + ": cannot open for writing: " + std::strerror(errno));
  write(out);
  out.close();
  if (!out)
    throw OutputError(p.string() + ": write failed: " + std::strerror(errno));
}

void write_file_atomically(const fs::path& p, const std::function<void(std::ostream&)>& write) {
  const fs::path tmp = p.string() + ".partial";
  try {
    write_file(tmp, write);
  } catch (const OutputError&) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  fs::rename(tmp, p);
}

void write_text_file(const fs::path& p, const std::string& text) {
  write_file(p, [&](std::ostream& out) { out << text; });
}

} // namespace rocklab
