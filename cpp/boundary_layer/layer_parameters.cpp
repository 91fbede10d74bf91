#include "boundary_layer/layer_parameters.hpp"

#include <cstddef>
#include <exception>
#include <set>
#include <sstream>

#include "core/error.hpp"
#include "core/expression.hpp"

namespace homesh {

void BoundaryLayerParameters::validate() const {
  if (faces.empty())
    throw ParameterError("boundary layer: no faces given (--bl-faces, BndLayerSurfaces)");
  for (const int f : faces)
    if (f < 1)
      throw ParameterError("boundary-layer face " + std::to_string(f) +
                           " does not exist (faces are numbered from 1)");
  for (const int s : solids)
    if (s < 1)
      throw ParameterError("boundary-layer solid " + std::to_string(s) +
                           " does not exist (solids are numbered from 1)");
  if (thickness.empty())
    throw ParameterError("boundary layer: no thickness given (--bl-thickness, BndLayerThickness)");
  Expression::parse(thickness, "boundary-layer thickness");
  checkParameter("layers", layers);
  checkParameter("progression", progression);
}

std::vector<double> BoundaryLayerParameters::splitCoordinates() const {
  std::vector<double> z(static_cast<std::size_t>(layers) + 1, 0.0);
  double step = 1.0, total = 0.0;
  for (int k = 0; k < layers; ++k) {
    z[static_cast<std::size_t>(k) + 1] = z[static_cast<std::size_t>(k)] + step;
    total += step;
    step *= progression;
  }
  for (double& v : z) v /= total;
  z.back() = 1.0;
  return z;
}

std::vector<int> parseIndexList(const std::string& text, const std::string& what) {
  std::set<int> out;
  std::stringstream in(text);
  std::string item;
  const auto number = [&](std::string s) {
    s.erase(0, s.find_first_not_of(" \t"));
    s.erase(s.find_last_not_of(" \t") + 1);
    std::size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (s.empty() || used != s.size() || v < 1)
      throw ParameterError(what + " '" + text + "': '" + s +
                           "' is not a positive integer (give a list like 1,8 or 11-12)");
    return v;
  };
  while (std::getline(in, item, ',')) {
    const std::size_t dash = item.find('-');
    if (dash == std::string::npos) {
      out.insert(number(item));
      continue;
    }
    const int a = number(item.substr(0, dash)), b = number(item.substr(dash + 1));
    if (b < a || b - a > 100000) {
      std::string message = what;
      message.append(" '").append(text).append("': range '").append(item);
      throw ParameterError(message.append("' is empty or too long"));
    }
    for (int v = a; v <= b; ++v) out.insert(v);
  }
  if (out.empty()) throw ParameterError(what + " is empty");
  return {out.begin(), out.end()};
}

}  // namespace homesh
