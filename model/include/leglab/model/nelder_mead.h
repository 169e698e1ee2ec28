#pragma once

#include <functional>
#include <vector>

namespace leglab {

/// A function of n variables for NelderMead: its value at a point (size n). +infinity marks a
/// point the search may not go to: such a vertex is never kept as best while any finite one is.
using SimplexObjective = std::function<double(const std::vector<double>& point)>;

/// Minimises `f` over R^n, derivative-free, by the Nelder-Mead simplex method (Nelder and Mead
/// 1965) with the standard coefficients: reflection 1, expansion 2, contraction 1/2 (inside and
/// outside), shrink 1/2 towards the best vertex. The first simplex is x and x + step_i e_i for
/// i = 0..n-1. Stops when every vertex is within `tolerance` of the best one in every
/// coordinate, or after `max_iterations` iterations (one reflection each, then at most an
/// expansion, a contraction or a shrink). A local method: it may stop at a kink or a saddle,
/// which is why it suits objectives where derivative steps stall (a minimum on a kink).
/// Writes the best vertex into `x` and returns f there.
/// Preconditions: n = x.size() >= 1, step.size() == n, every step_i != 0, f(x) finite.
/// Deterministic: the same input gives the same bits.
double NelderMead(const SimplexObjective& f, std::vector<double>& x,
                  const std::vector<double>& step, int max_iterations, double tolerance = 1e-9);

}  // namespace leglab
