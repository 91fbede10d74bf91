// Base64 (RFC 4648 alphabet) and zlib helpers for the binary-in-XML formats.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace homesh {

// Standard base64 with '=' padding (VTK).
std::string base64Encode(const void* data, std::size_t size);

// Nektar++'s variant: the bytes zero-padded to a multiple of 3, then base64 without '='.
std::string base64EncodeZeroPadded(const void* data, std::size_t size);

// Decodes either variant ('=' and whitespace are ignored). Throws IoError on other characters.
std::string base64Decode(const std::string& text);

// zlib (RFC 1950) stream at the default level, and back. Throw IoError on failure, and when
// the stream would inflate to more than maxBytes (a "zip bomb": a few megabytes of crafted
// input can inflate a thousandfold); the default limit is kMaxInflatedBytes.
inline constexpr std::size_t kMaxInflatedBytes = std::size_t{2} << 30;  // 2 GiB
std::string zlibCompress(const std::string& bytes);
std::string zlibDecompress(const std::string& stream, std::size_t maxBytes = kMaxInflatedBytes);

}  // namespace homesh
