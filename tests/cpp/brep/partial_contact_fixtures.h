// Parts with partial contact between the non-design solids Ω̄ and the part Ω, built in code
// from OCCT primitives (issue 20): every configuration a user makes where a non-design solid
// reaches the part's boundary or touches another on a face that is not identical to its own.
// Sizes in mm; each fixture is (part, non-design compound) ready for brep::load_two_breps.
#pragma once
#include <TopoDS_Shape.hxx>
#include <string>
#include <vector>

namespace topopt::testing {

struct PartialContactFixture {
  std::string name;
  TopoDS_Shape part;       ///< Ω: one solid
  TopoDS_Shape nondesign;  ///< Ω̄: a compound of solids inside Ω
};

/// A plate 60 x 40 x 8 with two bolt bosses (r 6, bore r 3) standing 6 mm out of its top face
/// and flush with its bottom face; Ω̄ = the two bosses (their outer cylinders: 8 mm inside the
/// plate, 6 mm on the part's boundary).
PartialContactFixture plate_with_bosses_on_one_side();

/// A plate 60 x 40 x 8 with a lug (r 10, bore r 5) centred on its edge x = 60, half outside it;
/// Ω̄ = the lug ring, whose outer cylinder is cut by the plate's outer face x = 60.
PartialContactFixture bracket_with_lug_cut_by_outer_face();

/// A cylinder r 20, height 30, with a boss r 5 along x standing out of its wall to x = 30;
/// Ω̄ = the boss from x = 12: its cylinder half inside the big cylinder, half outside.
PartialContactFixture boss_on_cylinder_wall();

/// A block 60 x 40 whose top is an arch z = 10 + 4 sin(pi x / 60) (every face converted to
/// B-splines), with a boss r 5 on the vertical axis at (30, 20) from z = 0 to 20; Ω̄ = the
/// boss, whose cylinder leaves the part along its intersection with the B-spline top.
PartialContactFixture boss_on_bspline_wall();

/// Two boxes fused into a part 40 x 30 x 20 whose top is two faces (x < 20, x > 20); Ω̄ = a pad
/// 10 x 10 x 5 under the top whose top face spans both.
PartialContactFixture pad_spanning_two_faces();

/// A box 40 x 30 x 20 with two pads on its bottom face touching at x = 20: pad A's face there
/// (5 x 5) lies inside pad B's (20 x 8).
PartialContactFixture pads_touching_on_unequal_faces();

/// All of the above, in this order.
std::vector<PartialContactFixture> partial_contact_fixtures();

}  // namespace topopt::testing
