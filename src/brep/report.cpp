#include "brep/report.h"

#include <sstream>

namespace topopt::brep {
namespace {

const char* entity_prefix(On on) {
  switch (on) {
    case On::Vertex:
      return "Vertex";
    case On::Edge:
      return "Edge";
    case On::Face:
      return "Face";
    default:
      return "";
  }
}

nlohmann::json location_json(const std::string& name, const Location& loc) {
  nlohmann::json j{{"name", name}, {"on", on_name(loc.on)}};
  if (loc.on != On::Interior) {
    j["on_entity"] = std::string(entity_prefix(loc.on)) + std::to_string(loc.index + 1);
    j["distance"] = loc.distance;
    if (loc.on == On::Edge) j["parameters"] = {loc.t[0], loc.t[1]};
  }
  return j;
}

nlohmann::json bbox_json(const TopologyIndex& t) {
  return {{"min", {t.bbox_min[0], t.bbox_min[1], t.bbox_min[2]}},
          {"max", {t.bbox_max[0], t.bbox_max[1], t.bbox_max[2]}}};
}

nlohmann::json face_json(const TopologyIndex& t, int f) {
  return {{"name", "Face" + std::to_string(f + 1)},
          {"surface", t.face_surface[f]},
          {"area", t.face_area[f]},
          {"centre", {t.face_centre(f, 0), t.face_centre(f, 1), t.face_centre(f, 2)}}};
}

/// Per input face of Ω̄ that the imprint split: its pieces, where each lies and its area.
nlohmann::json imprint_json(const TwoBReps& m) {
  nlohmann::json out = nlohmann::json::array();
  const MeshedNonDesign& md = m.meshed;
  if (!md.imprinted) return out;
  std::vector<std::vector<int>> pieces(m.nondesign.num_faces());
  for (int f = 0; f < md.topo.num_faces(); ++f) pieces[md.face_origin[f]].push_back(f);
  for (int f = 0; f < m.nondesign.num_faces(); ++f) {
    if (pieces[f].size() < 2) continue;
    nlohmann::json pj = nlohmann::json::array();
    for (int piece : pieces[f]) {
      nlohmann::json lj = location_json("piece", md.on_part.face[piece]);
      lj.erase("name");
      lj["area"] = md.topo.face_area[piece];
      pj.push_back(lj);
    }
    out.push_back({{"face", "Face" + std::to_string(f + 1)}, {"pieces", pj}});
  }
  return out;
}

/// "Face4 (on Face20, interior, on Face28)" for every input face the imprint split.
std::string imprint_summary(const TwoBReps& m) {
  std::ostringstream s;
  for (const auto& face : imprint_json(m)) {
    s << "  " << face["face"].get<std::string>() << " reaches the part's boundary in part: split into";
    for (const auto& p : face["pieces"])
      s << " [" << (p.contains("on_entity") ? "on " + p["on_entity"].get<std::string>() : "inside") << "]";
    s << "\n";
  }
  return s.str();
}

}  // namespace

nlohmann::json two_breps_report(const TwoBReps& m) {
  const TopologyIndex& p = m.part;
  const TopologyIndex& n = m.nondesign;
  nlohmann::json part{{"solids", p.num_solids()},     {"shells", p.num_shells()},
                      {"faces", p.num_faces()},       {"edges", p.num_edges()},
                      {"vertices", p.num_vertices()}, {"volume", p.num_solids() ? p.solid_volume[0] : 0.0},
                      {"bbox", bbox_json(p)}};
  nlohmann::json part_faces = nlohmann::json::array();
  for (int f = 0; f < p.num_faces(); ++f) part_faces.push_back(face_json(p, f));
  part["faces_detail"] = part_faces;

  nlohmann::json solids = nlohmann::json::array();
  double nd_volume = 0;
  for (int s = 0; s < n.num_solids(); ++s) {
    nlohmann::json faces = nlohmann::json::array();
    for (const int* f = n.solid_faces.begin(s); f != n.solid_faces.end(s); ++f) {
      nlohmann::json fj = face_json(n, *f);
      nlohmann::json lj = location_json(fj["name"], m.nd_on_part.face[*f]);
      fj["on"] = lj["on"];
      if (lj.contains("on_entity")) fj["on_entity"] = lj["on_entity"];
      faces.push_back(fj);
    }
    nd_volume += n.solid_volume[s];
    solids.push_back({{"index", s + 1}, {"volume", n.solid_volume[s]}, {"faces", faces}});
  }
  nlohmann::json edges = nlohmann::json::array(), vertices = nlohmann::json::array();
  for (int e = 0; e < n.num_edges(); ++e)
    edges.push_back(location_json("Edge" + std::to_string(e + 1), m.nd_on_part.edge[e]));
  for (int v = 0; v < n.num_vertices(); ++v)
    vertices.push_back(location_json("Vertex" + std::to_string(v + 1), m.nd_on_part.vertex[v]));
  nlohmann::json nondesign{
      {"solids", solids}, {"faces", n.num_faces()}, {"volume", nd_volume}, {"edges", edges}, {"vertices", vertices}};

  nlohmann::json contacts = nlohmann::json::array();
  for (const Contact& c : m.relations.contacts) {
    nlohmann::json pairs = nlohmann::json::array();
    for (auto [a, b] : c.faces) pairs.push_back({"Face" + std::to_string(a + 1), "Face" + std::to_string(b + 1)});
    contacts.push_back({{"solids", {c.solid_a + 1, c.solid_b + 1}}, {"faces", pairs}});
  }
  return {{"part", part},     {"nondesign", nondesign},          {"contacts", contacts}, {"imprint", imprint_json(m)},
          {"notes", m.notes}, {"warnings", m.relations.warnings}};
}

std::string two_breps_summary(const TwoBReps& m) {
  std::ostringstream s;
  const TopologyIndex& p = m.part;
  s << "part: 1 solid, " << p.num_faces() << " faces, " << p.num_edges() << " edges, " << p.num_vertices()
    << " vertices, volume " << p.solid_volume[0] << " mm³\n";
  const TopologyIndex& n = m.nondesign;
  s << "non-design: " << n.num_solids() << " solids, " << n.num_faces() << " faces\n";
  for (int i = 0; i < n.num_solids(); ++i) {
    int on_face = 0, interior = 0;
    std::ostringstream where;
    for (const int* f = n.solid_faces.begin(i); f != n.solid_faces.end(i); ++f) {
      const Location& loc = m.nd_on_part.face[*f];
      if (loc.on == On::Face) {
        ++on_face;
        where << " Face" << *f + 1 << "->Face" << loc.index + 1;
      } else {
        ++interior;
      }
    }
    s << "  solid " << i + 1 << ": volume " << n.solid_volume[i] << " mm³, " << on_face << " faces on the part's faces,"
      << where.str() << "; " << interior << " interior\n";
  }
  s << imprint_summary(m);
  for (const Contact& c : m.relations.contacts) {
    s << "  solids " << c.solid_a + 1 << " and " << c.solid_b + 1 << " touch";
    for (auto [a, b] : c.faces) s << " (Face" << a + 1 << " on Face" << b + 1 << ")";
    s << "\n";
  }
  for (const auto& note : m.notes) s << "note: " << note << "\n";
  for (const auto& w : m.relations.warnings) s << "warning: " << w << "\n";
  return s.str();
}

}  // namespace topopt::brep
