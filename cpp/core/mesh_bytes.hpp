// A Mesh (and a lone ElementBlock, a list of strings, a list of integers) as a flat byte string and
// back: how a mesh made in a child process (core/isolated_call.hpp) reaches its parent. Same
// machine, same build: the numbers are copied as they are in memory, so the round trip is exact.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/mesh.hpp"

namespace homesh {

void appendMeshBytes(std::string& out, const Mesh& mesh);
void appendTextsBytes(std::string& out, const std::vector<std::string>& texts);
void appendIntBytes(std::string& out, const std::vector<std::int32_t>& values);
void appendBlockBytes(std::string& out, const ElementBlock& block);

// Read from `bytes` at `offset`, which moves past what was read. Throw MeshingError when the
// bytes are short, Error when inconsistent (checkConsistency for the mesh).
Mesh readMeshBytes(const std::string& bytes, std::size_t& offset);
ElementBlock readBlockBytes(const std::string& bytes, std::size_t& offset);
std::vector<std::string> readTextsBytes(const std::string& bytes, std::size_t& offset);
std::vector<std::int32_t> readIntBytes(const std::string& bytes, std::size_t& offset);

}  // namespace homesh
