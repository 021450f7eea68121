// The SIMP material law, written once with its derivative (top88's E(ρ)).
#pragma once
#include <cmath>

namespace topopt::simp {

/// Relative stiffness E(ρ)/E0 = e_min + ρ^p (1 − e_min), ρ in [0, 1].
struct SimpLaw {
  double penalty = 3.0;  ///< p
  double e_min = 1e-9;   ///< stiffness of void relative to solid, keeps K regular

  double stiffness(double rho) const { return e_min + std::pow(rho, penalty) * (1 - e_min); }
  /// dE/dρ (relative)
  double derivative(double rho) const { return penalty * std::pow(rho, penalty - 1) * (1 - e_min); }
};

/// Smoothed Heaviside projection ρ̄ = (tanh(βη) + tanh(β(ρ̃−η))) / (tanh(βη) + tanh(β(1−η)))
/// (Wang, Lazarov & Sigmund 2011), with its derivative.
struct Heaviside {
  double beta = 1.0, eta = 0.5;
  double value(double x) const {
    return (std::tanh(beta * eta) + std::tanh(beta * (x - eta))) /
           (std::tanh(beta * eta) + std::tanh(beta * (1 - eta)));
  }
  double derivative(double x) const {
    double s = 1.0 / std::cosh(beta * (x - eta));
    return beta * s * s / (std::tanh(beta * eta) + std::tanh(beta * (1 - eta)));
  }
};

}  // namespace topopt::simp
