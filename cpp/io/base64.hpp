// Base64 (RFC 4648 alphabet) and zlib helpers for the binary-in-XML formats.
#pragma once

#include <cstdint>
#include <string>

namespace homesh {

// Standard base64 with '=' padding (VTK).
std::string base64Encode(const void* data, std::size_t size);

// Nektar++'s variant: the bytes zero-padded to a multiple of 3, then base64 without '='.
std::string base64EncodeZeroPadded(const void* data, std::size_t size);

// Decodes either variant ('=' and whitespace are ignored). Throws IoError on other characters.
std::string base64Decode(const std::string& text);

// zlib (RFC 1950) stream at the default level, and back. Throw IoError on failure.
std::string zlibCompress(const std::string& bytes);
std::string zlibDecompress(const std::string& stream);

}  // namespace homesh
