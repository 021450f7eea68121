// SIMP on the distributed mesh: the serial loop of simp::optimize (FE analysis → objective and
// sensitivities → filter → OC update → continuation), each rank on its own design tets, with
// the global quantities (compliance, volume, the OC multiplier's bisection, the largest change,
// the grey share) as MPI reductions. The kernels are simp's: the SIMP law, the Heaviside
// projection, oc_update with MoveLimits, Continuation; the filter is the Helmholtz PDE on
// PETSc (dist_helmholtz.h) and the FE solve dist_elasticity.h.
//
// Not (yet) distributed: MMA (its dual is a sum over all variables inside a bisection),
// Sigmund's sensitivity filter, the explicit (Gaussian, cone) filters, self-weight.
#pragma once
#include <functional>
#include <vector>

#include "common/progress.h"
#include "dist/dist_elasticity.h"
#include "dist/dist_mesh.h"
#include "simp/optimizer.h"

namespace topopt::dist {

/// Throws Error(InvalidParameter) naming the job key to change when `params` (or self-weight,
/// `gravity` non-zero) ask for what the distributed SIMP does not do.
void check_distributable(const simp::SimpParams& params, bool gravity);

/// Runs SIMP on this rank's part of the mesh (mesh.loads: the load cases; weights: #cases).
/// params.filter must be the Helmholtz kind (radius > 0, already resolved). Collective. Returns
/// on rank 0 the result as simp::optimize gives it, in the serial mesh's numbering (density
/// #T, design and variables #D); on the other ranks the history alone. on_iteration and
/// progress are used on rank 0 only.
simp::SimpResult optimize_mesh(const MpiSession& session, const DistMesh& mesh, const fem::Material& material,
                               const std::vector<double>& weights, const simp::SimpParams& params,
                               const DistSolverParams& solver, const Progress& progress = {},
                               const std::function<void(const simp::IterationRecord&)>& on_iteration = {});

}  // namespace topopt::dist
