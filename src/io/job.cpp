// Job file parsing and validation (see job.h).
#include "io/job.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/error.h"

namespace topopt::io {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

[[noreturn]] void bad(const std::string& key, const std::string& what) {
  throw Error(ErrorCode::InvalidParameter, "job file: \"" + key + "\" " + what);
}

double number(const json& j, const std::string& key, double fallback, const std::string& where) {
  if (!j.contains(key) || j[key].is_null()) return fallback;
  if (!j[key].is_number()) bad(where + key, "must be a number");
  return j[key].get<double>();
}

std::string resolve(const std::string& p, const std::string& base) {
  if (p.empty()) return p;
  fs::path path(p);
  if (path.is_relative() && !base.empty()) path = fs::path(base) / path;
  return path.lexically_normal().string();
}

void faces_of(const json& item, const std::string& where, std::vector<int>& faces, std::vector<int>& nd) {
  if (!item.contains("faces") || !item["faces"].is_array() || item["faces"].empty())
    bad(where + "faces", "must be a non-empty list of face names such as [\"Face3\"]");
  for (const auto& f : item["faces"]) {
    if (!f.is_string()) bad(where + "faces", "must hold face names such as \"Face3\"");
    parse_face_name(f.get<std::string>(), faces, nd);
  }
}

std::array<double, 3> vec3(const json& item, const std::string& key, const std::string& where) {
  if (!item.contains(key) || !item[key].is_array() || item[key].size() != 3)
    bad(where + key, "must be a list of three numbers [x, y, z]");
  std::array<double, 3> v{};
  for (int i = 0; i < 3; ++i) {
    if (!item[key][i].is_number()) bad(where + key, "must be a list of three numbers [x, y, z]");
    v[i] = item[key][i].get<double>();
  }
  return v;
}

}  // namespace

void parse_face_name(const std::string& name, std::vector<int>& faces, std::vector<int>& nd_faces) {
  std::string s = name;
  bool nd = false;
  const std::string prefix = "NonDesign:";
  if (s.rfind(prefix, 0) == 0) nd = true, s = s.substr(prefix.size());
  if (s.rfind("Face", 0) == 0 && s.size() > 4 && s.find_first_not_of("0123456789", 4) == std::string::npos) {
    int k = std::stoi(s.substr(4));
    if (k >= 1) {
      (nd ? nd_faces : faces).push_back(k);
      return;
    }
  }
  throw Error(ErrorCode::FaceNotFound, "\"" + name +
                                           "\" is not a face name; write faces as FreeCAD does: "
                                           "\"Face7\" (or \"NonDesign:Face2\" for a face of the non-design solids)");
}

Job parse_job(const std::string& text, const std::string& base_dir) {
  Job job;
  try {
    job.raw = json::parse(text);
  } catch (const json::parse_error& e) {
    throw Error(ErrorCode::Io, std::string("job file is not valid JSON: ") + e.what());
  }
  const json& j = job.raw;
  if (!j.is_object()) throw Error(ErrorCode::Io, "job file: the top level must be a JSON object");
  job.base_dir = base_dir;
  auto str = [&](const json& o, const std::string& key) -> std::string {
    if (!o.contains(key) || o[key].is_null()) return "";
    if (!o[key].is_string()) bad(key, "must be a string (a file path)");
    return o[key].get<std::string>();
  };
  job.part = resolve(str(j, "part"), base_dir);
  job.nondesign = resolve(str(j, "nondesign"), base_dir);
  if (j.contains("mesh")) {
    const json& m = j["mesh"];
    if (!m.is_object()) bad("mesh", "must be an object such as {\"size\": 2.0}");
    job.mesh_file = resolve(str(m, "file"), base_dir);
    job.mesh_size = number(m, "size", 0, "mesh.");
    job.mesh_min_size = number(m, "min_size", 0, "mesh.");
    const double layers = number(m, "wall_layers", 0, "mesh.");
    if (!(layers >= 0 && layers <= 4 && layers == std::floor(layers)))
      bad("mesh.wall_layers", "must be a whole number from 0 (off) to 4; 2 gives thin walls two element layers across");
    job.mesh_wall_layers = static_cast<int>(layers);
    if (m.contains("mesher")) {
      if (!m["mesher"].is_string() || (m["mesher"] != "auto" && m["mesher"] != "native" && m["mesher"] != "gmsh"))
        bad("mesh.mesher", "must be \"auto\", \"native\" (the two-B-Rep advancing front) or \"gmsh\"");
      job.mesher = m["mesher"].get<std::string>();
    }
    if (job.mesh_size < 0) bad("mesh.size", "must be positive (mm), or 0 for automatic");
    if (job.mesh_min_size < 0) bad("mesh.min_size", "must be positive (mm), or 0 for automatic");
  }
  if (j.contains("material")) {
    const json& m = j["material"];
    job.material.young = number(m, "E", job.material.young, "material.");
    job.material.poisson = number(m, "nu", job.material.poisson, "material.");
    job.material.density = number(m, "density", job.material.density, "material.");
    if (!(job.material.young > 0)) bad("material.E", "must be positive (MPa)");
    if (!(job.material.poisson > -1 && job.material.poisson < 0.5)) bad("material.nu", "must lie in (-1, 0.5)");
  }
  if (j.contains("supports")) {
    if (!j["supports"].is_array()) bad("supports", "must be a list");
    int i = 0;
    for (const auto& s : j["supports"]) {
      std::string where = "supports[" + std::to_string(i++) + "].";
      fem::SupportSpec spec;
      std::string type = s.value("type", "fixed");
      if (type == "fixed") {
        spec.kind = fem::SupportSpec::Kind::Fixed;
      } else if (type == "components") {
        spec.kind = fem::SupportSpec::Kind::Components;
        spec.fix = {false, false, false};
        if (!s.contains("fix") || !s["fix"].is_array())
          bad(where + "fix", "must list the fixed components, e.g. [\"x\", \"z\"]");
        for (const auto& c : s["fix"]) {
          std::string n = c.is_string() ? c.get<std::string>() : "";
          if (n == "x")
            spec.fix[0] = true;
          else if (n == "y")
            spec.fix[1] = true;
          else if (n == "z")
            spec.fix[2] = true;
          else
            bad(where + "fix", "must hold \"x\", \"y\" or \"z\"");
        }
      } else if (type == "symmetry") {
        spec.kind = fem::SupportSpec::Kind::Symmetry;
      } else {
        bad(where + "type", "must be \"fixed\", \"components\" or \"symmetry\", not \"" + type + "\"");
      }
      faces_of(s, where, spec.faces, spec.nd_faces);
      job.supports.push_back(spec);
    }
  }
  if (j.contains("load_cases")) {
    if (!j["load_cases"].is_array()) bad("load_cases", "must be a list");
    int i = 0;
    for (const auto& c : j["load_cases"]) {
      std::string where = "load_cases[" + std::to_string(i) + "].";
      fem::LoadCase lc;
      lc.name = c.value("name", "case" + std::to_string(i + 1));
      lc.weight = number(c, "weight", 1.0, where);
      if (!(lc.weight > 0)) bad(where + "weight", "must be positive");
      if (!c.contains("loads") || !c["loads"].is_array() || c["loads"].empty())
        bad(where + "loads", "must be a non-empty list of loads");
      int k = 0;
      for (const auto& l : c["loads"]) {
        std::string lw = where + "loads[" + std::to_string(k++) + "].";
        fem::LoadSpec spec;
        std::string type = l.value("type", "force");
        if (type == "force") {
          spec.kind = fem::LoadSpec::Kind::Force;
          faces_of(l, lw, spec.faces, spec.nd_faces);
          spec.vector = vec3(l, "vector", lw);
        } else if (type == "pressure") {
          spec.kind = fem::LoadSpec::Kind::Pressure;
          faces_of(l, lw, spec.faces, spec.nd_faces);
          spec.value = number(l, "value", 0, lw);
        } else if (type == "gravity") {
          spec.kind = fem::LoadSpec::Kind::Gravity;
          spec.vector = vec3(l, "vector", lw);
        } else {
          bad(lw + "type", "must be \"force\", \"pressure\" or \"gravity\", not \"" + type + "\"");
        }
        lc.items.push_back(spec);
      }
      job.load_cases.push_back(lc);
      ++i;
    }
  }
  job.output_dir = resolve("out", base_dir.empty() ? "." : base_dir);
  if (j.contains("output")) {
    const json& o = j["output"];
    if (o.contains("directory")) job.output_dir = resolve(str(o, "directory"), base_dir.empty() ? "." : base_dir);
    if (o.contains("vtu")) job.write_vtu = o["vtu"].get<bool>();
    if (o.contains("inp")) job.write_inp = o["inp"].get<bool>();
  }
  return job;
}

Job read_job(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(ErrorCode::Io, "cannot open the job file " + path);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string base = fs::absolute(fs::path(path)).parent_path().string();
  return parse_job(ss.str(), base);
}

void check_faces(const Job& job, int num_faces, int num_nd_faces) {
  auto check = [&](const std::vector<int>& faces, const std::vector<int>& nd, const std::string& what) {
    for (int f : faces)
      if (f > num_faces)
        throw Error(ErrorCode::FaceNotFound, what + " names Face" + std::to_string(f) + ", but the part has only " +
                                                 std::to_string(num_faces) + " faces (Face1 to Face" +
                                                 std::to_string(num_faces) + ")");
    if (num_nd_faces >= 0)
      for (int f : nd)
        if (f > num_nd_faces)
          throw Error(ErrorCode::FaceNotFound, what + " names NonDesign:Face" + std::to_string(f) +
                                                   ", but the non-design solids have only " +
                                                   std::to_string(num_nd_faces) + " faces");
  };
  for (size_t i = 0; i < job.supports.size(); ++i)
    check(job.supports[i].faces, job.supports[i].nd_faces, "support " + std::to_string(i + 1));
  for (const auto& lc : job.load_cases)
    for (const auto& l : lc.items) check(l.faces, l.nd_faces, "load case \"" + lc.name + "\"");
}

}  // namespace topopt::io
