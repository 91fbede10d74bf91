#include "core/mesh_bytes.hpp"

#include <cstdint>
#include <cstring>
#include <type_traits>

#include "core/error.hpp"

namespace homesh {
namespace {

template <class T>
void put(std::string& out, const T& value) {
  static_assert(std::is_trivially_copyable_v<T>);
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <class T>
void putVector(std::string& out, const std::vector<T>& values) {
  put(out, static_cast<std::uint64_t>(values.size()));
  if (!values.empty())
    out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

template <class T>
T get(const std::string& bytes, std::size_t& offset) {
  if (offset > bytes.size() || bytes.size() - offset < sizeof(T))
    throw MeshingError("the result handed back by a child process ends early");
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  offset += sizeof(T);
  return value;
}

template <class T>
std::vector<T> getVector(const std::string& bytes, std::size_t& offset) {
  const auto n = get<std::uint64_t>(bytes, offset);
  if (n > (bytes.size() - offset) / sizeof(T))
    throw MeshingError("the result handed back by a child process ends early");
  std::vector<T> values(n);
  if (n > 0) std::memcpy(values.data(), bytes.data() + offset, n * sizeof(T));
  offset += n * sizeof(T);
  return values;
}

}  // namespace

void appendBlockBytes(std::string& out, const ElementBlock& block) {
  put(out, static_cast<std::int32_t>(block.type));
  put(out, static_cast<std::int32_t>(block.order));
  put(out, static_cast<std::int32_t>(block.layerCells ? 1 : 0));
  putVector(out, block.nodes);
  putVector(out, block.entity);
}

ElementBlock readBlockBytes(const std::string& bytes, std::size_t& offset) {
  ElementBlock block;
  block.type = static_cast<CellType>(get<std::int32_t>(bytes, offset));
  block.order = get<std::int32_t>(bytes, offset);
  block.layerCells = get<std::int32_t>(bytes, offset) != 0;
  block.nodes = getVector<std::int64_t>(bytes, offset);
  block.entity = getVector<std::int32_t>(bytes, offset);
  return block;
}

void appendTextsBytes(std::string& out, const std::vector<std::string>& texts) {
  put(out, static_cast<std::uint64_t>(texts.size()));
  for (const std::string& text : texts) putVector(out, std::vector<char>(text.begin(), text.end()));
}

std::vector<std::string> readTextsBytes(const std::string& bytes, std::size_t& offset) {
  std::vector<std::string> texts;
  const auto n = get<std::uint64_t>(bytes, offset);
  for (std::uint64_t k = 0; k < n; ++k) {
    const std::vector<char> chars = getVector<char>(bytes, offset);
    texts.emplace_back(chars.begin(), chars.end());
  }
  return texts;
}

void appendIntBytes(std::string& out, const std::vector<std::int32_t>& values) {
  putVector(out, values);
}

std::vector<std::int32_t> readIntBytes(const std::string& bytes, std::size_t& offset) {
  return getVector<std::int32_t>(bytes, offset);
}

void appendMeshBytes(std::string& out, const Mesh& mesh) {
  put(out, static_cast<std::int32_t>(mesh.dim));
  put(out, static_cast<std::int32_t>(mesh.order));
  put(out, mesh.planeNormal);
  putVector(out, mesh.xyz);
  putVector(out, mesh.nodeCadDim);
  putVector(out, mesh.nodeCadIndex);
  putVector(out, mesh.nodeCadParam);
  put(out, static_cast<std::uint64_t>(mesh.blocks.size()));
  for (const ElementBlock& block : mesh.blocks) appendBlockBytes(out, block);
}

Mesh readMeshBytes(const std::string& bytes, std::size_t& offset) {
  Mesh mesh;
  mesh.dim = get<std::int32_t>(bytes, offset);
  mesh.order = get<std::int32_t>(bytes, offset);
  mesh.planeNormal = get<std::array<double, 3>>(bytes, offset);
  mesh.xyz = getVector<double>(bytes, offset);
  mesh.nodeCadDim = getVector<std::uint8_t>(bytes, offset);
  mesh.nodeCadIndex = getVector<std::int32_t>(bytes, offset);
  mesh.nodeCadParam = getVector<double>(bytes, offset);
  const auto blocks = get<std::uint64_t>(bytes, offset);
  for (std::uint64_t b = 0; b < blocks; ++b) mesh.blocks.push_back(readBlockBytes(bytes, offset));
  mesh.checkConsistency();
  return mesh;
}

}  // namespace homesh
