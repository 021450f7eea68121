// Tests of src/brep: reading, checking, indexing and classifying the two models.
#include "brep/classify.h"

#include <gtest/gtest.h>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRep_Builder.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Ax2.hxx>

#include <filesystem>

#include "brep/report.h"
#include "brep/shape_io.h"
#include "brep/two_breps.h"
#include "common/error.h"

using namespace topopt;
using namespace topopt::brep;

namespace {

TopoDS_Shape box(double x, double y, double z, double dx, double dy, double dz) {
  return BRepPrimAPI_MakeBox(gp_Pnt(x, y, z), dx, dy, dz).Shape();
}

TopoDS_Shape compound(std::initializer_list<TopoDS_Shape> shapes) {
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  for (const auto& s : shapes) b.Add(c, s);
  return c;
}

/// Index of the face of `t` whose centre is nearest `p` (0-based).
int face_near(const TopologyIndex& t, double x, double y, double z) {
  int best = -1;
  double bd = 1e300;
  for (int f = 0; f < t.num_faces(); ++f) {
    double d = (t.face_centre.row(f) - Eigen::RowVector3d(x, y, z)).norm();
    if (d < bd) bd = d, best = f;
  }
  return best;
}

ErrorCode code_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.code();
  }
  return ErrorCode::Internal;
}

std::string shared(const std::string& rel) { return std::string(TOPOPT_SHARED_DATA) + "/" + rel; }

}  // namespace

TEST(TopologyIndex, BoxCountsAndAdjacency) {
  TopologyIndex t = index_topology(box(0, 0, 0, 10, 20, 30));
  EXPECT_EQ(t.num_solids(), 1);
  EXPECT_EQ(t.num_faces(), 6);
  EXPECT_EQ(t.num_edges(), 12);
  EXPECT_EQ(t.num_vertices(), 8);
  EXPECT_NEAR(t.solid_volume[0], 6000.0, 1e-9);
  double area = t.face_area.sum();
  EXPECT_NEAR(area, 2 * (200 + 600 + 300), 1e-9);
  for (int f = 0; f < 6; ++f) {
    EXPECT_EQ(t.face_edges.size(f), 4);
    EXPECT_EQ(t.face_surface[f], "Plane");
    EXPECT_EQ(t.face_solid[f], 0);
  }
  for (int e = 0; e < 12; ++e)
    EXPECT_NEAR(t.edge_length[e],
                (t.vertex_point.row(t.edge_vertices(e, 0)) - t.vertex_point.row(t.edge_vertices(e, 1))).norm(), 1e-12);
  EXPECT_NEAR(t.diagonal(), std::sqrt(100 + 400 + 900), 1e-5);  // boxes carry the tolerance
}

TEST(Classify, BoxOnFloorOfBox) {
  // Ω = [0,10]^3; Ω̄ = [2,5]x[0,3]x[0,3]: its bottom (z=0) and front (y=0) faces lie on Ω's,
  // its edge along y=0,z=0 lies on Ω's edge, two of its vertices lie on that edge.
  TopologyIndex part = index_topology(box(0, 0, 0, 10, 10, 10));
  TopologyIndex nd = index_topology(box(2, 0, 0, 3, 3, 3));
  Classification c = classify(part, nd);
  ASSERT_EQ(c.face.size(), 6u);
  int bottom = face_near(nd, 3.5, 1.5, 0), front = face_near(nd, 3.5, 0, 1.5), top = face_near(nd, 3.5, 1.5, 3);
  EXPECT_EQ(c.face[bottom].on, On::Face);
  EXPECT_EQ(c.face[bottom].index, face_near(part, 5, 5, 0));
  EXPECT_EQ(c.face[front].on, On::Face);
  EXPECT_EQ(c.face[front].index, face_near(part, 5, 0, 5));
  EXPECT_EQ(c.face[top].on, On::Interior);
  int on_edge_vertices = 0, on_face_vertices = 0, interior_vertices = 0;
  for (const Location& v : c.vertex) {
    on_edge_vertices += v.on == On::Edge;
    on_face_vertices += v.on == On::Face;
    interior_vertices += v.on == On::Interior;
  }
  EXPECT_EQ(on_edge_vertices, 2);   // (2,0,0), (5,0,0)
  EXPECT_EQ(on_face_vertices, 4);   // on y=0 or z=0 but not both
  EXPECT_EQ(interior_vertices, 2);  // (2,3,3), (5,3,3)
  int edge_on_edge = 0;
  for (const Location& e : c.edge)
    if (e.on == On::Edge) {
      ++edge_on_edge;
      EXPECT_NEAR(std::abs(e.t[1] - e.t[0]), 3.0, 1e-9);  // covers [2,5] of the 10 mm edge
    }
  EXPECT_EQ(edge_on_edge, 1);
}

TEST(Classify, VertexOnVertexAndCylinderOnCylinder) {
  // A ring around a bore through a plate: the ring's bore face lies on the plate's bore face.
  TopoDS_Shape plate = BRepAlgoAPI_Cut(box(-20, -20, 0, 40, 40, 5),
                                       BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp::DZ()), 4, 5).Shape())
                           .Shape();
  TopoDS_Shape ring = BRepAlgoAPI_Cut(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp::DZ()), 8, 5).Shape(),
                                      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp::DZ()), 4, 5).Shape())
                          .Shape();
  TopologyIndex part = index_topology(plate), nd = index_topology(ring);
  Classification c = classify(part, nd);
  int cyl_on = 0, cyl_interior = 0, planes_on = 0;
  for (int f = 0; f < nd.num_faces(); ++f) {
    if (nd.face_surface[f] == "Cylinder") {
      double r = std::hypot(nd.face_centre(f, 0), nd.face_centre(f, 1));
      (void)r;
      if (c.face[f].on == On::Face) {
        ++cyl_on;
        EXPECT_EQ(part.face_surface[c.face[f].index], "Cylinder");
      } else {
        ++cyl_interior;
      }
    } else if (c.face[f].on == On::Face) {
      ++planes_on;
    }
  }
  EXPECT_EQ(cyl_on, 1);
  EXPECT_EQ(cyl_interior, 1);
  EXPECT_EQ(planes_on, 2);
  for (int v = 0; v < nd.num_vertices(); ++v) {
    bool inner = std::hypot(nd.vertex_point(v, 0), nd.vertex_point(v, 1)) < 6;
    EXPECT_EQ(c.vertex[v].on, inner ? On::Vertex : On::Face) << "vertex " << v;
  }
}

TEST(Containment, OutsideOverlapAndContact) {
  TopologyIndex part = index_topology(box(0, 0, 0, 10, 10, 10));
  auto outside = index_topology(compound({box(8, 8, 8, 4, 1, 1)}));
  EXPECT_EQ(code_of([&] { check_containment(part, outside); }), ErrorCode::NonDesignOutside);
  auto far = index_topology(compound({box(20, 20, 20, 1, 1, 1)}));
  EXPECT_EQ(code_of([&] { check_containment(part, far); }), ErrorCode::NonDesignOutside);
  auto overlap = index_topology(compound({box(1, 1, 1, 3, 3, 3), box(2, 2, 2, 3, 3, 3)}));
  EXPECT_EQ(code_of([&] { check_containment(part, overlap); }), ErrorCode::NonDesignOverlap);
  auto touching = index_topology(compound({box(1, 1, 1, 3, 3, 3), box(4, 1, 1, 2, 3, 3), box(7, 7, 7, 1, 1, 1)}));
  ContainmentReport r = check_containment(part, touching);
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_EQ(r.contacts[0].solid_a, 0);
  EXPECT_EQ(r.contacts[0].solid_b, 1);
  ASSERT_EQ(r.contacts[0].faces.size(), 1u);
  EXPECT_NEAR(touching.face_centre(r.contacts[0].faces[0].first, 0), 4.0, 1e-9);
  EXPECT_NEAR(touching.face_centre(r.contacts[0].faces[0].second, 0), 4.0, 1e-9);
}

TEST(SolidCheck, NotASolidAndOpenShell) {
  std::vector<std::string> notes;
  TopoDS_Shape face = BRepBuilderAPI_MakeFace(
                          BRepBuilderAPI_MakePolygon(gp_Pnt(0, 0, 0), gp_Pnt(1, 0, 0), gp_Pnt(1, 1, 0), true).Wire())
                          .Shape();
  try {
    load_two_breps(face, TopoDS_Shape());
    FAIL() << "a face was accepted as the part";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidShape);
    EXPECT_NE(std::string(e.what()).find("not a solid"), std::string::npos) << e.what();
  }
  // A box's shell with one face removed is open.
  TopoDS_Shape b = box(0, 0, 0, 1, 1, 1);
  TopologyIndex t = index_topology(b);
  TopoDS_Shell shell;
  BRep_Builder builder;
  builder.MakeShell(shell);
  for (int f = 1; f < 6; ++f) builder.Add(shell, t.faces(f));
  EXPECT_EQ(code_of([&] { load_two_breps(box(-1, -1, -1, 3, 3, 3), shell); }), ErrorCode::InvalidShape);
  // Two solids as the part.
  EXPECT_EQ(code_of([&] {
              load_two_breps(compound({box(0, 0, 0, 1, 1, 1), box(2, 0, 0, 1, 1, 1)}), TopoDS_Shape());
            }),
            ErrorCode::InvalidShape);
}

TEST(SolidCheck, ReversedSolidIsTurnedOutwards) {
  std::vector<std::string> notes;
  TopoDS_Shape b = box(0, 0, 0, 2, 2, 2).Reversed();
  TwoBReps m = load_two_breps(b, TopoDS_Shape());
  EXPECT_NEAR(m.part.solid_volume[0], 8.0, 1e-9);
  ASSERT_EQ(m.notes.size(), 1u);
  EXPECT_NE(m.notes[0].find("inside out"), std::string::npos);
}

TEST(ShapeIO, MissingFileAndBadText) {
  EXPECT_EQ(code_of([] { read_shape_file("/nonexistent/part.step"); }), ErrorCode::Io);
  EXPECT_EQ(code_of([] { read_shape_file(TOPOPT_SHARED_DATA "/README.md"); }), ErrorCode::Io);
  EXPECT_EQ(code_of([] { read_brep_string("this is not a shape"); }), ErrorCode::Io);
  TopoDS_Shape b = box(0, 0, 0, 1, 2, 3);
  TopologyIndex t = index_topology(read_brep_string(write_brep_string(b)));
  EXPECT_NEAR(t.solid_volume[0], 6.0, 1e-12);
}

TEST(Examples, RockerRingsLieOnBoresAndFaces) {
  TwoBReps m = load_two_breps(read_shape_file(shared("examples/rocker.step")),
                              read_shape_file(shared("examples/rocker_nondesign.step")));
  ASSERT_EQ(m.nondesign.num_solids(), 3);
  EXPECT_TRUE(m.relations.contacts.empty());
  const double bore_r[3] = {6, 5, 4};
  const double cx[3] = {0, 80, 40}, cy[3] = {0, 10, 55};
  for (int s = 0; s < 3; ++s) {
    int bore = 0, outer = 0, caps = 0;
    for (const int* f = m.nondesign.solid_faces.begin(s); f != m.nondesign.solid_faces.end(s); ++f) {
      const Location& loc = m.nd_on_part.face[*f];
      if (m.nondesign.face_surface[*f] == "Plane") {
        ASSERT_EQ(loc.on, On::Face) << "ring " << s + 1 << " cap";
        EXPECT_EQ(m.part.face_surface[loc.index], "Plane");
        ++caps;
        continue;
      }
      // Cylinders: tell the bore from the outside by the radius at a sample vertex.
      double r = 1e300;
      for (const int* e = m.nondesign.face_edges.begin(*f); e != m.nondesign.face_edges.end(*f); ++e)
        for (int end = 0; end < 2; ++end) {
          int v = m.nondesign.edge_vertices(*e, end);
          r = std::min(r, std::hypot(m.nondesign.vertex_point(v, 0) - cx[s], m.nondesign.vertex_point(v, 1) - cy[s]));
        }
      if (std::abs(r - bore_r[s]) < 1e-3) {
        ASSERT_EQ(loc.on, On::Face) << "ring " << s + 1 << " bore";
        EXPECT_EQ(m.part.face_surface[loc.index], "Cylinder");
        ++bore;
      } else {
        EXPECT_EQ(loc.on, On::Interior) << "ring " << s + 1 << " outer cylinder";
        ++outer;
      }
    }
    EXPECT_EQ(caps, 2);
    EXPECT_GE(bore, 1);
    EXPECT_GE(outer, 1);
  }
}

TEST(Examples, BracketClampPadsTouch) {
  TwoBReps m = load_two_breps(read_shape_file(shared("examples/bracket.step")),
                              read_shape_file(shared("examples/bracket_nondesign.step")));
  EXPECT_EQ(m.nondesign.num_solids(), 7);
  ASSERT_GE(m.relations.contacts.size(), 1u);
  bool pads = false;
  for (const Contact& c : m.relations.contacts)
    for (auto [a, b] : c.faces)
      if (std::abs(m.nondesign.face_centre(a, 0) - 52) < 1e-6 && std::abs(m.nondesign.face_centre(b, 0) - 52) < 1e-6)
        pads = true;
  EXPECT_TRUE(pads) << two_breps_summary(m);
}
