// Classification of the non-design model Ω̄ against the part Ω: for every vertex, edge and
// face of Ω̄, the entity of Ω it lies on, with parameters. This drives every transfer of the
// 14 steps (a node on a vertex of Ω̄ that lies on an edge of Ω is meshed with that edge, ...).
// The two models come from different files, so coincidence is decided geometrically with
// the shapes' tolerances, never from shared TShapes.
#pragma once
#include <string>
#include <vector>

#include "brep/topology_index.h"

namespace topopt::brep {

/// The kind of entity a point set lies on.
enum class On { Interior, Vertex, Edge, Face };
const char* on_name(On on);

/// Where one entity of Ω̄ lies on Ω.
struct Location {
  On on = On::Interior;  ///< Interior: inside the solid, on no entity of the other model
  int index = -1;        ///< 0-based index of the vertex / edge / face it lies on
  /// Parameters on that entity: a vertex on an edge: t[0] = curve parameter; a vertex on a
  /// face: (t[0], t[1]) = (u, v); an edge on an edge: [t[0], t[1]] = curve range covered.
  double t[2]{0, 0};
  double distance = 0;  ///< largest distance of the samples to that entity
};

struct ClassifyParams {
  /// Absolute tolerance (model units) added to the shapes' own tolerances; <= 0 means
  /// 1e-6 times the part's bounding-box diagonal.
  double tolerance = -1;
  /// Samples per edge (interior points; the end vertices are classified separately).
  int edge_samples = 7;
  /// Upper bound on the samples taken on a face (from a coarse triangulation's centroids).
  int face_samples = 24;
  /// CPU seconds (of the calling thread) the imprint of the part's boundary on the non-design
  /// solids may take (imprint.h) before it stops with Error(Timeout); must be > 0.
  double imprint_seconds = 120;
};

/// Classification of every entity of `other` against `base`.
struct Classification {
  std::vector<Location> vertex;  ///< one per vertex of `other`
  std::vector<Location> edge;    ///< one per edge of `other`
  std::vector<Location> face;    ///< one per face of `other`
};

/// Classifies each vertex, edge and face of `other` against `base`. An entity that lies on
/// no entity of `base` is Interior (whether it is inside base at all is check_containment's
/// business). A vertex is tested against vertices, then edges, then faces; an edge and a face
/// are "on" an entity only when all their samples are on that one entity.
Classification classify(const TopologyIndex& base, const TopologyIndex& other, const ClassifyParams& params = {});

/// Contact between two non-design solids: the faces of solid a that lie on faces of solid b.
struct Contact {
  int solid_a = -1, solid_b = -1;          ///< 0-based solid indices in the non-design model
  std::vector<std::pair<int, int>> faces;  ///< (face of a, face of b), 0-based model indices
};

/// Relations among the non-design solids and with the part.
struct ContainmentReport {
  std::vector<Contact> contacts;      ///< pairs of solids that touch (allowed)
  std::vector<std::string> warnings;  ///< things worth telling the user
};

/// The distance below which entities of the two models coincide: params.tolerance, or 1e-6
/// times base's bounding-box diagonal (at least 1e-6) when that is <= 0.
double coincidence_tolerance(const TopologyIndex& base, const ClassifyParams& params);

/// Whether solids i and j (0-based) of `nondesign` come within `tol` of each other; if they do,
/// `contact` gets the pairs (face of i, face of j) whose samples lie on each other (empty when
/// they touch along an edge or at a point only).
bool touching(const TopologyIndex& nondesign, int i, int j, double tol, Contact& contact);

/// Checks that every solid of `nondesign` lies inside the single solid of `part` and that no
/// two non-design solids overlap; finds the pairs that touch. Throws Error(NonDesignOutside)
/// or Error(NonDesignOverlap) naming the solids and the volume concerned.
ContainmentReport check_containment(const TopologyIndex& part, const TopologyIndex& nondesign,
                                    const ClassifyParams& params = {});

}  // namespace topopt::brep
