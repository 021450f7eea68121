// Test helper of the sparse kernel tests: a CsrMatrix written out dense, so that its products can be
// checked against Eigen's arithmetic (duplicate entries of a row summed, as the kernels sum them).
#pragma once
#include <Eigen/Dense>

#include "fem/csr_matrix.h"

namespace topopt::fem {

inline Eigen::MatrixXd dense(const CsrMatrix& M) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(M.rows, M.cols);
  for (int i = 0; i < M.rows; ++i)
    for (int k = M.ptr[i]; k < M.ptr[i + 1]; ++k) D(i, M.col[k]) += M.val[k];
  return D;
}

}  // namespace topopt::fem
