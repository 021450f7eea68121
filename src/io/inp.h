// CalculiX / Abaqus input (.inp) of a linear static problem on C3D4 elements, so that anyone
// can check our solve with ccx.
#pragma once
#include <string>

#include "common/types.h"
#include "fem/elasticity.h"

namespace topopt::io {

/// Writes the mesh (one ELSET per domain: DESIGN, NONDESIGN1, …), the material, the fixed
/// dofs of `supports` (*BOUNDARY) and load case `load_case` of `loads` ((3*#V) by #cases,
/// *CLOAD), one *STATIC step printing displacements (*NODE PRINT → .dat, *NODE FILE → .frd).
/// `scale` (#T, optional): per-element stiffness factors, written as one material per distinct
/// factor. Throws Error(Io) if the file cannot be written.
void write_inp(const std::string& path, const TetMesh& mesh, const fem::Material& material,
               const fem::Supports& supports, const Eigen::MatrixXd& loads, int load_case = 0,
               const VecXd& scale = VecXd());

/// Displacements (#V by 3) read from the .dat file that ccx writes for our .inp (*NODE PRINT
/// of U). Throws Error(Io) if the file has no displacement table.
MatX3d read_ccx_displacements(const std::string& dat_path, int num_nodes);

}  // namespace topopt::io
