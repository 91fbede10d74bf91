#include "io/atomic_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/error.hpp"

namespace homesh {

void checkParentFolder(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
    throw IoError("cannot write '" + path + "': folder '" + parent.string() + "' does not exist");
}

void writeFileAtomically(const std::string& path, const std::string& contents) {
  AtomicFile file(path, true);
  file.stream() << contents;
  file.commit();
}

AtomicFile::AtomicFile(const std::string& path, bool binary)
    : path_(path), temporary_(path + ".part") {
  checkParentFolder(path);
  stream_.open(temporary_, binary ? std::ios::out | std::ios::binary : std::ios::out);
  if (!stream_) throw IoError("cannot write '" + path + "': " + std::strerror(errno));
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    stream_.close();
    std::remove(temporary_.c_str());
  }
}

void AtomicFile::commit() {
  stream_.flush();
  const bool good = static_cast<bool>(stream_);
  stream_.close();
  if (!good || stream_.fail())
    throw IoError("cannot write '" + path_ + "': write failed (disk full?)");
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0)
    throw IoError("cannot write '" + path_ + "': " + std::strerror(errno));
  committed_ = true;
}

}  // namespace homesh
