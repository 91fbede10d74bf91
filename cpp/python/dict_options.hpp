// Python values and dicts as the core's options (internal to the Python module, module.cpp):
// a parameter's value, an options dict keyed as the parameter table, refinement sources and a
// boundary layer, as homesh/api.py hands them over after checking their keys.
#pragma once

#include <boost/python.hpp>
#include <vector>

#include "boundary_layer/layer_parameters.hpp"
#include "core/parameters.hpp"
#include "sizing/refinement_source.hpp"

namespace homesh {

// A Python value for a parameter as the core takes it (a bool, a real number or text);
// core/parameters.hpp's checkedOption judges it and names the parameter when it does not fit.
OptionValue optionValueFrom(const boost::python::object& value);

// The entries of an options dict keyed as the parameter table, None left out (not given).
OptionMap optionMapFrom(const boost::python::dict& d);

// Refinement sources from a list of dicts [{"kind": "segment" | "sphere" | "box" | "curve", "a",
// "b", "radius", "delta", "edge"}, ...] (homesh/api.py checks their fields first). Throws
// ParameterError naming the source whose kind or point is wrong.
std::vector<RefinementSource> sourcesFrom(const boost::python::object& list);

// The boundary layer of a dict the Python layer checked for its keys (homesh/api.py
// _boundary_layer): "faces" and optionally "solids" (lists of int), "thickness" (text), "layers",
// "progression" (checked here against the parameter table).
BoundaryLayerParameters boundaryLayerFrom(const boost::python::dict& d);

}  // namespace homesh
