// The Python extension homesh._core (Boost.Python). The pure-Python package `homesh` wraps it;
// see homesh/__init__.py for the public API.
//
// Every C++ exception becomes a Python exception (homesh errors to their Python classes, other
// std::exceptions to RuntimeError), so a failing job never takes FreeCAD down. Long calls release
// the GIL; the progress callback re-acquires it.
#include <Python.h>

#include <algorithm>
#include <atomic>
#include <boost/python.hpp>
#include <boost/python/numpy.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "cad/numbering_map.hpp"
#include "core/error.hpp"
#include "core/parameters.hpp"
#include "core/version.hpp"
#include "element/element_measure.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"
#include "io/mesh_readers.hpp"
#include "pipeline/case_setup.hpp"
#include "pipeline/geometry_check.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "pipeline/mesh_summary.hpp"
#include "pipeline/nektar_read_back.hpp"
#include "pipeline/report.hpp"
#include "python/dict_options.hpp"
#include "sizing/sizing_octree.hpp"

namespace bp = boost::python;
namespace np = boost::python::numpy;

namespace homesh {
namespace {

PyObject* gBaseError = nullptr;
PyObject* gParameterError = nullptr;
PyObject* gCadError = nullptr;
PyObject* gMeshingError = nullptr;
PyObject* gFileError = nullptr;
PyObject* gCancelledError = nullptr;

PyObject* makeException(const char* name, PyObject* bases, const char* doc) {
  const std::string qualified = std::string("homesh._core.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases, nullptr);
  if (type == nullptr) bp::throw_error_already_set();
  bp::scope().attr(name) = bp::handle<>(bp::borrowed(type));
  return type;
}

template <class E>
void registerTranslator(PyObject* pyType) {
  bp::register_exception_translator<E>([pyType](const E& e) { PyErr_SetString(pyType, e.what()); });
}

class ReleaseGil {
 public:
  ReleaseGil() : state_(PyEval_SaveThread()) {}
  ~ReleaseGil() { PyEval_RestoreThread(state_); }
  ReleaseGil(const ReleaseGil&) = delete;
  ReleaseGil& operator=(const ReleaseGil&) = delete;

 private:
  PyThreadState* state_;
};

// Calls progress(stage, seconds_or_None); an exception in the callback cancels the job.
// Holds the GIL for its lifetime (from a thread that released it).
class AcquireGil {
 public:
  AcquireGil() : state_(PyGILState_Ensure()) {}
  ~AcquireGil() { PyGILState_Release(state_); }
  AcquireGil(const AcquireGil&) = delete;
  AcquireGil& operator=(const AcquireGil&) = delete;

 private:
  PyGILState_STATE state_;
};

// The text of the pending Python exception (which is cleared); never fails.
std::string takePythonError() {
  PyObject *type = nullptr, *value = nullptr, *trace = nullptr;
  PyErr_Fetch(&type, &value, &trace);
  std::string text;
  if (value != nullptr) {
    PyObject* str = PyObject_Str(value);
    const char* utf8 = str != nullptr ? PyUnicode_AsUTF8(str) : nullptr;
    if (utf8 != nullptr) text = utf8;
    Py_XDECREF(str);
  }
  PyErr_Clear();  // also whatever PyObject_Str or PyUnicode_AsUTF8 may have raised
  Py_XDECREF(type);
  Py_XDECREF(value);
  Py_XDECREF(trace);
  return text;
}

// homesh._core.CancelToken: set from any thread (a GUI's Cancel button) while a job runs with
// the GIL released; the job reads it without the GIL, between stages, the linear mesher's
// dimensions and the optimiser's colour groups.
class CancelToken {
 public:
  void cancel() { cancelled_.store(true); }
  bool cancelled() const { return cancelled_.load(); }

 private:
  std::atomic<bool> cancelled_{false};
};

// Calls progress(stage, seconds_or_None, fraction, detail): when a stage starts (None, 0, ""),
// within it (None, fraction, what was done) and when it ends (its seconds, 1, ""). An exception
// in the callback, or the token's cancel(), cancels the job. Called with the GIL released;
// never lets an exception escape into the pipeline.
class PythonProgress : public PipelineObserver {
 public:
  PythonProgress(bp::object callback, const CancelToken* token)
      : callback_(std::move(callback)), token_(token) {}
  void stageStarted(const std::string& stage) override { call(stage, nullptr, 0.0, ""); }
  void stageProgress(const std::string& stage, double fraction,
                     const std::string& detail) override {
    call(stage, nullptr, fraction, detail);
  }
  void stageFinished(const std::string& stage, double seconds) override {
    call(stage, &seconds, 1.0, "");
  }
  bool cancelRequested() override {
    return (token_ != nullptr && token_->cancelled()) || failed_.load();
  }
  const std::string& failure() const { return failure_; }

 private:
  void call(const std::string& stage, const double* seconds, double fraction,
            const std::string& detail) noexcept {
    if (!failure_.empty()) return;
    const AcquireGil gil;
    if (callback_.is_none()) return;
    try {
      callback_(stage, seconds != nullptr ? bp::object(*seconds) : bp::object(),
                std::min(1.0, std::max(0.0, fraction)), detail);
    } catch (const bp::error_already_set&) {
      const std::string text = takePythonError();
      failure_ = "progress callback raised an exception" + (text.empty() ? "" : ": " + text);
      failed_.store(true);
    } catch (...) {
      PyErr_Clear();
      failure_ = "progress callback failed";
      failed_.store(true);
    }
  }
  bp::object callback_;
  const CancelToken* token_;
  std::string failure_;
  // Set with failure_: cancelRequested may be asked from any of the optimiser's threads.
  std::atomic<bool> failed_{false};
};

template <class T>
np::ndarray toArray(const std::vector<T>& values, std::size_t rows, std::size_t cols) {
  const bp::tuple shape = cols == 0 ? bp::make_tuple(rows) : bp::make_tuple(rows, cols);
  np::ndarray a = np::empty(shape, np::dtype::get_builtin<T>());
  if (!values.empty()) std::memcpy(a.get_data(), values.data(), values.size() * sizeof(T));
  return a;
}

// Copies a contiguous numpy array of dtype T (any shape) into a vector.
template <class T>
std::vector<T> fromArray(const bp::object& object, const char* what) {
  np::ndarray a = np::from_object(object, np::dtype::get_builtin<T>(), np::ndarray::C_CONTIGUOUS);
  std::size_t n = 1;
  for (int k = 0; k < a.get_nd(); ++k) n *= static_cast<std::size_t>(a.shape(k));
  if (a.get_nd() == 0) throw ParameterError(std::string(what) + " must be an array");
  std::vector<T> v(n);
  if (n) std::memcpy(v.data(), a.get_data(), n * sizeof(T));
  return v;
}

CellType cellTypeFromName(const std::string& name) {
  for (CellType t :
       {CellType::Line, CellType::Triangle, CellType::Quadrilateral, CellType::Tetrahedron,
        CellType::Prism, CellType::Pyramid, CellType::Hexahedron})
    if (cellShortName(t) == name) return t;
  throw ParameterError("unknown element type '" + name + "'");
}

// The Python-visible mesh: the curved mesh a job made (or a mesh read from a file or rebuilt from
// saved arrays) and, apart, its job's records, from which report() and summary() are written.
class PyMesh {
 public:
  PyMesh(CurvedMesh curved, StageRecords records)
      : curved_(std::make_shared<const CurvedMesh>(std::move(curved))),
        records_(std::make_shared<const StageRecords>(std::move(records))) {}
  explicit PyMesh(MeshResult result)
      : PyMesh(std::move(static_cast<CurvedMesh&>(result)),
               std::move(static_cast<StageRecords&>(result))) {}

  int order() const { return curved_->mesh.order; }
  int dim() const { return curved_->mesh.dim; }
  std::size_t numNodes() const { return curved_->mesh.numNodes(); }
  std::size_t numElements() const { return curved_->mesh.numElements(); }
  bool hasCad() const { return static_cast<bool>(curved_->cad); }
  // The CAD file's numbers to the meshed model's (HealingRecord::numbering) as text, "" when
  // they are the same: kept in a saved .npz so that groups stay in the file's numbering.
  std::string numberingText() const {
    const NumberingMap& n = records_->healing.numbering;
    return n.changed() ? n.toText() : std::string();
  }

  np::ndarray nodes() const { return toArray(curved_->mesh.xyz, numNodes(), 3); }
  np::ndarray nodeCadDim() const { return toArray(curved_->mesh.nodeCadDim, numNodes(), 0); }
  np::ndarray nodeCadIndex() const { return toArray(curved_->mesh.nodeCadIndex, numNodes(), 0); }
  np::ndarray nodeCadParams() const { return toArray(curved_->mesh.nodeCadParam, numNodes(), 2); }
  bp::tuple planeNormal() const {
    const auto& n = curved_->mesh.planeNormal;
    return bp::make_tuple(n[0], n[1], n[2]);
  }

  // [(type name, order, connectivity (E, npe) int64, entity (E,) int32), ...]
  bp::list blocks() const {
    bp::list out;
    for (const ElementBlock& b : curved_->mesh.blocks)
      out.append(bp::make_tuple(cellShortName(b.type), b.order,
                                toArray(b.nodes, b.count(), b.nodesPerElement()),
                                toArray(b.entity, b.count(), 0)));
    return out;
  }

  np::ndarray scaledJacobian() const {
    return toArray(curved_->quality.scaledJacobian, curved_->quality.scaledJacobian.size(), 0);
  }

  bp::dict qualitySummary() const {
    const QualitySummary& q = curved_->quality;
    bp::dict d;
    d["min"] = q.scaled.min;
    d["mean"] = q.scaled.mean;
    d["distortion_min"] = q.distortionSummary.min;
    d["distortion_mean"] = q.distortionSummary.mean;
    d["invalid_elements"] = q.invalid;
    d["undecided_elements"] = q.undecided;
    d["certified"] = q.certified;
    bp::dict byType;
    for (const auto& [type, t] : q.byType) {
      bp::dict e;
      e["count"] = t.count;
      e["min"] = t.scaledJacobian.min;
      e["mean"] = t.scaledJacobian.mean;
      e["invalid_elements"] = t.invalid;
      byType[cellShortName(type)] = e;
    }
    d["by_type"] = byType;
    return d;
  }

  np::ndarray distortion() const {
    return toArray(curved_->quality.distortion, curved_->quality.distortion.size(), 0);
  }

  // Upper ends of the intervals that hold each element's min J / max J.
  np::ndarray scaledJacobianUpper() const {
    const auto& v = curved_->quality.scaledJacobianUpper;
    return toArray(v, v.size(), 0);
  }

  // Per element: 1 proven valid, -1 invalid, 0 undecided.
  np::ndarray validity() const {
    std::vector<std::int8_t> v;
    for (const Validity x : curved_->quality.validity)
      v.push_back(x == Validity::Valid ? 1 : x == Validity::Invalid ? -1 : 0);
    return toArray(v, v.size(), 0);
  }

  bp::dict timings() const {
    bp::dict d;
    for (const auto& [stage, s] : records_->timings.seconds) d[stage] = s;
    return d;
  }

  // groups: a list of (name, [entity, ...]) pairs (named boundary groups). Returns, for a .xml
  // whose geometry as Nektar++ builds it is not proven valid, the line saying so
  // (pipeline/nektar_read_back.hpp); else "".
  std::string write(const std::string& path, bool binary, bool compressed,
                    const bp::list& groups) const {
    WriteOptions options;
    options.binary = binary;
    options.compressed = compressed;
    for (bp::ssize_t i = 0; i < bp::len(groups); ++i) {
      const bp::tuple g = bp::extract<bp::tuple>(groups[i]);
      NamedGroup group;
      group.name = bp::extract<std::string>(g[0]);
      const bp::list entities = bp::extract<bp::list>(g[1]);
      for (bp::ssize_t k = 0; k < bp::len(entities); ++k)
        group.entities.push_back(bp::extract<int>(entities[k]));
      options.groups.push_back(std::move(group));
    }
    options = inMeshedNumbering(std::move(options), *records_, curved_->mesh.dim);
    const ReleaseGil nogil;
    writeMeshFiles(*curved_, {path}, options);
    if (std::filesystem::path(path).extension() != ".xml") return "";
    const NektarReadBack check = checkNektarReadBack(path, records_->options.threads);
    return check.proven() ? "" : check.line();
  }

  np::ndarray elementVolumes() const {
    const std::vector<double> v = elementMeasures(curved_->mesh);
    return toArray(v, v.size(), 0);
  }

  std::string reportJson(const std::string& input) const {
    return meshReportJson(*curved_, *records_, input);
  }

  // pipeline/mesh_summary.hpp's lines and headline, as the CLI prints them.
  bp::list summaryLines() const {
    bp::list out;
    for (const std::string& line : meshSummaryLines(*curved_, *records_)) out.append(line);
    return out;
  }
  std::string headline() const { return qualityHeadline(curved_->mesh, curved_->quality); }

  // A copy of this mesh optimised (optimise/optimiser.hpp) with the options of a dict keyed as
  // the parameter table (OptimiserOptions::apply checks them), and the optimiser's JSON record.
  bp::tuple optimise(const bp::dict& given) const {
    OptimiserOptions options;
    options.apply(optionMapFrom(given));
    const int threads = options.threads;
    CurvedMesh copy = *curved_;
    StageRecords records = *records_;
    OptimiserResult record;
    {
      const ReleaseGil nogil;
      // A mesh made from CAD keeps it: boundary nodes slide on their curves and faces.
      record = optimiseMesh(copy.mesh, options, nullptr, copy.cad.get());
      copy.quality = evaluateQuality(copy.mesh, threads);
      if (copy.cad) records.geometry = measureGeometryAccuracy(copy.mesh, *copy.cad, threads);
    }
    JsonWriter json;
    json.beginObject();
    appendOptimiser(json, record);
    json.endObject();
    return bp::make_tuple(PyMesh(std::move(copy), std::move(records)), json.str());
  }

  // Immutable, so safe to read without the GIL.
  std::shared_ptr<const CurvedMesh> curved_;
  std::shared_ptr<const StageRecords> records_;
};

// What each front-end function of homesh/api.py takes besides the table's own keys: refinement
// sources (a list of dicts) and a boundary layer (a dict).
enum Extras : unsigned { kNoExtras = 0, kSources = 1, kBoundaryLayer = 2 };

// `base` (the defaults, or a NekMesh case's options) with an options dict keyed as the parameter
// table applied over it (None: not given), checked once by MeshingOptions::apply; `allowed` lists
// the table keys the caller has a use for (empty: all that MeshingOptions holds). Sources are
// added to the base's; a boundary layer replaces the base's.
MeshingOptions optionsFrom(const bp::dict& d, const std::vector<std::string>& allowed,
                           unsigned extras, MeshingOptions base = {}) {
  // The extras this caller takes come out of the dict; the rest are table keys.
  bp::dict table = bp::extract<bp::dict>(bp::object(d).attr("copy")());
  const bp::object none;
  const bp::object sources = (extras & kSources) != 0 ? table.attr("pop")("sources", none) : none;
  const bp::object layer =
      (extras & kBoundaryLayer) != 0 ? table.attr("pop")("boundary_layer", none) : none;
  const OptionMap values = optionMapFrom(table);
  MeshingOptions options = std::move(base);
  options.apply(values, allowed);
  if (!sources.is_none() && bp::len(sources) > 0) {
    if (!options.sizing) options.sizing = SizingParameters{};
    for (RefinementSource& s : sourcesFrom(sources)) options.sizing->sources.push_back(s);
  }
  if (!layer.is_none()) options.boundaryLayer = boundaryLayerFrom(bp::extract<bp::dict>(layer));
  options.validate();
  return options;
}

// The table keys each front-end function uses (MeshingOptions::fromMap refuses the others).
// homesh.mesh: every MeshingOptions key but those of a mesh made elsewhere.
const std::vector<std::string> kMeshKeys = [] {
  std::vector<std::string> keys = MeshingOptions::keys({});
  keys.erase(std::remove(keys.begin(), keys.end(), "classify_tolerance"), keys.end());
  return keys;
}();
const std::vector<std::string> kCurveKeys = [] {
  std::vector<std::string> keys{"threads", "verbosity"};
  keys.insert(keys.end(), kCurveOptionKeys.begin(), kCurveOptionKeys.end());
  return keys;
}();
const std::vector<std::string> kSizingKeys = {"threads",   "heal",      "solids_only",
                                              "surface",   "auto",      "imprint",
                                              "min_delta", "max_delta", "eps"};
const std::vector<std::string> kReadKeys = {"threads", "classify_tolerance"};

// The table keys the front-end function `function` ("mesh", "curve", "sizing": predict and
// size_field, "read", "optimise": HighOrderMesh.optimise) takes, in the table's order, for
// homesh/api.py's keywords and docstrings.
bp::list frontEndKeys(const std::string& function) {
  const std::vector<std::string>* keys = function == "mesh"     ? &kMeshKeys
                                         : function == "curve"  ? &kCurveKeys
                                         : function == "sizing" ? &kSizingKeys
                                         : function == "read"   ? &kReadKeys
                                                                : nullptr;
  if (keys == nullptr && function != "optimise")
    throw ParameterError("option_keys: no function '" + function +
                         "' (mesh, curve, sizing, read or optimise)");
  bp::list out;
  for (const std::string& key :
       keys != nullptr ? MeshingOptions::keys(*keys) : OptimiserOptions::keys())
    out.append(key);
  return out;
}

// The sizing octree and prediction of a CAD source: the JSON report of `homesh predict`,
// and the octree's leaves written to `octreePath` when it is not empty.
std::string predict(const CaseSetup& setup, const bp::dict& given, const std::string& octreePath,
                    const std::string& input) {
  MeshingOptions options = optionsFrom(given, kSizingKeys, kSources, setup.options);
  options.boundaryLayer.reset();  // the prediction is of the sizing alone
  options.octreeOutput = octreePath;
  const ReleaseGil nogil;
  return predictReportJson(runSizingStage(setup.source, options), input);
}

// The sizing octree's leaves that are not outside the model, as arrays: "centre" (L, 3),
// "half_width" (L,), "delta" (L,) and "boundary" (L,) uint8 (1: the boundary passes through the
// leaf), with "predicted_elements". For drawing the size field.
bp::dict sizeField(const std::string& text, const std::string& name, const bp::dict& given) {
  const CadSource source = CadSource::brepText(text, name);
  const MeshingOptions options = optionsFrom(given, kSizingKeys, kSources);
  std::vector<double> centre, half, delta;
  std::vector<std::uint8_t> boundary;
  double predicted = 0.0;
  {
    const ReleaseGil nogil;
    const SizingResult r = runSizingStage(source, options);
    predicted = r.prediction.elements;
    const SizingOctree& octree = *r.octree;
    for (std::size_t i = 0; i < octree.numLeaves(); ++i) {
      const SizingOctree::Leaf leaf = octree.leaf(i);
      if (leaf.location == SizingOctree::Location::Outside) continue;
      centre.insert(centre.end(), leaf.centre.data(), leaf.centre.data() + 3);
      half.push_back(leaf.halfWidth);
      delta.push_back(leaf.delta);
      boundary.push_back(leaf.location == SizingOctree::Location::Boundary ? 1 : 0);
    }
  }
  bp::dict out;
  out["centre"] = toArray(centre, half.size(), 3);
  out["half_width"] = toArray(half, half.size(), 0);
  out["delta"] = toArray(delta, delta.size(), 0);
  out["boundary"] = toArray(boundary, boundary.size(), 0);
  out["predicted_elements"] = predicted;
  return out;
}

// A CAD file or a NekMesh .mcf case (pipeline/case_setup.hpp).
std::string predictFile(const std::string& path, const bp::dict& options,
                        const std::string& octreePath) {
  return predict(setupCase(path), options, octreePath, path);
}

std::string predictBrep(const std::string& text, const std::string& name, const bp::dict& options,
                        const std::string& octreePath) {
  CaseSetup setup;
  setup.source = CadSource::brepText(text, name);
  return predict(setup, options, octreePath, name);
}

// The parameter table (core/parameters.hpp) as a list of dicts: key, property, option, label,
// kind ("integer", "real", "length", "boolean"), min, max (inf: none), min_exclusive, default,
// zero_is_automatic, switchable, group, doc, range (in words).
bp::list parameters() {
  bp::list out;
  for (const ParameterDefinition& p : parameterDefinitions()) {
    bp::dict d;
    d["key"] = p.key;
    d["property"] = p.property;
    d["option"] = p.option;
    d["label"] = p.label;
    d["kind"] = p.kind == ParameterKind::Integer   ? "integer"
                : p.kind == ParameterKind::Length  ? "length"
                : p.kind == ParameterKind::Boolean ? "boolean"
                : p.kind == ParameterKind::Choice  ? "choice"
                                                   : "real";
    d["min"] = p.min;
    d["max"] = p.max;
    d["min_exclusive"] = p.minExclusive;
    d["default"] = p.defaultValue;
    d["zero_is_automatic"] = p.zeroIsAutomatic;
    d["switchable"] = p.switchable;
    d["group"] = p.group;
    d["doc"] = p.doc;
    d["range"] = rangeText(p);
    bp::list choices;
    for (const std::string& name : choiceNames(p)) choices.append(name);
    d["choices"] = choices;
    out.append(d);
  }
  return out;
}

// Whether `value` is in the range of parameter `key` (core/parameters.hpp's inRange).
bool parameterInRange(const std::string& key, double value) {
  try {
    return inRange(parameterDefinition(key), value);
  } catch (const std::out_of_range&) {
    throw ParameterError("no parameter '" + key + "'");
  }
}

// The token behind a `cancel` argument (None or a CancelToken); the caller's argument keeps it
// alive for the call.
const CancelToken* cancelTokenOf(const bp::object& cancel) {
  if (cancel.is_none()) return nullptr;
  bp::extract<const CancelToken&> token(cancel);
  if (!token.check()) throw ParameterError("cancel must be a homesh CancelToken or None");
  return &token();
}

// Runs `run(observer)` (a pipeline returning a MeshResult) with the GIL released, reporting to
// the Python progress callback and honouring the cancel token; a cancel caused by the callback
// raising says so.
template <class Run>
PyMesh runObserved(bp::object progress, const bp::object& cancel, Run run) {
  PythonProgress observer(std::move(progress), cancelTokenOf(cancel));
  std::unique_ptr<MeshResult> result;
  try {
    const ReleaseGil nogil;
    result = std::make_unique<MeshResult>(run(&observer));
  } catch (const CancelledError&) {
    if (!observer.failure().empty()) throw CancelledError(observer.failure());
    throw;
  }
  return PyMesh(std::move(*result));
}

PyMesh runPipeline(const CadSource& source, const MeshingOptions& options, bp::object progress,
                   const bp::object& cancel) {
  return runObserved(std::move(progress), cancel, [&](PipelineObserver* observer) {
    return runMeshPipeline(source, options, observer);
  });
}

// Node coordinates from an (N, 3) array, every one finite.
std::vector<double> finiteNodes(const bp::object& nodes) {
  std::vector<double> xyz = fromArray<double>(nodes, "nodes");
  for (std::size_t k = 0; k < xyz.size(); ++k)
    if (!std::isfinite(xyz[k]))
      throw ParameterError("nodes: node " + std::to_string(k / 3) +
                           " has a coordinate that is not finite");
  return xyz;
}

// A CAD file or a NekMesh .mcf case: a case's CAD, order, sizes and boundary layer are used
// where the options do not say otherwise.
PyMesh meshFile(const std::string& path, const bp::dict& options, bp::object progress,
                const bp::object& cancel) {
  const CaseSetup setup = setupCase(path);
  return runPipeline(setup.source,
                     optionsFrom(options, kMeshKeys, kSources | kBoundaryLayer, setup.options),
                     std::move(progress), cancel);
}

PyMesh meshBrep(const std::string& text, const std::string& name, const bp::dict& options,
                bp::object progress, const bp::object& cancel) {
  return runPipeline(CadSource::brepText(text, name),
                     optionsFrom(options, kMeshKeys, kSources | kBoundaryLayer),
                     std::move(progress), cancel);
}

// Curves a linear volume (or planar 2D) mesh made elsewhere on the CAD of `source` (BRep text or
// a CAD file): pipeline's curveMeshOnCad. nodes (N, 3); cells: {"tet": (E, 4), "prism": (E, 6),
// "pyramid": (E, 5), "hex": (E, 8)} or, in 2D, {"tri": (E, 3), "quad": (E, 4)}, 0-based corner
// nodes in Gmsh's order (api.curve checks the keys).
PyMesh curveOnCad(const CadSource& source, const bp::object& nodes, const bp::dict& cells,
                  const bp::dict& given, bp::object progress, const bp::object& cancel) {
  const MeshingOptions options = optionsFrom(given, kCurveKeys, kNoExtras);
  Mesh linear;
  linear.dim = 3;  // 2 once a 2D array holds cells (below)
  linear.order = 1;
  linear.xyz = finiteNodes(nodes);
  if (linear.xyz.size() % 3 != 0) throw ParameterError("nodes must be an (N, 3) array");
  for (const CellType type : {CellType::Tetrahedron, CellType::Prism, CellType::Pyramid,
                              CellType::Hexahedron, CellType::Triangle, CellType::Quadrilateral}) {
    const std::string name = cellShortName(type);
    if (!cells.has_key(name)) continue;
    ElementBlock block;
    block.type = type;
    const std::string what = name + " cells";
    block.nodes = fromArray<std::int64_t>(cells[name], what.c_str());
    const auto corners = static_cast<std::size_t>(cellNumVertices(type));
    if (block.nodes.size() % corners != 0)
      throw ParameterError(name + " cells must be an (E, " + std::to_string(corners) + ") array");
    block.entity.assign(block.nodes.size() / corners, 1);
    linear.blocks.push_back(std::move(block));
  }
  bool planar = false, solid = false;
  for (const ElementBlock& b : linear.blocks) {
    (cellDimension(b.type) == 2 ? planar : solid) |= b.count() > 0;
    for (const std::int64_t id : b.nodes)
      if (id < 0 || static_cast<std::size_t>(id) >= linear.numNodes())
        throw ParameterError(cellShortName(b.type) + " cells refer to node " + std::to_string(id) +
                             ", outside the " + std::to_string(linear.numNodes()) + " nodes");
  }
  if (planar && solid)
    throw ParameterError("cells: 2D cells (tri, quad) and volume cells cannot be curved together");
  if (planar) linear.dim = 2;
  const std::size_t n = linear.numNodes();
  linear.nodeCadDim.assign(n, static_cast<std::uint8_t>(linear.dim));
  linear.nodeCadIndex.assign(n, 0);
  linear.nodeCadParam.assign(2 * n, std::numeric_limits<double>::quiet_NaN());
  if (linear.dim == 2)  // its plane, as the mesh readers find it (zero: on curved faces)
    if (const auto normal = planeOfCells(linear, 1e-5)) linear.planeNormal = *normal;
  return runObserved(std::move(progress), cancel, [&](PipelineObserver* observer) {
    return curveMeshOnCad(source, linear, options, observer);
  });
}

PyMesh curveBrep(const std::string& text, const std::string& name, const bp::object& nodes,
                 const bp::dict& cells, const bp::dict& options, bp::object progress,
                 const bp::object& cancel) {
  return curveOnCad(CadSource::brepText(text, name), nodes, cells, options, std::move(progress),
                    cancel);
}

PyMesh curveFile(const std::string& path, const bp::object& nodes, const bp::dict& cells,
                 const bp::dict& options, bp::object progress, const bp::object& cancel) {
  return curveOnCad(CadSource::file(path), nodes, cells, options, std::move(progress), cancel);
}

// Rebuilds a mesh (without CAD) from the arrays PyMesh exposes, and evaluates its quality.
// blocks: [(type name, order, connectivity, entity), ...] as returned by PyMesh.blocks().
PyMesh meshFromArrays(int dim, int order, const bp::object& nodes, const bp::object& cadDim,
                      const bp::object& cadIndex, const bp::object& cadParams,
                      const bp::list& blocks, const bp::tuple& normal,
                      const std::string& numbering) {
  CurvedMesh curved;
  Mesh& mesh = curved.mesh;
  mesh.dim = dim;
  mesh.order = order;
  if (dim != 2 && dim != 3) throw ParameterError("dim must be 2 or 3");
  if (bp::len(normal) != 3) throw ParameterError("plane normal needs 3 components");
  for (int k = 0; k < 3; ++k) mesh.planeNormal[k] = bp::extract<double>(normal[k]);
  mesh.xyz = finiteNodes(nodes);
  mesh.nodeCadDim = fromArray<std::uint8_t>(cadDim, "node_cad_dim");
  mesh.nodeCadIndex = fromArray<std::int32_t>(cadIndex, "node_cad_index");
  mesh.nodeCadParam = fromArray<double>(cadParams, "node_cad_params");
  for (bp::ssize_t i = 0; i < bp::len(blocks); ++i) {
    const bp::tuple b = bp::extract<bp::tuple>(blocks[i]);
    ElementBlock block;
    block.type = cellTypeFromName(bp::extract<std::string>(b[0]));
    block.order = bp::extract<int>(b[1]);
    block.nodes = fromArray<std::int64_t>(b[2], "connectivity");
    block.entity = fromArray<std::int32_t>(b[3], "entity");
    mesh.blocks.push_back(std::move(block));
  }
  mesh.checkConsistency();
  curved.quality = evaluateQuality(mesh);
  StageRecords records;
  records.options.order = order;
  if (!numbering.empty()) records.healing.numbering = NumberingMap::fromText(numbering);
  return {std::move(curved), std::move(records)};
}

// Reads a mesh file (.msh, .xml) and evaluates its quality.
PyMesh readMeshFile(const std::string& path, const std::string& cad, const bp::dict& given) {
  const MeshingOptions options = MeshingOptions::fromMap(optionMapFrom(given), kReadKeys);
  CurvedMesh curved;
  StageRecords records;
  {
    const ReleaseGil nogil;
    curved.mesh = readMesh(path, &records.notes);
    curved.quality = evaluateQuality(curved.mesh, options.threads);
    if (!cad.empty())
      records.geometry =
          checkGeometryAgainstCad(curved.mesh, cad, options.threads, options.classifyTolerance);
  }
  records.options.order = curved.mesh.order;
  return {std::move(curved), std::move(records)};
}

// Reference coordinates (equispaced, Gmsh order) of the nodes of (type, order): (nodes x dim).
np::ndarray referenceNodes(const std::string& type, int order) {
  const ReferenceElement& ref = ReferenceElement::get(cellTypeFromName(type), order);
  std::vector<double> xi;
  for (int n = 0; n < ref.numNodes(); ++n)
    for (int k = 0; k < ref.dim(); ++k) xi.push_back(ref.nodes()(n, k));
  return toArray(xi, static_cast<std::size_t>(ref.numNodes()), static_cast<std::size_t>(ref.dim()));
}

// A quadrature rule of the given degree on the reference shape: (points (n x dim), weights).
bp::tuple quadrature(const std::string& type, int degree) {
  const QuadratureRule rule = quadratureRule(cellTypeFromName(type), degree);
  return bp::make_tuple(toArray(rule.points, static_cast<std::size_t>(rule.size()),
                                static_cast<std::size_t>(rule.dim)),
                        toArray(rule.weights, static_cast<std::size_t>(rule.size()), 0));
}

// Values of the Lagrange basis of (type, order) at reference points (npts x dim):
// returns (npts x numNodes), nodes in Gmsh order. Used to draw curved elements.
np::ndarray lagrangeBasis(const std::string& type, int order, const bp::object& points) {
  const ReferenceElement& ref = ReferenceElement::get(cellTypeFromName(type), order);
  const std::vector<double> xi = fromArray<double>(points, "points");
  const auto dim = static_cast<std::size_t>(ref.dim());
  if (xi.size() % dim != 0)
    throw ParameterError("points must have " + std::to_string(dim) + " coordinates each");
  const std::size_t npts = xi.size() / dim;
  std::vector<double> out(npts * ref.numNodes());
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  for (std::size_t i = 0; i < npts; ++i) {
    ref.evaluate(&xi[i * dim], values, gradients);
    for (int n = 0; n < ref.numNodes(); ++n) out[i * ref.numNodes() + n] = values(n);
  }
  return toArray(out, npts, ref.numNodes());
}

}  // namespace
}  // namespace homesh

BOOST_PYTHON_MODULE(_core) {
  using namespace homesh;
  np::initialize();
  bp::scope().attr("__version__") = kVersion;

  gBaseError = makeException("HOMeshError", PyExc_RuntimeError, "Base of all HOMesh errors.");
  gParameterError = makeException("ParameterError",
                                  bp::make_tuple(bp::handle<>(bp::borrowed(gBaseError)),
                                                 bp::handle<>(bp::borrowed(PyExc_ValueError)))
                                      .ptr(),
                                  "A parameter is out of range (order, size, ...).");
  gCadError = makeException("CadError", gBaseError, "The CAD model cannot be read or meshed.");
  gMeshingError = makeException("MeshingError", gBaseError, "The mesher failed.");
  gFileError = makeException("FileError",
                             bp::make_tuple(bp::handle<>(bp::borrowed(gBaseError)),
                                            bp::handle<>(bp::borrowed(PyExc_OSError)))
                                 .ptr(),
                             "A file is missing, unreadable or cannot be written.");
  gCancelledError = makeException("CancelledError", gBaseError, "The job was cancelled.");
  registerTranslator<Error>(gBaseError);
  registerTranslator<ParameterError>(gParameterError);
  registerTranslator<CadError>(gCadError);
  registerTranslator<MeshingError>(gMeshingError);
  registerTranslator<IoError>(gFileError);
  registerTranslator<CancelledError>(gCancelledError);

  bp::class_<CancelToken, boost::noncopyable>(
      "CancelToken",
      "Pass as mesh(..., cancel=token); token.cancel() from any thread stops the job within a "
      "fraction of a second (CancelledError)")
      .def("cancel", &CancelToken::cancel)
      .add_property("cancelled", &CancelToken::cancelled);

  bp::class_<PyMesh>("Mesh", bp::no_init)
      .add_property("order", &PyMesh::order)
      .add_property("dim", &PyMesh::dim)
      .add_property("num_nodes", &PyMesh::numNodes)
      .add_property("num_elements", &PyMesh::numElements)
      .add_property("has_cad", &PyMesh::hasCad)
      .add_property("plane_normal", &PyMesh::planeNormal)
      .def("nodes", &PyMesh::nodes)
      .def("node_cad_dim", &PyMesh::nodeCadDim)
      .def("node_cad_index", &PyMesh::nodeCadIndex)
      .def("node_cad_params", &PyMesh::nodeCadParams)
      .def("blocks", &PyMesh::blocks)
      .def("scaled_jacobian", &PyMesh::scaledJacobian)
      .def("distortion", &PyMesh::distortion)
      .def("scaled_jacobian_upper", &PyMesh::scaledJacobianUpper)
      .def("validity", &PyMesh::validity)
      .def("quality_summary", &PyMesh::qualitySummary)
      .def("timings", &PyMesh::timings)
      .def("write", &PyMesh::write,
           (bp::arg("path"), bp::arg("binary") = false, bp::arg("compressed") = false,
            bp::arg("groups") = bp::list()))
      .def("element_volumes", &PyMesh::elementVolumes)
      .def("report_json", &PyMesh::reportJson)
      .def("summary_lines", &PyMesh::summaryLines)
      .def("headline", &PyMesh::headline)
      .def("numbering_text", &PyMesh::numberingText)
      .def("optimise", &PyMesh::optimise, (bp::arg("options")));

  bp::def("mesh_file", &meshFile,
          (bp::arg("path"), bp::arg("options"), bp::arg("progress") = bp::object(),
           bp::arg("cancel") = bp::object()));
  bp::def("mesh_brep", &meshBrep,
          (bp::arg("text"), bp::arg("name"), bp::arg("options"), bp::arg("progress") = bp::object(),
           bp::arg("cancel") = bp::object()));
  bp::def("predict_file", &predictFile,
          (bp::arg("path"), bp::arg("options"), bp::arg("octree_path") = ""));
  bp::def("predict_brep", &predictBrep,
          (bp::arg("text"), bp::arg("name"), bp::arg("options"), bp::arg("octree_path") = ""));
  bp::def("parameters", &parameters);
  bp::def("option_keys", &frontEndKeys, (bp::arg("function")));
  bp::def("parameter_in_range", &parameterInRange, (bp::arg("key"), bp::arg("value")));
  bp::def("curve_brep", &curveBrep,
          (bp::arg("text"), bp::arg("name"), bp::arg("nodes"), bp::arg("cells"), bp::arg("options"),
           bp::arg("progress") = bp::object(), bp::arg("cancel") = bp::object()));
  bp::def("curve_file", &curveFile,
          (bp::arg("path"), bp::arg("nodes"), bp::arg("cells"), bp::arg("options"),
           bp::arg("progress") = bp::object(), bp::arg("cancel") = bp::object()));
  bp::def("size_field", &sizeField, (bp::arg("text"), bp::arg("name"), bp::arg("options")));
  bp::def("read_mesh", &readMeshFile, (bp::arg("path"), bp::arg("cad"), bp::arg("options")));
  bp::def("quadrature_rule", &quadrature, (bp::arg("type"), bp::arg("degree")));
  bp::def("reference_nodes", &referenceNodes, (bp::arg("type"), bp::arg("order")));
  bp::def("lagrange_basis", &lagrangeBasis, (bp::arg("type"), bp::arg("order"), bp::arg("points")));
  bp::def("mesh_from_arrays", &meshFromArrays,
          (bp::arg("dim"), bp::arg("order"), bp::arg("nodes"), bp::arg("node_cad_dim"),
           bp::arg("node_cad_index"), bp::arg("node_cad_params"), bp::arg("blocks"),
           bp::arg("plane_normal"), bp::arg("numbering") = std::string()));
}
