// Checks of an optimisation problem on its mesh, before SIMP starts, that turn what would
// fail deep inside (a singular update, a filter that eats the memory) into a message that
// says what to change: loads that put no force on the part, and a filter radius larger than
// the part or asking for more neighbour pairs than memory holds.
#pragma once
#include <string>
#include <vector>

#include "common/types.h"
#include "fem/boundary_conditions.h"
#include "simp/filter.h"
#include "simp/optimizer.h"

namespace topopt::pipeline {

/// Per load case (column c of `loads`, (3*#V) by #cases, named by cases[c].name): throws
/// Error(InvalidParameter) when its loads sum to nothing ("give a force that is not zero")
/// or act only on degrees of freedom the supports fix ("move the load or the support").
void check_loads_reach_the_part(const Eigen::MatrixXd& loads, const fem::Supports& supports,
                                const std::vector<fem::LoadCase>& cases);

/// About how many (element, neighbour) pairs a density filter of `radius` holds over the
/// design tets of `mesh` (domain 0): the neighbours of up to 64 tets spread over the design,
/// counted exactly, times the number of design tets.
double estimated_filter_pairs(const TetMesh& mesh, double radius);

/// The same estimate for the radii (k + 1) / bins × radius, k = 0 .. bins - 1 (one pass).
std::vector<double> filter_pairs_within(const TetMesh& mesh, double radius, int bins);

/// Throws Error(InvalidParameter) when `radius` (mm; given = the user set
/// 'optimization.filter_radius') exceeds the part's diagonal, and Error(TooLarge) when the
/// filter's estimated pairs need more than half of `memory_bytes` (each pair ~90 bytes
/// while the filter is built); both name the largest radius to use, or a coarser mesh when
/// the radius was the automatic one.
void check_filter_radius(const TetMesh& mesh, double radius, bool given, double memory_bytes);

/// The filter a job runs with (radius resolved): the kind it names, or for "auto" (automatic)
/// simp::choose_filter_kind's choice from the estimated neighbour pairs and half of
/// `memory_bytes`. An explicit kind is checked by check_filter_radius; the Helmholtz filter
/// only for a radius beyond the part. `note` (may be null) gets a line saying what was chosen
/// and why when "auto" chose the Helmholtz filter.
simp::FilterParams chosen_filter(const TetMesh& mesh, const simp::FilterParams& requested, bool automatic,
                                 double memory_bytes, std::string* note);

/// The machine's physical memory in bytes (0 when unknown: no memory check).
double physical_memory_bytes();

/// After SIMP: a warning (empty when none) when the run stopped at its iteration cap before
/// the design was crisp — the projection short of its final β, or more than 3 % of the design
/// volume grey in the last iteration — naming both figures and the key to raise
/// ('optimization.max_iterations', the study's MaxIterations in FreeCAD).
std::string not_crisp_warning(const simp::SimpResult& result, const simp::SimpParams& params);

}  // namespace topopt::pipeline
