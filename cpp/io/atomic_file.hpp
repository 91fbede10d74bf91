// Writes a file under a temporary name and renames it into place on commit(), so readers never
// see a half-written file and a failure leaves any previous file intact.
#pragma once

#include <fstream>
#include <string>

namespace homesh {

// Throws IoError unless the folder `path` would be written in exists.
void checkParentFolder(const std::string& path);

// Writes `contents` to `path` through an AtomicFile.
void writeFileAtomically(const std::string& path, const std::string& contents);

class AtomicFile {
 public:
  // Throws IoError if the file cannot be created.
  AtomicFile(const std::string& path, bool binary);
  ~AtomicFile();  // removes the temporary file unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return stream_; }
  // Flushes, checks for write errors and renames; throws IoError on failure.
  void commit();

 private:
  std::string path_, temporary_;
  std::ofstream stream_;
  bool committed_ = false;
};

}  // namespace homesh
