#include "leglab/model/nelder_mead.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>

namespace leglab {

double NelderMead(const SimplexObjective& f, std::vector<double>& x,
                  const std::vector<double>& step, int max_iterations, double tolerance) {
  const size_t n = x.size();
  assert(n >= 1 && step.size() == n);
  std::vector<std::vector<double>> simplex(n + 1, x);
  for (size_t i = 0; i < n; ++i) simplex[i + 1][i] += step[i];
  std::vector<double> value(n + 1);
  for (size_t i = 0; i <= n; ++i) value[i] = f(simplex[i]);
  std::vector<size_t> order(n + 1);
  std::vector<double> centroid(n);
  // The trial points' storage, reused (an accepted point is swapped into the simplex).
  std::vector<double> reflected(n), other(n);
  auto along = [&](double t, size_t worst, std::vector<double>& point) {
    for (size_t d = 0; d < n; ++d) point[d] = centroid[d] + t * (simplex[worst][d] - centroid[d]);
  };
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    std::iota(order.begin(), order.end(), size_t{0});
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return value[a] < value[b]; });
    const size_t best = order[0], worst = order[n], second_worst = order[n - 1];
    double size = 0.0;
    for (size_t i = 1; i <= n; ++i) {
      for (size_t d = 0; d < n; ++d) {
        size = std::max(size, std::abs(simplex[order[i]][d] - simplex[best][d]));
      }
    }
    if (size < tolerance) break;
    std::fill(centroid.begin(), centroid.end(), 0.0);
    for (size_t i = 0; i < n; ++i) {
      for (size_t d = 0; d < n; ++d) centroid[d] += simplex[order[i]][d] / static_cast<double>(n);
    }
    along(-1.0, worst, reflected);
    const double reflected_value = f(reflected);
    if (reflected_value < value[best]) {
      along(-2.0, worst, other);
      const double expanded_value = f(other);
      if (expanded_value < reflected_value) {
        simplex[worst].swap(other), value[worst] = expanded_value;
      } else {
        simplex[worst].swap(reflected), value[worst] = reflected_value;
      }
    } else if (reflected_value < value[second_worst]) {
      simplex[worst].swap(reflected), value[worst] = reflected_value;
    } else {
      const bool outside = reflected_value < value[worst];
      along(outside ? -0.5 : 0.5, worst, other);
      const double contracted_value = f(other);
      if (contracted_value < (outside ? reflected_value : value[worst])) {
        simplex[worst].swap(other), value[worst] = contracted_value;
      } else {  // shrink towards the best vertex
        for (size_t i = 1; i <= n; ++i) {
          for (size_t d = 0; d < n; ++d) {
            simplex[order[i]][d] = 0.5 * (simplex[order[i]][d] + simplex[best][d]);
          }
          value[order[i]] = f(simplex[order[i]]);
        }
      }
    }
  }
  const size_t best =
      static_cast<size_t>(std::min_element(value.begin(), value.end()) - value.begin());
  x = simplex[best];
  return value[best];
}

}  // namespace leglab
