#include "cad/naca_aerofoil.hpp"

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepLib.hxx>
#include <BRepTools.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <Geom_BSplineCurve.hxx>
#include <TColStd_HArray1OfReal.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Wire.hxx>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <gp.hxx>
#include <gp_Pln.hxx>
#include <sstream>
#include <vector>

#include "cad/occt_access.hpp"
#include "core/error.hpp"
#include "core/format.hpp"

namespace homesh {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kSamples = 241;     // interpolation points per surface, both edges included
constexpr double kMargin = 0.01;  // chord fractions between the aerofoil and the box

struct Naca {
  double m = 0.0, p = 0.0, t = 0.0;  // maximum camber, its position, thickness (chord fractions)

  double thickness(double x) const {  // half thickness yt(x), closed trailing edge
    return 5.0 * t *
           (0.2969 * std::sqrt(x) + x * (-0.1260 + x * (-0.3516 + x * (0.2843 + x * -0.1036))));
  }
  double camber(double x) const {
    if (m == 0.0) return 0.0;
    return x < p ? m / (p * p) * (2.0 * p * x - x * x)
                 : m / ((1.0 - p) * (1.0 - p)) * (1.0 - 2.0 * p + 2.0 * p * x - x * x);
  }
  double camberSlope(double x) const {
    if (m == 0.0) return 0.0;
    return x < p ? 2.0 * m / (p * p) * (p - x) : 2.0 * m / ((1.0 - p) * (1.0 - p)) * (p - x);
  }
  // The surface point above (upper) or below the camber line at chord station x.
  gp_Pnt surface(double x, bool upper) const {
    const double yt = (upper ? 1.0 : -1.0) * thickness(x);
    const double theta = std::atan(camberSlope(x));
    return {x - yt * std::sin(theta), camber(x) + yt * std::cos(theta), 0.0};
  }
};

Naca parseDigits(const std::string& digits) {
  const bool ok = digits.size() == 4 && std::all_of(digits.begin(), digits.end(), [](char c) {
                    return std::isdigit(static_cast<unsigned char>(c)) != 0;
                  });
  if (!ok)
    throw ParameterError("NACA digits must be exactly 4 digits (as \"0012\"), got '" +
                         excerpt(digits) + "'");
  Naca n;
  n.m = (digits[0] - '0') / 100.0;
  n.p = (digits[1] - '0') / 10.0;
  n.t = std::stoi(digits.substr(2)) / 100.0;
  if (n.t <= 0.0) throw ParameterError("NACA " + digits + ": the thickness (digits 3-4) is zero");
  if (n.m > 0.0 && n.p == 0.0)
    throw ParameterError("NACA " + digits +
                         ": a cambered aerofoil needs the camber position (digit 2) above 0");
  if (n.m == 0.0) n.p = 0.0;  // no camber: the position digit means nothing
  return n;
}

// Rotation by -AOA about the origin.
gp_Pnt rotate(const gp_Pnt& p, double aoaRadians) {
  const double c = std::cos(aoaRadians), s = std::sin(aoaRadians);
  return {c * p.X() + s * p.Y(), -s * p.X() + c * p.Y(), 0.0};
}

// Spline parameters b of the samples: x = (1 - cos b) / 2 clusters them at both edges, and the
// surface is smooth in b (sqrt(x) = sin(b / 2)). A cambered aerofoil's camber line changes
// curvature at x = p, which puts a small tangent kink in its surfaces there (about 1e-3 rad for
// a 4421); the samples are graded down to 1/16 of their spacing towards it, so that the smooth
// spline stays within about 1e-7 chord of the formula.
std::vector<double> splineParameters(const Naca& n) {
  const double h = kPi / (kSamples - 1);
  std::vector<double> betas;
  if (n.m == 0.0) {
    for (int i = 0; i < kSamples; ++i) betas.push_back(i == kSamples - 1 ? kPi : h * i);
    return betas;
  }
  const double bp = std::acos(1.0 - 2.0 * n.p);
  std::vector<double> offsets = {0.0};
  double step = h / 16.0;
  for (int k = 1; offsets.back() + step < 4.0 * h; ++k) {
    offsets.push_back(offsets.back() + step);
    if (k % 2 == 0 && step < h) step *= 2.0;
  }
  const double keep = offsets.back() + 0.5 * h;
  for (int i = 0; i < kSamples; ++i) {
    const double b = i == kSamples - 1 ? kPi : h * i;
    if (std::abs(b - bp) > keep || i == 0 || i == kSamples - 1) betas.push_back(b);
  }
  for (const double o : offsets)
    for (const double b : {bp - o, bp + o})
      if (b > 0.5 * h && b < kPi - 0.5 * h) betas.push_back(b);
  std::sort(betas.begin(), betas.end());
  betas.erase(std::unique(betas.begin(), betas.end()), betas.end());
  return betas;
}

// Surface points, rotated, with their spline parameters: from the leading to the trailing edge
// (upper) or back (lower).
std::vector<std::pair<double, gp_Pnt>> samples(const Naca& n, bool upper, double aoa) {
  const std::vector<double> betas = splineParameters(n);
  std::vector<std::pair<double, gp_Pnt>> out;
  out.reserve(betas.size());
  for (const double b : betas) out.emplace_back(b, n.surface(0.5 * (1.0 - std::cos(b)), upper));
  out.front().second = gp_Pnt(0.0, 0.0, 0.0);  // the edges exactly, shared by both surfaces
  out.back().second = gp_Pnt(1.0, 0.0, 0.0);
  for (auto& [b, p] : out) p = rotate(p, aoa);
  if (!upper) {
    std::reverse(out.begin(), out.end());
    for (auto& [b, p] : out) b = kPi - b;
  }
  return out;
}

Handle(Geom_BSplineCurve) interpolate(const std::vector<std::pair<double, gp_Pnt>>& pts) {
  const int n = static_cast<int>(pts.size());
  Handle(TColgp_HArray1OfPnt) points = new TColgp_HArray1OfPnt(1, n);
  Handle(TColStd_HArray1OfReal) params = new TColStd_HArray1OfReal(1, n);
  for (int i = 0; i < n; ++i) {
    points->SetValue(i + 1, pts[i].second);
    params->SetValue(i + 1, pts[i].first);
  }
  GeomAPI_Interpolate interpolation(points, params, false, 1e-12);
  interpolation.Perform();
  if (!interpolation.IsDone()) throw CadError("NACA aerofoil: B-spline interpolation failed");
  return interpolation.Curve();
}

void checkBox(const NacaDomain& d, const std::vector<std::pair<double, gp_Pnt>>& upper,
              const std::vector<std::pair<double, gp_Pnt>>& lower) {
  for (const auto& [name, value] : {std::pair<const char*, double>{"Xmin", d.xmin},
                                    {"Ymin", d.ymin},
                                    {"Xmax", d.xmax},
                                    {"Ymax", d.ymax},
                                    {"AOA", d.aoaDegrees}})
    if (!std::isfinite(value))
      throw ParameterError(std::string("NACA domain: ") + name + " must be a finite number");
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const auto* side : {&upper, &lower}) {
    for (const auto& [b, p] : *side) {
      x0 = std::min(x0, p.X());
      y0 = std::min(y0, p.Y());
      x1 = std::max(x1, p.X());
      y1 = std::max(y1, p.Y());
    }
  }
  const auto fail = [&](const char* name, double value, const char* relation, double limit) {
    throw ParameterError(std::string("NACA domain: ") + name + " (" + formatNumber(value) +
                         ") must be " + relation + " " + formatNumber(limit) +
                         " to hold the aerofoil at AOA " + formatNumber(d.aoaDegrees) +
                         " with a margin of " + formatNumber(kMargin) + " chord");
  };
  if (d.xmin > x0 - kMargin) fail("Xmin", d.xmin, "at most", x0 - kMargin);
  if (d.ymin > y0 - kMargin) fail("Ymin", d.ymin, "at most", y0 - kMargin);
  if (d.xmax < x1 + kMargin) fail("Xmax", d.xmax, "at least", x1 + kMargin);
  if (d.ymax < y1 + kMargin) fail("Ymax", d.ymax, "at least", y1 + kMargin);
}

}  // namespace

CadModel makeNacaDomain(const NacaDomain& d) {
  const Naca naca = parseDigits(d.digits);
  const std::string name = "NACA " + d.digits;
  const double aoa = d.aoaDegrees * kPi / 180.0;
  const auto upperPoints = samples(naca, true, aoa);
  const auto lowerPoints = samples(naca, false, aoa);
  checkBox(d, upperPoints, lowerPoints);

  const TopoDS_Face face = withOcctErrors("building the " + name + " domain", [&] {
    const auto vertex = [](double x, double y) {
      return BRepBuilderAPI_MakeVertex(gp_Pnt(x, y, 0.0)).Vertex();
    };
    const std::array<TopoDS_Vertex, 4> corners = {vertex(d.xmin, d.ymin), vertex(d.xmax, d.ymin),
                                                  vertex(d.xmax, d.ymax), vertex(d.xmin, d.ymax)};
    BRepBuilderAPI_MakeWire outer;
    for (int k = 0; k < 4; ++k)
      outer.Add(BRepBuilderAPI_MakeEdge(corners[k], corners[(k + 1) % 4]).Edge());

    const TopoDS_Vertex leading = vertex(0.0, 0.0);
    const TopoDS_Vertex trailing = BRepBuilderAPI_MakeVertex(upperPoints.back().second).Vertex();
    const TopoDS_Edge upper =
        BRepBuilderAPI_MakeEdge(interpolate(upperPoints), leading, trailing).Edge();
    const TopoDS_Edge lower =
        BRepBuilderAPI_MakeEdge(interpolate(lowerPoints), trailing, leading).Edge();
    // Upper then lower runs clockwise: a hole in a face whose normal is +z.
    BRepBuilderAPI_MakeWire inner(upper, lower);
    if (!outer.IsDone() || !inner.IsDone()) throw CadError(name + ": the wires do not close");

    BRepBuilderAPI_MakeFace makeFace(gp_Pln(gp::Origin(), gp::DZ()), outer.Wire(), true);
    makeFace.Add(inner.Wire());
    if (!makeFace.IsDone()) throw CadError(name + ": the face cannot be built");
    TopoDS_Face f = makeFace.Face();
    TopTools_IndexedMapOfShape edges;
    TopExp::MapShapes(f, TopAbs_EDGE, edges);
    for (int i = 1; i <= edges.Extent(); ++i)
      BRepLib::BuildPCurveForEdgeOnPlane(TopoDS::Edge(edges(i)), f);
    if (edges.Extent() != 6 || !edges(5).IsSame(upper) || !edges(6).IsSame(lower))
      throw CadError(name + ": the aerofoil's edges are not Edge5 and Edge6");
    if (!BRepCheck_Analyzer(f).IsValid()) throw CadError(name + ": the face is not valid");
    return f;
  });

  std::ostringstream text;
  withOcctErrors("writing the " + name + " domain", [&] { BRepTools::Write(face, text); });
  return CadModel::fromBrepText(text.str(), name);
}

}  // namespace homesh
