// Surface meshing of one B-Rep model by its hierarchy (steps 1, 5 and 9 of the method for a
// single model): nodes on the vertices, the edges discretised once (so faces that share an
// edge share its nodes), then every face filled by the 2D advancing front (face_front.h) in
// its parameter plane, scaled so that lengths there approximate lengths on the surface.
//
// Sizes: a global size (default diagonal / 50) refined by the curvature of faces and edges
// (max_angle of turning per element, floor min_size), graded along edges from their
// vertices and inside faces from finer boundary pieces (gradation); boundary pieces are split
// where a face's loops come close to each other (proximity) or run longer than the face's
// graded size; on request (wall_layers) walls thinner than two sizes are refined from their
// thickness, measured by rays across the model. The parameter scaling is exact for planes and cylinders and approximate
// on other surfaces; the triangles are then improved on the surface itself (surface_optimize.h). A collapsed edge (cone
// apex, sphere pole) becomes a fan of triangles around its apex.
#pragma once
#include <array>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "brep/topology_index.h"
#include "common/progress.h"
#include "common/types.h"
#include "mesh/surface/face_front.h"
#include "mesh/surface/graded_size.h"

class TopoDS_Face;

namespace topopt::mesh {

struct SurfaceMeshParams {
  double size = 0;                                     ///< target edge length (mm); <= 0: the model's diagonal / 50
  double min_size = 0;                                 ///< smallest edge length (mm); <= 0: size / 10
  double max_angle = 2 * 3.14159265358979323846 / 16;  ///< turning of the surface or edge per element (rad)
  double gradation = 1.3;   ///< how fast sizes may grow away from finer regions (ratio per element)
  int wall_layers = 0;      ///< walls thinner than two sizes get about this many element
                            ///< layers across (0: no refinement by wall thickness)
  int optimize_rounds = 3;  ///< flip + smoothing rounds judged on the surface (0: none)
  int threads = 0;          ///< faces meshed in parallel; 0 = all cores
  FaceFrontParams front;    ///< the face engine's settings (its size is set per face)
  /// Which ways of filling a face are tried, in order, until one closes (empty: all): 0 its
  /// loops as measured, 1 with gaps between its edges' ends closed, 2 in isotropic
  /// parameters, 3 in unscaled parameters, 4 split in two along a parameter line through its
  /// middle (tests pick one to exercise it).
  std::vector<int> face_attempts;
  /// CPU seconds each way of filling one face may take (its thread's clock); past it that way
  /// stops and the next is tried. 0: automatic (face_cpu_seconds()), < 0: no limit.
  double face_cpu_seconds = 0;
};

/// The automatic CPU budget (s) of one way of filling a face expected to take `triangles`
/// triangles: 20 s, and 1 s more per 2 000 triangles (the front makes some 20 000 a second).
double face_cpu_seconds(double triangles);

struct SurfaceMesh {
  MatX3d V;                       ///< #V by 3 nodes; the first #vertices are the model's vertices, in order
  MatX3i F;                       ///< #F by 3 triangles, normals pointing out of the solid that holds the face
  VecXi face;                     ///< #F: the face's number, 1-based as FreeCAD's FaceN
  std::vector<int> failed_faces;  ///< faces that could not be meshed (1-based), with reasons below
  std::vector<std::string> reasons;
};

/// The rule that sets the size on a face where the face is finest (topopt mesh --stats,
/// "face_sizes"): the model's size, the face's curvature (max_angle per element), the
/// smallest size (curvature asked for less), a boundary piece made finer for a neighbour (a
/// finer face or a curved edge next to it, graded from there), an edge shorter than the size,
/// two loops of the face close to each other (proximity), a thin wall (wall_layers), or the
/// segments a non-design solid put on the face.
enum class SizeReason { MaxSize, Curvature, MinSize, Neighbour, ShortEdge, Proximity, WallThickness, NonDesign };

/// "max size", "curvature", "min size", "gradation from a neighbour", "short edge",
/// "proximity", "wall thickness", "non-design solid".
const char* size_reason_name(SizeReason r);

/// Why a face's mesh is as fine as it is.
struct FaceSize {
  int face = 0;          ///< 1-based, FreeCAD's FaceN
  double size = 0;       ///< the finest target size on the face (mm): its own or its finest boundary piece's
  double face_size = 0;  ///< the face's own size (mm): the model's size or what its curvature allows
  SizeReason reason = SizeReason::MaxSize;  ///< the rule that gives `size`
};

/// wall_layers from a user (CLI, job): an integer 0..4, else Error(InvalidParameter) saying so.
int wall_layers_option(double value);

/// Meshes every face of `topo`. A face that cannot be meshed is listed in failed_faces (the
/// rest of the surface is still returned) so callers can name it.
SurfaceMesh mesh_surface(const brep::TopologyIndex& topo, const SurfaceMeshParams& params = {},
                         const Progress& progress = {});

/// The surface mesh of one B-Rep model built stage by stage, on a node pool that may be
/// shared with another model: the 14 steps of the two-B-Rep method (DESIGN.md) move nodes,
/// segments and triangles between two of these. Stages, in order: vertex nodes (given or
/// created), edges (given, aliased to another edge, or discretised honouring fixed nodes,
/// then split by proximity), faces (given, aliased, or filled by the 2D front honouring
/// constraint segments and nodes). mesh_surface() is the single-model sequence.
class ModelSurface {
 public:
  /// `nodes` is the shared pool (#nodes rows of x, y, z); new nodes are appended to it.
  ModelSurface(const brep::TopologyIndex& topo, std::vector<std::array<double, 3>>& nodes,
               const SurfaceMeshParams& params);
  const brep::TopologyIndex& topo() const { return topo_; }
  double size() const { return h_; }

  // ---- vertices (steps 1-3)
  /// Vertex v (0-based) is meshed by an existing node (step 2: a transfer).
  void set_vertex_node(int v, int node);
  /// Every vertex without a node gets one; with merge_tolerance > 0 a vertex within that
  /// distance of an earlier vertex of this model shares its node (solids that touch).
  void create_vertex_nodes(double merge_tolerance = 0);
  int vertex_node(int v) const { return vertex_node_[v]; }

  // ---- edges (steps 4-7)
  /// The mesh of edge e must contain `node` (step 4); its parameter is found by projection.
  void fix_edge_node(int e, int node);
  /// Edge e is meshed by `nodes`, from its first vertex to its last (step 6: a transfer);
  /// it is never split afterwards.
  void set_edge_mesh(int e, const std::vector<int>& nodes);
  /// Edge e has the geometry of edge `rep` (solids that touch): it takes rep's nodes, in
  /// reverse order when `reversed`, whenever rep's mesh changes.
  void alias_edge(int e, int rep, bool reversed);
  /// Discretises every edge not given, then splits pieces by proximity (never given edges).
  void mesh_edges(const Progress& progress = {});
  /// Nodes of edge e from its first vertex to its last (empty for a collapsed edge).
  const std::vector<int>& edge_nodes(int e) const { return edge_node_[e]; }
  bool edge_given(int e) const { return edge_kind_[e] == EdgeKind::Given; }
  /// Parameter of the point x on edge e's curve, and its distance to the curve.
  double edge_parameter(int e, const double* x, double* distance = nullptr) const;

  // ---- faces (steps 8-11)
  /// Face f (0-based) must contain the segment between nodes a and b (step 8).
  void constrain_face(int f, int a, int b);
  /// Face f must contain node n as a vertex of its mesh.
  void add_face_node(int f, int n);
  const std::vector<std::array<int, 2>>& face_constraints(int f) const { return constraint_[f]; }
  /// Face f is meshed by `tris` (step 10: a transfer), oriented as this model's output.
  void set_face_mesh(int f, std::vector<std::array<int, 3>> tris);
  /// Face f lies on face `src` (solids that touch): it takes src's triangles, reversed
  /// when `reversed`. Checked: the copied triangles' boundary must be f's boundary.
  void alias_face(int f, int src, bool reversed);
  /// Fills every face not given or aliased (in parallel), then copies the aliased ones.
  /// Faces that fail are listed by failed_faces().
  void mesh_faces(const Progress& progress = {});
  /// Face f's triangles, normals out of the solid that holds the face (the index's first).
  const std::vector<std::array<int, 3>>& face_triangles(int f) const { return face_tris_[f]; }
  const std::vector<int>& failed_faces() const { return failed_; }  ///< 1-based
  /// With wall_layers: (x, y, z, size) at the middle of each thin wall sample, for the
  /// volume's size (BackgroundSize seeds), so the fill puts nodes inside the wall.
  const std::vector<std::array<double, 4>>& wall_points() const { return wall_points_; }
  const std::vector<std::string>& failure_reasons() const { return reasons_; }
  /// Faces (1-based) the front closed only on a retry, with the way that closed them
  /// (SurfaceMeshParams::face_attempts).
  const std::vector<std::pair<int, std::string>>& retried_faces() const { return retried_; }
  /// Per face (after mesh_edges and the face constraints): its finest size and the rule that
  /// sets it (FaceSize). A boundary piece counts where it is below 0.7 of the face's own size
  /// (finer pieces are what the face's fill grows from).
  std::vector<FaceSize> face_sizes() const;

  /// Triangles of solid s (0-based), oriented out of it.
  std::vector<std::array<int, 3>> solid_triangles(int s) const;
  /// The model's mesh on its own node numbering: vertex nodes first (in order), then the
  /// nodes its triangles use.
  SurfaceMesh result() const;

 private:
  enum class EdgeKind { Free, Given, Alias };
  /// A per-direction scale making lengths in (su·u, sv·v) approximate lengths on the face,
  /// and its largest curvature.
  struct FaceGeometry {
    double su = 1, sv = 1, kmax = 0;
  };
  /// An edge sampled finely: parameters, arc length and the size allowed at each sample.
  struct EdgeSamples {
    std::vector<double> t, s, size;
    int va = -1, vb = -1;
  };
  /// A face's boundary in its scaled parameters (see face_loops).
  struct Loops {
    std::vector<std::array<double, 2>> uv;
    std::vector<int> global;
    std::vector<std::array<int, 2>> segs;
    std::vector<int> seg_edge;
    std::vector<int> seg_piece;
  };
  /// Where an edge's nodes go: (parameter, node; -1 where one is to be made), first vertex to last.
  using Division = std::vector<std::pair<double, int>>;
  /// A division and the sizes of the edge's first and last vertex it was made at.
  struct EdgeDivision {
    Division at;
    double size_a = -1, size_b = -1;
  };
  /// A coarse tessellation of the model: points, outward triangles, each point's scaled
  /// parameters on its face, each triangle's face (-1: a face without parameters).
  struct Tessellation {
    MatX3d V;
    MatX3i F;
    std::vector<std::array<double, 2>> uv;
    std::vector<int> face;
  };
  /// Face corners that proximity splits leave alone: per edge, whether its first / last piece
  /// is at a needle corner; and every such corner (match_corner_pieces).
  struct SharpCorners {
    struct Corner {
      int node = -1;               ///< the corner's node (pool number)
      std::array<int, 2> edges{};  ///< the B-Rep edges of the two pieces meeting there (0-based)
    };
    std::vector<std::array<char, 2>> needle_end;
    std::vector<Corner> all;
  };
  /// Pieces to split in one proximity round: per edge, the pieces (may repeat); any marked;
  /// per edge, whether a piece was marked because another loop of a face is close.
  struct PieceSplits {
    std::vector<std::vector<int>> pieces;
    bool any = false;
    std::vector<char> close;
  };
  /// A face's boundary segments with their lengths and boxes, ordered by their lowest u.
  struct SegmentBoxes {
    explicit SegmentBoxes(const Loops& L);
    std::vector<double> len, xlo, xhi, ylo, yhi;
    std::vector<int> order;
  };
  /// What the front starts from on a face: its loops (nodes extended by the projected
  /// constraint nodes), constraint segments and isolated nodes, in the loops' local numbering.
  struct FaceInput {
    Loops loops;
    std::vector<std::array<int, 2>> csegs;
    std::vector<int> isolated;
  };
  struct FaceOut {
    std::vector<int> global;  ///< the face's input nodes' pool numbers (the first rows of X)
    MatX3d X;                 ///< every node of the face's mesh
    MatX3i T;
    std::string error;
    std::string attempt;  ///< the way of filling that closed the face (face_attempts)
  };
  /// One way of filling a face: the parameter scaling, whether loop gaps are closed and
  /// whether the face is split in two along a parameter line (add_split_line).
  struct FaceAttempt {
    const char* name;
    FaceGeometry geo;
    bool close_gaps = false;
    bool split = false;
  };

  // construction: sizes of faces, edges and vertices
  static FaceGeometry face_geometry(const TopoDS_Face& f);
  void size_faces();
  void measure_thickness();
  Tessellation coarse_tessellation() const;
  void sample_edges();
  void thin_edge_sizes();
  void initial_vertex_sizes();
  void grade_vertex_sizes();
  // edges
  Division division(int e) const;
  void discretise(int e, const Division& d);
  std::vector<EdgeDivision> match_vertex_sizes();
  void refresh_alias(int e);
  void split_by_proximity(const Progress& progress);
  std::pair<int, int> free_piece(int e, int piece) const;
  SharpCorners sharp_corners() const;
  void mark_piece(const Loops& L, int s, bool crossing, const SharpCorners& corners, PieceSplits& splits,
                  bool close = false) const;
  void mark_long_pieces(int f, const Loops& L, const SegmentBoxes& boxes, const SharpCorners& corners,
                        PieceSplits& splits) const;
  void mark_close_pieces(const Loops& L, const SegmentBoxes& boxes, const SharpCorners& corners,
                         PieceSplits& splits) const;
  void split_pieces(std::vector<std::vector<int>>& split, std::vector<char>& stale);
  void split_rounds(const SharpCorners& corners, std::vector<char>& stale, const Progress& progress);
  bool match_corner_pieces(const SharpCorners& corners, std::vector<char>& stale);
  std::array<int, 2> corner_piece(int e, int node) const;
  void edges_changed(const std::vector<char>& changed, std::vector<char>& stale);
  FaceSize face_size_reason(int f) const;
  // faces
  Loops face_loops(int f) const;
  Loops face_loops(int f, const FaceGeometry& g) const;
  void mesh_face(int f, const Progress& progress, FaceOut& out) const;
  std::vector<FaceAttempt> face_attempts(int f) const;
  void mesh_face_once(int f, const FaceAttempt& a, const Progress& progress, FaceOut& out) const;
  static void close_loop_gaps(FaceInput& in);
  static void add_split_line(int f, FaceInput& in, double h);
  double face_budget(int f) const;
  FaceInput face_input(int f, const FaceGeometry& g) const;
  void improve_on_surface(int f, const FaceGeometry& g, const FaceInput& in, FaceFrontResult& r, FaceOut& out) const;
  void take_face_mesh(int f, const FaceOut& fo);
  void copy_aliased_face(int f);
  int new_node(double x, double y, double z);

  const brep::TopologyIndex& topo_;
  std::vector<std::array<double, 3>>& nodes_;
  SurfaceMeshParams params_;
  double h_, hmin_, grade_;
  std::vector<FaceGeometry> geo_;
  std::vector<double> face_size_;
  std::vector<EdgeSamples> samples_;
  std::vector<double> vsize_;
  std::vector<SizeRaster> thin_size_;               ///< per face: the size inside thin walls
  std::vector<std::array<double, 4>> wall_points_;  ///< see wall_points()
  std::vector<int> vertex_node_;
  std::vector<EdgeKind> edge_kind_;
  std::vector<std::array<int, 2>> alias_of_;                ///< (rep, reversed) per aliased edge
  std::vector<std::vector<std::pair<double, int>>> fixed_;  ///< (parameter, node) per edge
  std::vector<std::vector<double>> edge_param_;
  std::vector<std::vector<int>> edge_node_;
  std::vector<char> split_close_;  ///< per edge: split because two loops of a face are close
  std::vector<std::vector<std::array<int, 2>>> constraint_;
  std::vector<std::vector<int>> face_extra_nodes_;
  std::vector<char> face_given_;
  std::vector<std::array<int, 2>> face_alias_;  ///< (src, reversed); src -1: none
  std::vector<std::vector<std::array<int, 3>>> face_tris_;
  std::vector<int> failed_;
  std::vector<std::string> reasons_;
  std::vector<std::pair<int, std::string>> retried_;
};

/// The number of directed edges of the triangles T (#T by 3) not used exactly once each way
/// (0 for a closed, consistently oriented surface): check_surface(T).unpaired_edges of
/// common/closed_surface.h, under the name the 14 steps use.
long open_edges(const MatX3i& T);

/// Per solid of `topo`: the number of mesh edges not used exactly twice in opposite directions
/// by the triangles of that solid's faces (0 for a closed, consistently oriented surface).
std::vector<long> open_edges_per_solid(const brep::TopologyIndex& topo, const SurfaceMesh& mesh);

/// The triangles (rows of mesh.F) on the faces of solid s (0-based), oriented out of that
/// solid, as their own triangle list over mesh.V.
MatX3i solid_triangles(const brep::TopologyIndex& topo, const SurfaceMesh& mesh, int s);

}  // namespace topopt::mesh
