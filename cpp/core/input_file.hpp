// The one check every reader makes before opening an input: the path names a regular file.
// A FIFO would block the reader until some other process writes to it (a hang, not an error),
// and a directory or device is never an input.
#pragma once

#include <string>

namespace homesh {

// Throws IoError naming `what` (e.g. "input file", "mesh file") and the path when it does not
// exist, is a directory, or is not a regular file (FIFO, socket, device).
void requireRegularFile(const std::string& path, const std::string& what);

// The extension of `path` in lower case, with its dot (".step", ".msh"); empty when it has none.
// What every reader and writer chooses a format by.
std::string lowerExtension(const std::string& path);

// The whole content of the file at `path`, as bytes. Throws IoError naming `what` and the path
// when it cannot be opened.
std::string readFileBytes(const std::string& path, const std::string& what);

}  // namespace homesh
