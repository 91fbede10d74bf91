#include "io/base64.hpp"

#include <zlib.h>

#include <array>
#include <cctype>

#include "core/error.hpp"

namespace homesh {
namespace {

const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

std::string encode(const std::uint8_t* data, std::size_t size, bool pad) {
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (std::size_t i = 0; i < size; i += 3) {
    const std::uint32_t b0 = data[i];
    const std::uint32_t b1 = i + 1 < size ? data[i + 1] : 0;
    const std::uint32_t b2 = i + 2 < size ? data[i + 2] : 0;
    const std::uint32_t triple = (b0 << 16) | (b1 << 8) | b2;
    out += kAlphabet[(triple >> 18) & 63];
    out += kAlphabet[(triple >> 12) & 63];
    out += i + 1 < size || !pad ? kAlphabet[(triple >> 6) & 63] : '=';
    out += i + 2 < size || !pad ? kAlphabet[triple & 63] : '=';
  }
  return out;
}

}  // namespace

std::string base64Encode(const void* data, std::size_t size) {
  return encode(static_cast<const std::uint8_t*>(data), size, true);
}

std::string base64EncodeZeroPadded(const void* data, std::size_t size) {
  std::string bytes(static_cast<const char*>(data), size);
  bytes.resize((size + 2) / 3 * 3, '\0');
  return encode(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), false);
}

std::string base64Decode(const std::string& text) {
  std::array<int, 256> value;
  value.fill(-1);
  for (int i = 0; i < 64; ++i) value[static_cast<unsigned char>(kAlphabet[i])] = i;
  std::string out;
  out.reserve(text.size() / 4 * 3);
  std::uint32_t buffer = 0;
  int bits = 0;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '=' || std::isspace(c) != 0) continue;
    if (value[c] < 0) throw IoError("invalid character in base64 data");
    buffer = (buffer << 6) | static_cast<std::uint32_t>(value[c]);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((buffer >> bits) & 0xFF);
    }
  }
  return out;
}

std::string zlibCompress(const std::string& bytes) {
  uLongf size = compressBound(static_cast<uLong>(bytes.size()));
  std::string out(size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(out.data()), &size,
                reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uLong>(bytes.size()),
                Z_DEFAULT_COMPRESSION) != Z_OK)
    throw IoError("zlib compression failed");
  out.resize(size);
  return out;
}

std::string zlibDecompress(const std::string& stream, std::size_t maxBytes) {
  z_stream z{};
  if (inflateInit(&z) != Z_OK) throw IoError("zlib initialisation failed");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(stream.data()));
  z.avail_in = static_cast<uInt>(stream.size());
  std::string out;
  std::array<char, 65536> chunk;
  int status = Z_OK;
  while (status == Z_OK) {
    z.next_out = reinterpret_cast<Bytef*>(chunk.data());
    z.avail_out = static_cast<uInt>(chunk.size());
    status = inflate(&z, Z_NO_FLUSH);
    if (out.size() + (chunk.size() - z.avail_out) > maxBytes) {
      inflateEnd(&z);
      throw IoError("compressed data inflates to more than " + std::to_string(maxBytes >> 20) +
                    " MiB (refused)");
    }
    out.append(chunk.data(), chunk.size() - z.avail_out);
    if (status == Z_BUF_ERROR && z.avail_in == 0) break;
  }
  inflateEnd(&z);
  // Trailing zero bytes after the stream (Nektar++'s padding) are fine.
  if (status != Z_STREAM_END) throw IoError("corrupt zlib data");
  return out;
}

}  // namespace homesh
