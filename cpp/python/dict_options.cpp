#include "python/dict_options.hpp"

#include <Python.h>

#include <Eigen/Core>
#include <string>

#include "core/error.hpp"

namespace bp = boost::python;

namespace homesh {
namespace {

Eigen::Vector3d pointFrom(const bp::object& p, const std::string& what) {
  if (bp::len(p) != 3) throw ParameterError(what + " must be three numbers");
  return {bp::extract<double>(p[0]), bp::extract<double>(p[1]), bp::extract<double>(p[2])};
}

}  // namespace

OptionValue optionValueFrom(const bp::object& value) {
  PyObject* o = value.ptr();
  if (PyBool_Check(o) != 0) return o == Py_True;
  if (PyUnicode_Check(o) != 0) return std::string(bp::extract<std::string>(value));
  if (PyNumber_Check(o) != 0 && PyComplex_Check(o) == 0) {
    PyObject* real = PyNumber_Float(o);
    if (real != nullptr) {
      const double x = PyFloat_AsDouble(real);
      Py_DECREF(real);
      return x;
    }
    PyErr_Clear();
  }
  // Not a number, on/off or text (a list, an array): its repr, which every kind refuses.
  return std::string(bp::extract<std::string>(bp::str(value.attr("__repr__")())));
}

OptionMap optionMapFrom(const bp::dict& d) {
  OptionMap values;
  const bp::list keys = d.keys();
  for (bp::ssize_t i = 0; i < bp::len(keys); ++i) {
    const bp::object value = d[keys[i]];
    if (!value.is_none()) values[bp::extract<std::string>(keys[i])] = optionValueFrom(value);
  }
  return values;
}

std::vector<RefinementSource> sourcesFrom(const bp::object& list) {
  std::vector<RefinementSource> out;
  for (bp::ssize_t i = 0; i < bp::len(list); ++i) {
    const bp::dict src = bp::extract<bp::dict>(list[i]);
    const std::string kind = bp::extract<std::string>(src.get("kind", ""));
    const std::string which = "source " + std::to_string(i + 1);
    const double radius = bp::extract<double>(src.get("radius", 0.0));
    const double delta = bp::extract<double>(src.get("delta", 0.0));
    if (kind == "segment")
      out.push_back(RefinementSource::segment(pointFrom(src["a"], which + " a"),
                                              pointFrom(src["b"], which + " b"), radius, delta));
    else if (kind == "sphere")
      out.push_back(
          RefinementSource::sphere(pointFrom(src["a"], which + " centre"), radius, delta));
    else if (kind == "box")
      out.push_back(RefinementSource::box(pointFrom(src["a"], which + " a"),
                                          pointFrom(src["b"], which + " b"), delta));
    else if (kind == "curve")
      out.push_back(RefinementSource::curve(bp::extract<int>(src.get("edge", 0)), radius, delta));
    else {
      std::string message = which;
      message += ": kind must be segment, sphere, box or curve, got '";
      message += kind;
      message += "'";
      throw ParameterError(message);
    }
  }
  return out;
}

BoundaryLayerParameters boundaryLayerFrom(const bp::dict& d) {
  BoundaryLayerParameters p;
  const bp::object faces = d["faces"];
  for (bp::ssize_t i = 0; i < bp::len(faces); ++i) p.faces.push_back(bp::extract<int>(faces[i]));
  if (d.has_key("solids")) {
    const bp::object solids = d["solids"];
    for (bp::ssize_t i = 0; i < bp::len(solids); ++i)
      p.solids.push_back(bp::extract<int>(solids[i]));
  }
  p.thickness = bp::extract<std::string>(d["thickness"]);
  if (d.has_key("layers"))
    p.layers = static_cast<int>(checkedOption("layers", optionValueFrom(d["layers"])));
  if (d.has_key("progression"))
    p.progression = checkedOption("progression", optionValueFrom(d["progression"]));
  return p;
}

}  // namespace homesh
