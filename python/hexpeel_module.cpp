// _hexpeel: the compiled part of the Python package `hexpeel` (python/hexpeel/__init__.py wraps
// it). numpy arrays in and out; reports as Python dicts (the JSON of the CLI); every problem is a
// hexpeel.Error (a ValueError) with the CLI's message and the status code's name as `code`.
#include "hexpeel/chords.h"
#include "hexpeel/diagnosis.h"
#include "hexpeel/validation.h"
#include "hexpeel/pipeline.h"
#include "hexpeel/quality.h"
#include "hexpeel/status.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <tbb/global_control.h>

#include <cmath>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace py = pybind11;

namespace {

using namespace hexpeel;

/// hexpeel.Error, created at import (a strong reference kept for the life of the process).
PyObject* g_error = nullptr;

/// Thrown inside the bindings; turned into hexpeel.Error by the registered translator.
struct HexpeelError {
  std::string code;
  std::string message;  ///< full text, "code: message" as the CLI prints it
  py::object report;    ///< the mesh report of a failed run, or None
};

[[noreturn]] void fail(const Status& s, py::object report = py::none()) {
  throw HexpeelError{std::string(to_string(s.code)), to_string(s), std::move(report)};
}
/// Problems with the arguments themselves (shapes, dtypes): code "invalid_argument".
[[noreturn]] void fail_argument(const std::string& msg) {
  throw HexpeelError{"invalid_argument", "invalid_argument: " + msg, py::none()};
}

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) {
    if (i) s += ", ";
    s += std::to_string(a.shape(i));
  }
  if (a.ndim() == 1) s += ",";
  return s + ")";
}

std::string dtype_text(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

/// Any array-like as a numpy array (lists of lists included); non-arrays are an error.
py::array as_array(const py::object& obj, const char* name) {
  py::array a;
  try {
    a = py::module_::import("numpy").attr("asarray")(obj);
  } catch (py::error_already_set&) {
    fail_argument(std::string(name) + " cannot be converted to a numpy array");
  }
  return a;
}

/// (N, 3) real coordinates as C-contiguous float64 (converted when needed).
std::vector<Vec3> read_points(const py::object& obj, const char* name = "points") {
  py::array a = as_array(obj, name);
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    fail_argument(std::string(name) + " must be an array of real numbers (float64), got dtype " +
                  dtype_text(a));
  if (a.ndim() != 2 || a.shape(1) != 3)
    fail_argument(std::string(name) + " must have shape (N, 3), got shape " + shape_text(a));
  auto p = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!p) fail_argument(std::string(name) + " cannot be converted to float64");
  const py::ssize_t n = p.shape(0);
  if (n > INT32_MAX) fail_argument(std::string(name) + ": too many points");
  std::vector<Vec3> out(static_cast<size_t>(n));
  auto r = p.unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) out[i] = Vec3(r(i, 0), r(i, 1), r(i, 2));
  return out;
}

/// (M, k) vertex ids, 0-based, each in [0, n): as int32 rows. `code` names out-of-range ids.
std::vector<int32_t> read_cells(const py::object& obj, int k, int64_t n, const char* name,
                                const char* what, StatusCode code) {
  py::array a = as_array(obj, name);
  const char kind = a.dtype().kind();
  if (a.size() == 0 && a.ndim() == 1) {
    return {};  // an empty list: no cells (reported as empty by the caller)
  }
  if (kind != 'i' && kind != 'u')
    fail_argument(std::string(name) + " must be an array of integers (vertex ids), got dtype " +
                  dtype_text(a));
  if (a.ndim() != 2 || a.shape(1) != k) {
    if (k == 4 && a.ndim() == 2 && a.shape(1) > 0)
      fail(Status::error(StatusCode::non_quad_face,
                         std::string(name) + " has " + std::to_string(a.shape(1)) +
                             " corners per face: every face must be a quad, shape (M, 4)"));
    fail_argument(std::string(name) + " must have shape (" + (k == 8 ? "H" : "M") + ", " +
                  std::to_string(k) +
                  "), got shape " + shape_text(a));
  }
  if (a.shape(0) > INT32_MAX / k) fail_argument(std::string(name) + ": too many cells");
  // int64 holds every id of any signed type; uint64 ids above INT64_MAX are out of range anyway
  // and come out negative (numpy's wrap-around cast), which is reported the same way.
  auto c = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!c) fail_argument(std::string(name) + " cannot be converted to int64");
  const py::ssize_t m = c.shape(0);
  std::vector<int32_t> out;
  out.reserve(static_cast<size_t>(m) * k);
  auto r = c.unchecked<2>();
  for (py::ssize_t i = 0; i < m; ++i) {
    for (int j = 0; j < k; ++j) {
      const int64_t v = r(i, j);
      if (v < 0 || v >= n)
        fail(Status::error(code, std::string(what) + " " + std::to_string(i) + " corner " +
                                     std::to_string(j) + " refers to vertex " +
                                     std::to_string(v) + " but only " + std::to_string(n) +
                                     " vertices exist (ids are 0-based)"));
      out.push_back(static_cast<int32_t>(v));
    }
  }
  return out;
}

PolygonSoup read_soup(const py::object& points, const py::object& quads) {
  PolygonSoup soup;
  soup.points = read_points(points);
  std::vector<int32_t> ids = read_cells(quads, 4, static_cast<int64_t>(soup.points.size()),
                                        "quads", "quad", StatusCode::index_out_of_range);
  if (ids.empty()) fail(Status::error(StatusCode::empty_mesh, "the surface has no quads"));
  soup.indices = std::move(ids);
  const int32_t m = static_cast<int32_t>(soup.indices.size() / 4);
  soup.offsets.resize(static_cast<size_t>(m) + 1);
  for (int32_t f = 0; f <= m; ++f) soup.offsets[f] = 4 * f;
  return soup;
}

void check_sharp_angle(double deg) {
  if (!(deg > 0.0 && deg < 180.0))
    fail_argument("sharp_angle must be in (0, 180) degrees, got " + std::to_string(deg));
}

/// nlohmann::json -> Python objects (through the json module: exact, and NaN comes out null).
py::object to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

/// Warnings the library logged while the GIL was released, issued as Python UserWarnings.
struct Warnings {
  std::vector<std::string> messages;
  Context context() {
    Context ctx;
    ctx.log = [this](LogLevel level, std::string_view msg) {
      if (level == LogLevel::warning) messages.emplace_back(msg);
    };
    return ctx;
  }
  void issue() const {
    for (const std::string& m : messages)
      if (PyErr_WarnEx(PyExc_UserWarning, ("hexpeel: " + m).c_str(), 2) != 0)
        throw py::error_already_set();
  }
};

/// Library exceptions (a broken invariant, out of memory) as hexpeel.Error with internal_error.
template <typename F>
auto guarded(F&& f) {
  try {
    return f();
  } catch (const std::bad_alloc&) {
    throw;  // MemoryError
  } catch (const std::logic_error& e) {
    fail(Status::error(StatusCode::internal_error, e.what()));
  }
}

std::unique_ptr<tbb::global_control> thread_limit(int threads) {
  if (threads < 0 || threads > 1024) fail_argument("threads must be in [0, 1024] (0 = one per core)");
  if (threads == 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               static_cast<size_t>(threads));
}

py::tuple mesh(const py::object& points, const py::object& quads, double sharp_angle,
               double plan_budget, int threads, bool repair_surface, const std::string& repair_fill) {
  check_sharp_angle(sharp_angle);
  if (!(plan_budget >= 0.0) || !std::isfinite(plan_budget))
    fail_argument("plan_budget must be a finite number >= 0");
  PolygonSoup soup = read_soup(points, quads);
  MeshParams params;
  params.sharp_angle_deg = sharp_angle;
  params.planner.budget_s = plan_budget;
  params.repair_surface = repair_surface;
  if (repair_fill == "tets") params.repair_fill = MeshParams::RepairFill::tets;
  else if (repair_fill == "elimination") params.repair_fill = MeshParams::RepairFill::elimination;
  else if (repair_fill == "both") params.repair_fill = MeshParams::RepairFill::both;
  else fail_argument("repair_fill must be 'tets', 'elimination' or 'both', got '" + repair_fill + "'");
  Warnings warnings;
  MeshResult r;
  {
    auto limit = thread_limit(threads);
    Context ctx = warnings.context();
    py::gil_scoped_release release;
    r = guarded([&] { return run_mesh(soup, params, ctx); });
  }
  warnings.issue();
  nlohmann::json j = to_json(r);
  // The budgets, passes and retries this run used, as in the CLI's --report.
  j["params"] = effort_to_json(params);
  py::object report = to_python(j);
  if (!r.status.ok()) fail(r.status, report);

  const HexMesh& m = r.mesh;
  py::array_t<double> pts({static_cast<py::ssize_t>(m.points.size()), py::ssize_t{3}});
  auto pw = pts.mutable_unchecked<2>();
  for (size_t i = 0; i < m.points.size(); ++i)
    for (int k = 0; k < 3; ++k) pw(i, k) = m.points[i][k];
  py::array_t<int32_t> hexes({static_cast<py::ssize_t>(m.hexes.size()), py::ssize_t{8}});
  auto hw = hexes.mutable_unchecked<2>();
  for (size_t i = 0; i < m.hexes.size(); ++i)
    for (int k = 0; k < 8; ++k) hw(i, k) = m.hexes[i][k];
  return py::make_tuple(pts, hexes, report);
}

py::object check(const py::object& points, const py::object& quads, double sharp_angle) {
  check_sharp_angle(sharp_angle);
  PolygonSoup soup = read_soup(points, quads);
  Warnings warnings;
  SurfaceDiagnosis d;
  {
    Context ctx = warnings.context();
    py::gil_scoped_release release;
    d = guarded([&] { return diagnose_surface(soup, sharp_angle, ctx); });
  }
  warnings.issue();
  return to_python(to_json(d));
}

py::array_t<int32_t> patches(const py::object& points, const py::object& quads, double sharp_angle) {
  check_sharp_angle(sharp_angle);
  PolygonSoup soup = read_soup(points, quads);
  ValidationParams vp;
  vp.allow_odd = true;  // patches need a closed oriented surface, not a meshable one
  ValidationResult v = run_validation(soup, vp);
  if (!v.status.ok()) fail(v.status);
  const QuadSurface& s = v.surface;  // quads in input order (some reversed to agree)
  const QuadAdjacency adj = build_adjacency(s);
  int32_t count = 0;
  const std::vector<int32_t> patch = sharp_patches(s, adj, classify_edges(s, adj, sharp_angle), count);
  py::array_t<int32_t> out(static_cast<py::ssize_t>(patch.size()));
  auto w = out.mutable_unchecked<1>();
  for (size_t i = 0; i < patch.size(); ++i) w(i) = patch[i];
  return out;
}

py::object quality(const py::object& points, const py::object& hexes) {
  HexMesh mesh;
  mesh.points = read_points(points);
  std::vector<int32_t> ids = read_cells(hexes, 8, static_cast<int64_t>(mesh.points.size()),
                                        "hexes", "hex", StatusCode::invalid_mesh);
  mesh.hexes.resize(ids.size() / 8);
  for (size_t h = 0; h < mesh.hexes.size(); ++h)
    for (int k = 0; k < 8; ++k) mesh.hexes[h][k] = ids[8 * h + k];
  QualityReport q;
  {
    py::gil_scoped_release release;
    q = guarded([&] { return run_quality(mesh); });
  }
  return to_python(to_json(q));
}

}  // namespace

PYBIND11_MODULE(_hexpeel, m) {
  py::options options;
  options.disable_function_signatures();  // the docstrings carry them (inspect.signature too)
  m.doc() = "Compiled core of the hexpeel package (use `import hexpeel`).";

  g_error = PyErr_NewExceptionWithDoc(
      "hexpeel.Error",
      "A hexpeel failure: bad input or a meshing failure.\n\n"
      "str(e) is the message the command-line tool prints after 'hexpeel: error: '.\n"
      "Attributes:\n"
      "  code   -- the status code's name, e.g. 'odd_quad_count', 'nonzero_genus',\n"
      "            'index_out_of_range', 'stuck'; 'invalid_argument' for arrays of the\n"
      "            wrong shape or dtype and options out of range.\n"
      "  report -- for a failed hexpeel.mesh: the report dict (as --report writes it);\n"
      "            None otherwise.",
      PyExc_ValueError, nullptr);
  if (g_error == nullptr) throw py::error_already_set();
  PyObject_SetAttrString(g_error, "code", Py_None);
  PyObject_SetAttrString(g_error, "report", Py_None);
  m.attr("Error") = py::handle(g_error);  // the module's reference plus our own in g_error

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const HexpeelError& e) {
      py::object err = py::reinterpret_borrow<py::object>(g_error)(e.message);
      err.attr("code") = e.code;
      err.attr("report") = e.report;
      PyErr_SetObject(g_error, err.ptr());
    }
  });

  m.def("mesh", &mesh, py::arg("points"), py::arg("quads"), py::kw_only(),
        py::arg("sharp_angle") = 60.0, py::arg("plan_budget") = 30.0, py::arg("threads") = 0,
        py::arg("repair_surface") = false, py::arg("repair_fill") = "tets",
        "mesh(points, quads, *, sharp_angle=60.0, plan_budget=30.0, threads=0,\n"
        "     repair_surface=False, repair_fill='tets')\n--\n\n"
        "-> (points, hexes, report)\n\n"
        "Fills a closed genus-0 all-quad surface with hexahedra (as `hexpeel mesh`).\n\n"
        "points: (N, 3) float64 vertex coordinates; quads: (M, 4) integer 0-based vertex ids.\n"
        "Returns the points (P, 3) float64 (the N input vertices first, in input order),\n"
        "the hexes (H, 8) int32 in VTK_HEXAHEDRON corner order, and the report dict (the\n"
        "JSON of `hexpeel mesh --report`). A mesh with inverted hexes is returned too:\n"
        "report['scaled_jacobian']['count_nonpositive'] > 0 says so (the CLI's exit 5).\n"
        "sharp_angle: degrees from flat above which an edge is sharp, in (0, 180);\n"
        "plan_budget: budget of the elimination-order search (deterministic work units);\n"
        "threads: at most this many threads (0 = one per core); the result is the same.\n"
        "repair_surface: refine a surface with self-crossing chords or an odd count and\n"
        "mesh that (`--repair-surface`): the hexes' boundary is the refined surface, the\n"
        "input vertices come first; report['repair'] says what changed.\n"
        "repair_fill: how (`--repair-fill`): 'tets' (the surface split into six, filled\n"
        "through tetrahedra), 'elimination' or 'both' (the better mesh kept).\n"
        "The GIL is released while meshing. Raises hexpeel.Error.");
  m.def("check", &check, py::arg("points"), py::arg("quads"), py::kw_only(),
        py::arg("sharp_angle") = 60.0,
        "check(points, quads, *, sharp_angle=60.0)\n--\n\n-> dict\n\n"
        "Diagnoses a surface: the JSON of `hexpeel check --json` as a dict. An invalid\n"
        "surface is not an error: d['status'] names the problem.\n"
        "Raises hexpeel.Error only for arrays that are not a surface at all (shape, dtype,\n"
        "ids out of range, no quads).");
  m.def("patches", &patches, py::arg("points"), py::arg("quads"), py::kw_only(),
        py::arg("sharp_angle") = 60.0,
        "patches(points, quads, *, sharp_angle=60.0)\n--\n\n-> (M,) int32\n\n"
        "The surface cut along its sharp edges (bent more than sharp_angle degrees from\n"
        "flat) into patches, as a CAD part's faces: the 0-based patch of every quad, numbered\n"
        "in the order of each patch's first quad (`hexpeel mesh --patch-sets`).\n"
        "Raises hexpeel.Error for a surface `hexpeel check` refuses (open, non-manifold,\n"
        "not a sphere, ...), an odd quad count aside.");
  m.def("quality", &quality, py::arg("points"), py::arg("hexes"),
        "quality(points, hexes)\n--\n\n-> dict\n\n"
        "Scaled Jacobian and topology of a hex mesh, as `hexpeel quality --json`.\n"
        "points: (P, 3) float64; hexes: (H, 8) integer 0-based ids in VTK corner order.\n"
        "Raises hexpeel.Error (code 'invalid_mesh' for ids out of range).");
}
