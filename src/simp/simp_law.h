// The SIMP material law, written once with its derivative (top88's E(ρ)).
#pragma once
#include <cmath>

namespace topopt::simp {

/// Relative stiffness E(ρ)/E0 = e_min + ρ^p (1 − e_min), ρ in [0, 1]; below linear_below
/// (if set) linear in ρ instead, e_min + ρ ρ0^(p−1) (1 − e_min), continuous at ρ0. With
/// self-weight the load of an element grows like ρ: under ρ^p alone its stiffness would
/// vanish faster than its weight and near-void elements would carry huge displacements
/// (Bruyneel & Duysinx 2005).
struct SimpLaw {
  double penalty = 3.0;     ///< p
  double e_min = 1e-9;      ///< stiffness of void relative to solid, keeps K regular
  double linear_below = 0;  ///< ρ0; 0: the power law everywhere

  double stiffness(double rho) const {
    if (rho < linear_below) return e_min + rho * std::pow(linear_below, penalty - 1) * (1 - e_min);
    return e_min + std::pow(rho, penalty) * (1 - e_min);
  }
  /// dE/dρ (relative)
  double derivative(double rho) const {
    if (rho < linear_below) return std::pow(linear_below, penalty - 1) * (1 - e_min);
    return penalty * std::pow(rho, penalty - 1) * (1 - e_min);
  }
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
