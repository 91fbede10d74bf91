// STEP through OpenCASCADE's reader, then the model's indexing and the CAD check (healing off:
// the check is what runs on every file; OCCT itself is not instrumented).
#include "cad/cad_healing.hpp"
#include "cad/cad_model.hpp"
#include "fuzz_target.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return homesh::fuzz::readBytes(data, size, ".step", [](const std::string& path) {
    homesh::HealingRecord record;
    homesh::healModel(homesh::CadModel::fromFile(path), homesh::HealingOptions{false, false},
                      record);
  });
}
