// Gmsh MSH 4.1 ASCII reader and writer (see msh.h).
#include "io/msh.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>

#include "common/error.h"
#include "common/face_key.h"
#include "common/tet_boundary.h"

namespace topopt::io {
namespace {

using KeyHash = FaceKeyHash;
inline FaceKey sorted_key(int a, int b, int c) { return face_key(a, b, c); }

}  // namespace

void write_msh(const std::string& path, const TetMesh& mesh) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw Error(ErrorCode::Io, "cannot write the mesh file " + path);
  const long nv = mesh.V.rows(), nt = mesh.T.rows(), nf = mesh.F.rows();
  const bool has_nd = mesh.nd_face.size() == nf && nf > 0;
  // Surface entities: one per (face, nd_face) pair; volume entities: one per domain.
  std::map<std::pair<int, int>, int> surf;  // (face, nd) -> entity tag
  for (long t = 0; t < nf; ++t) surf.emplace(std::make_pair(mesh.face[t], has_nd ? mesh.nd_face[t] : 0), 0);
  int tag = 0;
  for (auto& kv : surf) kv.second = ++tag;
  int ndom = nt ? mesh.domain.maxCoeff() + 1 : 1;
  std::set<int> faces, nd_faces;
  for (const auto& kv : surf) {
    if (kv.first.first > 0) faces.insert(kv.first.first);
    if (kv.first.second > 0) nd_faces.insert(kv.first.second);
  }
  std::fprintf(f, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n%zu\n",
               static_cast<size_t>(ndom) + faces.size() + nd_faces.size());
  for (int d = 0; d < ndom; ++d)
    if (d == 0)
      std::fprintf(f, "3 1 \"design\"\n");
    else
      std::fprintf(f, "3 %d \"nondesign%d\"\n", d + 1, d);
  for (int fc : faces) std::fprintf(f, "2 %d \"Face%d\"\n", fc, fc);
  for (int fc : nd_faces) std::fprintf(f, "2 %d \"NonDesign:Face%d\"\n", kNonDesignFaceTag + fc, fc);
  std::fprintf(f, "$EndPhysicalNames\n");
  // Entities (bounding boxes are the whole mesh's: readers only use them as hints).
  Eigen::RowVector3d lo = nv ? Eigen::RowVector3d(mesh.V.colwise().minCoeff()) : Eigen::RowVector3d::Zero();
  Eigen::RowVector3d hi = nv ? Eigen::RowVector3d(mesh.V.colwise().maxCoeff()) : Eigen::RowVector3d::Zero();
  std::fprintf(f, "$Entities\n0 0 %zu %d\n", surf.size(), ndom);
  for (const auto& kv : surf) {
    std::vector<int> phys;
    if (kv.first.first > 0) phys.push_back(kv.first.first);
    if (kv.first.second > 0) phys.push_back(kNonDesignFaceTag + kv.first.second);
    std::fprintf(f, "%d %.17g %.17g %.17g %.17g %.17g %.17g %zu", kv.second, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2],
                 phys.size());
    for (int p : phys) std::fprintf(f, " %d", p);
    std::fprintf(f, " 0\n");
  }
  for (int d = 0; d < ndom; ++d)
    std::fprintf(f, "%d %.17g %.17g %.17g %.17g %.17g %.17g 1 %d 0\n", d + 1, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2],
                 d + 1);
  std::fprintf(f, "$EndEntities\n");
  // Nodes: one block on volume entity 1.
  std::fprintf(f, "$Nodes\n1 %ld 1 %ld\n3 1 0 %ld\n", nv, nv, nv);
  for (long i = 0; i < nv; ++i) std::fprintf(f, "%ld\n", i + 1);
  for (long i = 0; i < nv; ++i) std::fprintf(f, "%.17g %.17g %.17g\n", mesh.V(i, 0), mesh.V(i, 1), mesh.V(i, 2));
  std::fprintf(f, "$EndNodes\n");
  // Elements: triangles by surface entity, tets by domain.
  std::map<int, std::vector<long>> tri_by_entity;
  for (long t = 0; t < nf; ++t) tri_by_entity[surf[{mesh.face[t], has_nd ? mesh.nd_face[t] : 0}]].push_back(t);
  std::vector<std::vector<long>> tet_by_domain(ndom);
  for (long t = 0; t < nt; ++t) tet_by_domain[mesh.domain[t]].push_back(t);
  size_t blocks = tri_by_entity.size();
  for (const auto& v : tet_by_domain) blocks += !v.empty();
  std::fprintf(f, "$Elements\n%zu %ld 1 %ld\n", blocks, nf + nt, nf + nt);
  long id = 0;
  for (const auto& kv : tri_by_entity) {
    std::fprintf(f, "2 %d 2 %zu\n", kv.first, kv.second.size());
    for (long t : kv.second)
      std::fprintf(f, "%ld %d %d %d\n", ++id, mesh.F(t, 0) + 1, mesh.F(t, 1) + 1, mesh.F(t, 2) + 1);
  }
  for (int d = 0; d < ndom; ++d) {
    if (tet_by_domain[d].empty()) continue;
    std::fprintf(f, "3 %d 4 %zu\n", d + 1, tet_by_domain[d].size());
    for (long t : tet_by_domain[d])
      std::fprintf(f, "%ld %d %d %d %d\n", ++id, mesh.T(t, 0) + 1, mesh.T(t, 1) + 1, mesh.T(t, 2) + 1,
                   mesh.T(t, 3) + 1);
  }
  std::fprintf(f, "$EndElements\n");
  bool ok = std::ferror(f) == 0;
  ok &= std::fclose(f) == 0;
  if (!ok) throw Error(ErrorCode::Io, "error while writing " + path + " (disk full?)");
}

namespace {

/// Whitespace token reader over a whole file, tracking the line for messages.
class Tokens {
 public:
  Tokens(const std::string& path) : path_(path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(ErrorCode::Io, "cannot open the mesh file " + path);
    std::ostringstream ss;
    ss << in.rdbuf();
    text_ = ss.str();
  }
  bool done() {
    skip();
    return pos_ >= text_.size();
  }
  std::string word() {
    skip();
    size_t b = pos_;
    if (pos_ < text_.size() && text_[pos_] == '"') {
      size_t e = text_.find('"', pos_ + 1);
      if (e == std::string::npos) fail("unterminated string");
      pos_ = e + 1;
      return text_.substr(b + 1, e - b - 1);
    }
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    if (b == pos_) fail("unexpected end of file");
    return text_.substr(b, pos_ - b);
  }
  long integer() {
    skip();
    char* end = nullptr;
    long v = std::strtol(text_.c_str() + pos_, &end, 10);
    if (end == text_.c_str() + pos_) fail("expected an integer");
    pos_ = end - text_.c_str();
    return v;
  }
  double real() {
    skip();
    char* end = nullptr;
    double v = std::strtod(text_.c_str() + pos_, &end);
    if (end == text_.c_str() + pos_) fail("expected a number");
    pos_ = end - text_.c_str();
    return v;
  }
  /// Skips to the line after `end_marker`; `name` says which section in a message (the
  /// marker of a section we do not know came from the file and is not repeated).
  void skip_section(const std::string& end_marker, const std::string& name) {
    size_t e = text_.find(end_marker, pos_);
    if (e == std::string::npos) fail(name + " has no end line");
    pos_ = e + end_marker.size();
  }
  [[noreturn]] void fail(const std::string& what) const {
    long line = 1 + std::count(text_.begin(), text_.begin() + std::min(pos_, text_.size()), '\n');
    throw Error(ErrorCode::Io,
                path_ + ":" + std::to_string(line) + ": " + what + " (expected a Gmsh MSH 4.1 ASCII file)");
  }

 private:
  void skip() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  std::string path_, text_;
  size_t pos_ = 0;
};

}  // namespace

namespace {

/// What read_msh collects from the sections of a file before it becomes a TetMesh.
struct MshContents {
  std::map<std::pair<int, int>, std::vector<int>> phys;  // (dim, entity) -> physical tags
  std::unordered_map<long, int> node_index;              // node tag -> index into nodes
  std::vector<std::array<double, 3>> nodes;
  std::vector<std::array<long, 4>> tets;      // corner node tags
  std::vector<int> tet_dom;                   // domain of each tet
  std::vector<std::array<long, 3>> tris;      // corner node tags of the tagged triangles
  std::vector<std::pair<int, int>> tri_tags;  // (face, nd_face) of each triangle
};

/// $MeshFormat: version 4.x, ASCII.
void read_format(Tokens& in) {
  std::string version = in.word();
  long binary = in.integer();
  in.integer();
  if (version.rfind("4", 0) != 0) {
    const bool looks_like_a_version =
        version.size() <= 8 && version.find_first_not_of("0123456789.") == std::string::npos;
    in.fail("MSH version " + (looks_like_a_version ? version + " " : std::string()) + "is not supported; save as 4.1");
  }
  if (binary) in.fail("binary MSH is not supported; save as ASCII");
  in.skip_section("$EndMeshFormat", "$MeshFormat");
}

/// $Entities: the physical tags of every point, curve, surface and volume entity.
void read_entities(Tokens& in, MshContents& c) {
  long count[4];
  for (long& n : count) n = in.integer();
  for (int dim = 0; dim <= 3; ++dim)
    for (long i = 0; i < count[dim]; ++i) {
      int tag = static_cast<int>(in.integer());
      for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) in.real();  // a point, or a bounding box
      long n = in.integer();
      for (long k = 0; k < n; ++k) c.phys[{dim, tag}].push_back(static_cast<int>(in.integer()));
      if (dim == 0) continue;
      long nb = in.integer();  // bounding entities
      for (long k = 0; k < nb; ++k) in.integer();
    }
  in.skip_section("$EndEntities", "$Entities");
}

/// $Nodes: coordinates by node tag (parametric coordinates skipped).
void read_nodes(Tokens& in, MshContents& c) {
  long blocks = in.integer(), total = in.integer();
  in.integer(), in.integer();
  c.nodes.reserve(total);
  for (long b = 0; b < blocks; ++b) {
    long dim = in.integer();
    in.integer();
    long parametric = in.integer(), n = in.integer();
    std::vector<long> tags(n);
    for (long k = 0; k < n; ++k) tags[k] = in.integer();
    for (long k = 0; k < n; ++k) {
      std::array<double, 3> x{in.real(), in.real(), in.real()};
      if (parametric)
        for (long p = 0; p < std::min<long>(dim, 2); ++p) in.real();
      c.node_index[tags[k]] = static_cast<int>(c.nodes.size());
      c.nodes.push_back(x);
    }
  }
  in.skip_section("$EndNodes", "$Nodes");
}

/// One element of $Elements: a (linear or quadratic) tet gets its block's domain, a tagged
/// (linear or quadratic) triangle its face and non-design face; corners only.
void add_element(MshContents& c, long type, int entity, const std::vector<int>& ph, const std::array<long, 10>& v) {
  if (type == 4 || type == 11) {
    c.tets.push_back({v[0], v[1], v[2], v[3]});
    int tag = ph.empty() ? entity : ph.front();
    c.tet_dom.push_back(std::max(0, tag - 1));
  } else if ((type == 2 || type == 9) && !ph.empty()) {
    int face = 0, nd_face = 0;
    for (int p : ph)
      if (p > kNonDesignFaceTag)
        nd_face = p - kNonDesignFaceTag;
      else
        face = p;
    c.tris.push_back({v[0], v[1], v[2]});
    c.tri_tags.emplace_back(face, nd_face);
  }
}

/// $Elements: tets and tagged triangles (other types read and skipped).
void read_elements(Tokens& in, MshContents& c) {
  long blocks = in.integer();
  in.integer(), in.integer(), in.integer();
  static const std::map<long, int> kNodesOf = {{1, 2}, {2, 3}, {3, 4}, {4, 4},  {5, 8},   {6, 6},
                                               {7, 5}, {8, 3}, {9, 6}, {10, 9}, {11, 10}, {15, 1}};
  for (long b = 0; b < blocks; ++b) {
    int dim = static_cast<int>(in.integer());
    int entity = static_cast<int>(in.integer());
    long type = in.integer(), n = in.integer();
    auto it = kNodesOf.find(type);
    if (it == kNodesOf.end()) in.fail("element type " + std::to_string(type) + " is not supported");
    const std::vector<int>& ph = c.phys[{dim, entity}];
    for (long k = 0; k < n; ++k) {
      in.integer();
      std::array<long, 10> v{};
      for (int j = 0; j < it->second; ++j) v[j] = in.integer();
      add_element(c, type, entity, ph, v);
    }
  }
  in.skip_section("$EndElements", "$Elements");
}

/// The index of the node with `tag`; throws Error(Io) if the file does not define it.
int node_of_tag(const MshContents& c, long tag, const std::string& path) {
  auto it = c.node_index.find(tag);
  if (it == c.node_index.end())
    throw Error(ErrorCode::Io, path + ": an element uses node " + std::to_string(tag) + " which is not defined");
  return it->second;
}

/// m.V, m.T (negatively oriented tets flipped) and m.domain from the file's contents.
void set_tets(const MshContents& c, const std::string& path, TetMesh& m) {
  m.V.resize(c.nodes.size(), 3);
  for (size_t i = 0; i < c.nodes.size(); ++i) m.V.row(i) << c.nodes[i][0], c.nodes[i][1], c.nodes[i][2];
  m.T.resize(c.tets.size(), 4);
  m.domain.resize(c.tets.size());
  for (size_t t = 0; t < c.tets.size(); ++t) {
    for (int a = 0; a < 4; ++a) m.T(t, a) = node_of_tag(c, c.tets[t][a], path);
    Eigen::RowVector3d p0 = m.V.row(m.T(t, 0));
    Eigen::Matrix3d J;
    for (int a = 0; a < 3; ++a) J.row(a) = m.V.row(m.T(t, a + 1)) - p0;
    if (J.determinant() < 0) std::swap(m.T(t, 2), m.T(t, 3));
    m.domain[t] = c.tet_dom[t];
  }
}

/// m.F, m.face, m.nd_face: the file's tagged triangles, each oriented as the boundary of the
/// tets says (outwards); without any, the boundary of the tets with face 0.
void set_boundary(const MshContents& c, const std::string& path, TetMesh& m) {
  if (c.tris.empty()) {
    m.F = boundary_triangles(m.T);
    m.face = VecXi::Zero(m.F.rows());
    m.nd_face = VecXi::Zero(m.F.rows());
    return;
  }
  m.F.resize(c.tris.size(), 3);
  m.face.resize(c.tris.size());
  m.nd_face.resize(c.tris.size());
  MatX3i B = boundary_triangles(m.T);
  std::unordered_map<std::array<int, 3>, std::array<int, 3>, KeyHash> outward;
  for (long i = 0; i < B.rows(); ++i) outward[sorted_key(B(i, 0), B(i, 1), B(i, 2))] = {B(i, 0), B(i, 1), B(i, 2)};
  for (size_t t = 0; t < c.tris.size(); ++t) {
    std::array<int, 3> tri{node_of_tag(c, c.tris[t][0], path), node_of_tag(c, c.tris[t][1], path),
                           node_of_tag(c, c.tris[t][2], path)};
    auto it = outward.find(sorted_key(tri[0], tri[1], tri[2]));
    if (it != outward.end()) tri = it->second;
    m.F.row(t) << tri[0], tri[1], tri[2];
    m.face[t] = c.tri_tags[t].first;
    m.nd_face[t] = c.tri_tags[t].second;
  }
}

}  // namespace

TetMesh read_msh(const std::string& path) {
  Tokens in(path);
  MshContents c;
  bool saw_format = false;
  while (!in.done()) {
    std::string sec = in.word();
    if (sec == "$MeshFormat") {
      read_format(in);
      saw_format = true;
    } else if (sec == "$Entities") {
      read_entities(in, c);
    } else if (sec == "$Nodes") {
      read_nodes(in, c);
    } else if (sec == "$Elements") {
      read_elements(in, c);
    } else if (!sec.empty() && sec[0] == '$') {
      in.skip_section("$End" + sec.substr(1), "a section this reader skips");
    } else {
      // the text itself is not repeated: the file may be anything readable (mesh.file)
      in.fail("text outside a $Section");
    }
  }
  if (!saw_format) in.fail("no $MeshFormat section");
  if (c.tets.empty()) throw Error(ErrorCode::Io, path + ": the mesh has no tetrahedra");
  TetMesh m;
  set_tets(c, path, m);
  set_boundary(c, path, m);
  return m;
}

}  // namespace topopt::io
