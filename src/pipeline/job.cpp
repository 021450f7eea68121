// The job model: parsing and validation, section by section (see job.h). The
// "optimization" section is in job_optimization.cpp.
#include "pipeline/job.h"

#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "common/error.h"
#include "io/json_text.h"
#include "pipeline/job_fields.h"

namespace topopt::pipeline {
namespace fs = std::filesystem;
using nlohmann::json;

/// The "optimization" section (job_optimization.cpp).
OptimizeSettings parse_optimization(const json& section);

namespace {

std::string resolve(const std::string& p, const std::string& base) {
  if (p.empty()) return p;
  fs::path path(p);
  if (path.is_relative() && !base.empty()) path = fs::path(base) / path;
  return path.lexically_normal().string();
}

/// The faces of a support or load: a non-empty list of face names.
void faces_of(const Fields& f, std::vector<int>& faces, std::vector<int>& nondesign) {
  const std::string form = "must be a non-empty list of face names such as [\"Face3\"]";
  if (!f.has("faces") || !f.at("faces").is_array() || f.at("faces").empty()) f.bad("faces", form);
  for (const auto& name : f.at("faces")) {
    if (!name.is_string()) f.bad("faces", form);
    parse_face_name(name.get<std::string>(), faces, nondesign);
  }
}

MeshSettings parse_mesh(const json& section, const std::string& base_dir) {
  const Fields f(section, "mesh", {"size", "min_size", "mesher", "wall_layers", "file"}, "{\"size\": 2.0}");
  MeshSettings m;
  m.size = f.number("size", 0);
  m.min_size = f.number("min_size", 0);
  m.wall_layers = f.integer("wall_layers", 0, 0, 4);
  m.mesher = mesher_from_name(
      f.choice("mesher", "auto", {"auto", "native", "gmsh"},
               "native: the two-B-Rep advancing front; gmsh: Gmsh's OCC fragments; auto: native, Gmsh where it fails"));
  m.file = resolve(f.text("file", ""), base_dir);
  check_mesh_settings(m, "'mesh.size'", "'mesh.min_size'");
  return m;
}

fem::Material parse_material(const json& section) {
  const Fields f(section, "material", {"E", "nu", "density"}, "{\"E\": 210000, \"nu\": 0.3}");
  fem::Material m;
  m.young = f.number("E", m.young);
  m.poisson = f.number("nu", m.poisson);
  m.density = f.number("density", m.density);
  if (!(m.young > 0 && m.young <= 1e9))
    f.bad("E", "must be a Young's modulus in MPa, above 0 and at most 1e9 (steel: 210000)");
  if (!(m.poisson > -1 && m.poisson < 0.5)) f.bad("nu", "must lie in (-1, 0.5) (steel: 0.3)");
  if (!(m.density >= 0 && m.density <= 1e-3)) f.bad("density", "must be a density in t/mm³ (steel: 7.85e-9)");
  return m;
}

fem::SupportSpec parse_support(const json& item, const std::string& where) {
  const Fields f(item, where, {"type", "faces", "fix"}, "{\"type\": \"fixed\", \"faces\": [\"Face3\"]}");
  fem::SupportSpec spec;
  const std::string type = f.choice("type", "fixed", {"fixed", "components", "symmetry"});
  if (type != "components" && f.has("fix")) f.bad("fix", "only goes with \"type\": \"components\"");
  if (type == "symmetry") spec.kind = fem::SupportSpec::Kind::Symmetry;
  if (type == "components") {
    spec.kind = fem::SupportSpec::Kind::Components;
    spec.fix = {false, false, false};
    const std::string form = "must list the fixed components, e.g. [\"x\", \"z\"]";
    if (!f.has("fix") || !f.at("fix").is_array() || f.at("fix").empty()) f.bad("fix", form);
    for (const auto& c : f.at("fix")) {
      const std::string axis = c.is_string() ? c.get<std::string>() : "";
      if (axis != "x" && axis != "y" && axis != "z") f.bad("fix", form);
      spec.fix[axis[0] - 'x'] = true;
    }
  }
  faces_of(f, spec.faces, spec.nd_faces);
  return spec;
}

/// |v| checked against a limit in the unit the key is in.
void check_magnitude(const Fields& f, const std::string& key, double magnitude, double limit, const std::string& unit) {
  if (magnitude > limit) {
    std::ostringstream m;
    m << "has a magnitude of " << magnitude << " " << unit << ", more than any part can carry (at most " << limit << " "
      << unit << "): give it in " << unit;
    f.bad(key, m.str());
  }
}

fem::LoadSpec parse_load(const json& item, const std::string& where) {
  const Fields f(item, where, {"type", "faces", "vector", "value"},
                 "{\"type\": \"force\", \"faces\": [\"Face7\"], \"vector\": [0, -1000, 0]}");
  fem::LoadSpec spec;
  const std::string type = f.choice("type", "force", {"force", "pressure", "gravity"});
  if (type != "pressure" && f.has("value")) f.bad("value", "only goes with \"type\": \"pressure\"");
  if (type == "pressure" && f.has("vector"))
    f.bad("vector", "does not go with \"type\": \"pressure\" (give its \"value\" in MPa)");
  if (type == "gravity" && f.has("faces")) f.bad("faces", "does not go with gravity: it acts on the whole part");
  if (type == "pressure") {
    spec.kind = fem::LoadSpec::Kind::Pressure;
    if (!f.has("value")) f.bad("value", "must give the pressure in MPa (positive pushes into the part)");
    spec.value = f.number("value", 0);
    check_magnitude(f, "value", std::abs(spec.value), LoadLimits::kPressure, "MPa");
  } else {
    spec.kind = type == "force" ? fem::LoadSpec::Kind::Force : fem::LoadSpec::Kind::Gravity;
    spec.vector = f.vec3("vector");
    const double norm = std::hypot(spec.vector[0], spec.vector[1], spec.vector[2]);
    if (type == "force") check_magnitude(f, "vector", norm, LoadLimits::kForce, "N");
    if (type == "gravity") check_magnitude(f, "vector", norm, LoadLimits::kGravity, "mm/s²");
  }
  if (type != "gravity") faces_of(f, spec.faces, spec.nd_faces);
  return spec;
}

fem::LoadCase parse_load_case(const json& item, int i) {
  const std::string where = "load_cases[" + std::to_string(i) + "]";
  const Fields f(item, where, {"name", "weight", "loads"}, "{\"name\": \"pull\", \"loads\": [...]}");
  fem::LoadCase lc;
  lc.name = f.text("name", "case" + std::to_string(i + 1));
  lc.weight = f.number("weight", 1.0);
  if (!(lc.weight > 0)) f.bad("weight", "must be positive (the case's share in the objective)");
  if (!f.has("loads") || !f.at("loads").is_array() || f.at("loads").empty())
    f.bad("loads", "must be a non-empty list of loads");
  int k = 0;
  for (const auto& l : f.at("loads"))
    lc.items.push_back(parse_load(l, f.name("loads") + "[" + std::to_string(k++) + "]"));
  return lc;
}

OutputSettings parse_output(const json& section, const std::string& base_dir) {
  const Fields f(section, "output", {"directory", "vtu", "inp", "step", "step_max_triangles", "verification"}, "{\"directory\": \"out\"}");
  OutputSettings o;
  const std::string dir = f.text("directory", "out");
  if (dir.empty()) f.bad("directory", "must name a folder (relative to the job file's folder)");
  o.directory = resolve(dir, base_dir.empty() ? fs::current_path().string() : base_dir);
  o.vtu = f.boolean("vtu", o.vtu);
  o.inp = f.boolean("inp", o.inp);
  o.step = f.boolean("step", o.step);
  o.step_max_triangles = f.integer("step_max_triangles", -1, 0, 2000000000);
  o.verification = f.boolean("verification", o.verification);
  return o;
}

/// The "result" section: how the result surface is made (its resolution) and whether the
/// non-design solids the design leaves apart are joined to it (join_non_design).
void parse_result(const json& section, OptimizeSettings& o) {
  const Fields f(section, "result", {"resolution", "join_non_design"}, "{\"resolution\": 2}");
  o.smooth.resolution = f.integer("resolution", o.smooth.resolution, 1, 2);
  o.hygiene.join_non_design = f.boolean("join_non_design", o.hygiene.join_non_design);
}

/// A list section: each element parsed by `one(element, index)`.
template <class T, class One>
std::vector<T> parse_list(const Fields& top, const std::string& key, One one) {
  std::vector<T> out;
  if (!top.has(key)) return out;
  if (!top.at(key).is_array()) top.bad(key, "must be a list [...]");
  int i = 0;
  for (const auto& item : top.at(key)) out.push_back(one(item, i++));
  return out;
}

}  // namespace

void parse_face_name(const std::string& name, std::vector<int>& faces, std::vector<int>& nondesign_faces) {
  std::string s = name;
  bool nondesign = false;
  const std::string prefix = "NonDesign:";
  if (s.rfind(prefix, 0) == 0) nondesign = true, s = s.substr(prefix.size());
  if (s.rfind("Face", 0) == 0 && s.size() > 4 && s.size() < 12 &&
      s.find_first_not_of("0123456789", 4) == std::string::npos) {
    const int k = std::stoi(s.substr(4));
    if (k >= 1) {
      (nondesign ? nondesign_faces : faces).push_back(k);
      return;
    }
  }
  throw Error(ErrorCode::FaceNotFound, "\"" + name +
                                           "\" is not a face name; write faces as FreeCAD does: "
                                           "\"Face7\" (or \"NonDesign:Face2\" for a face of the non-design solids)");
}

OptimizeSettings parse_optimization_text(const std::string& text) {
  return parse_optimization(text.empty() ? json::object() : io::parse_json_text(text, "the job's optimization section"));
}

Job parse_job(const std::string& text, const std::string& base_dir) {
  const json doc = io::parse_json_text(text, "job file");
  const Fields top(
      doc, "", {"part", "nondesign", "mesh", "material", "supports", "load_cases", "optimization", "result", "output"});
  Job job;
  job.base_dir = base_dir;
  job.part = resolve(top.text("part", ""), base_dir);
  job.nondesign = resolve(top.text("nondesign", ""), base_dir);
  job.mesh = parse_mesh(top.has("mesh") ? top.at("mesh") : json::object(), base_dir);
  job.material = parse_material(top.has("material") ? top.at("material") : json::object());
  job.supports = parse_list<fem::SupportSpec>(top, "supports", [](const json& item, int i) {
    return parse_support(item, "supports[" + std::to_string(i) + "]");
  });
  job.load_cases = parse_list<fem::LoadCase>(top, "load_cases", parse_load_case);
  std::set<std::string> names;
  for (size_t i = 0; i < job.load_cases.size(); ++i)
    if (!names.insert(job.load_cases[i].name).second)
      top.bad("load_cases[" + std::to_string(i) + "].name",
              "repeats the name \"" + job.load_cases[i].name + "\": give each load case its own");
  job.optimization = parse_optimization(top.has("optimization") ? top.at("optimization") : json::object());
  parse_result(top.has("result") ? top.at("result") : json::object(), job.optimization);
  job.output = parse_output(top.has("output") ? top.at("output") : json::object(), base_dir);
  return job;
}

Job read_job(const std::string& path) {
  const std::string text = io::read_text_file(path, "job file");
  return parse_job(text, fs::absolute(fs::path(path)).parent_path().string());
}

void check_faces(const Job& job, int num_faces, int num_nondesign_faces) {
  auto check = [&](const std::vector<int>& faces, const std::vector<int>& nondesign, const std::string& what) {
    for (int f : faces)
      if (f > num_faces)
        throw Error(ErrorCode::FaceNotFound, what + " names Face" + std::to_string(f) + ", but the part has only " +
                                                 std::to_string(num_faces) + " faces (Face1 to Face" +
                                                 std::to_string(num_faces) + ")");
    if (num_nondesign_faces >= 0)
      for (int f : nondesign)
        if (f > num_nondesign_faces)
          throw Error(ErrorCode::FaceNotFound, what + " names NonDesign:Face" + std::to_string(f) +
                                                   ", but the non-design solids have only " +
                                                   std::to_string(num_nondesign_faces) + " faces");
  };
  for (size_t i = 0; i < job.supports.size(); ++i)
    check(job.supports[i].faces, job.supports[i].nd_faces, "support " + std::to_string(i + 1));
  for (const auto& lc : job.load_cases)
    for (const auto& l : lc.items) check(l.faces, l.nd_faces, "load case \"" + lc.name + "\"");
  if (const int base = job.optimization.simp.controls.overhang.base_face; base > 0)
    check({base}, {}, "optimization.controls.overhang.base_face");
}

void require_supports_and_loads(const Job& job) {
  if (job.supports.empty())
    throw Error(ErrorCode::NoSupport,
                "the job has no support: add \"supports\" with at least one, e.g. [{\"type\": \"fixed\", \"faces\": "
                "[\"Face3\"]}]");
  if (job.load_cases.empty())
    throw Error(ErrorCode::InvalidParameter, "the job has no load case: add \"load_cases\" with at least one load");
}

}  // namespace topopt::pipeline
