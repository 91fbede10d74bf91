#include "pipeline/case_setup.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "core/error.hpp"
#include "io/mcf_reader.hpp"

namespace homesh {
namespace {

bool isMcf(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".mcf";
}

}  // namespace

CaseSetup setupCase(const std::string& input) {
  CaseSetup setup;
  if (!isMcf(input)) {
    setup.source = CadSource::file(input);
    return setup;
  }
  const McfCase mcf = readMcfFile(input);
  setup.fromMcf = true;
  setup.notices = mcf.notices;
  if (mcf.isNaca()) {
    NacaDomain d;
    d.digits = *mcf.nacaDigits;
    d.xmin = *mcf.xmin;
    d.ymin = *mcf.ymin;
    d.xmax = *mcf.xmax;
    d.ymax = *mcf.ymax;
    d.aoaDegrees = *mcf.aoa;
    setup.source = CadSource::nacaDomain(d);
  } else {
    setup.source = CadSource::file(mcf.cadFile);
    setup.source.scale = 0.001;  // NekMesh reads CAD in metres; OCCT gives millimetres
  }
  if (mcf.order) setup.options.order = *mcf.order;
  setup.options.expectedDimension = mcf.is2D() ? 2 : 3;
  const int given =
      int(mcf.minDelta.has_value()) + int(mcf.maxDelta.has_value()) + int(mcf.eps.has_value());
  if (given != 0 && given != 3)
    throw ParameterError(input + ": PARAMETERS needs all of MinDelta, MaxDelta and EPS, or none");
  if (given == 3) {
    SizingParameters p;
    p.minDelta = *mcf.minDelta;
    p.maxDelta = *mcf.maxDelta;
    p.eps = *mcf.eps;
    p.thinWall = 0.0;  // NekMesh's sizing has no thin-wall bound: its parameters, its sizes
    p.narrowFace = 0.0;
    for (const RefinementLine& line : mcf.refinementLines)
      p.sources.push_back(RefinementSource::segment(line.x1, line.x2, line.radius, line.delta));
    setup.options.sizing = p;
  } else if (!mcf.refinementLines.empty()) {
    throw ParameterError(input + ": REFINEMENT needs MinDelta, MaxDelta and EPS in PARAMETERS");
  }
  if (mcf.hasBoundaryLayer()) {
    const std::string file = std::filesystem::path(input).filename().string();
    const auto& keys = mcf.boundaryLayer;
    BoundaryLayerParameters bl;
    bl.faces = parseIndexList(keys.at("BndLayerSurfaces"), input + ": BndLayerSurfaces");
    bl.thickness = keys.at("BndLayerThickness");
    if (mcf.boundaryLayerLayers) bl.layers = *mcf.boundaryLayerLayers;
    if (mcf.boundaryLayerProgression) bl.progression = *mcf.boundaryLayerProgression;
    for (const auto& [key, value] : keys)
      if (key != "BndLayerSurfaces" && key != "BndLayerThickness" && key != "BndLayerLayers" &&
          key != "BndLayerProgression")
        setup.notices.push_back(std::string(file)
                                    .append(": PARAMETERS ")
                                    .append(key)
                                    .append(" is not used yet and is ignored"));
    setup.options.boundaryLayer = bl;
  }
  return setup;
}

}  // namespace homesh
