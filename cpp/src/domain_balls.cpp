// Stage 2: domain balls (Def. 1). See dcg/domain_balls.h and ALGORITHM.md "2. Domain balls".
//
// Greedy, largest first, ties broken by candidate index (deterministic). Accepted balls are
// registered in a hashed uniform grid in every cell that their box of half-width r + gap / 2
// overlaps: two balls conflict (|c_i - c_j| <= r_i + r_j + gap) only if those boxes overlap, so
// a candidate only looks at the cells of its own box, nearest shells first, and stops at the
// first conflict. Accepted balls are disjoint, so the cells they fill are bounded by the
// shape's volume; the cell size is the median candidate radius (at least gap + 2 min_radius).
#include "dcg/domain_balls.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <unordered_map>
#include <vector>

#include "dcg/errors.h"
#include "dcg/options.h"
#include "polling.h"

namespace dcg {

DomainBalls compute_domain_balls(const Balls& candidates, const DomainBallsOptions& options,
                                 const Progress& progress, double from, double to) {
  check_option("min_gap", options.min_gap);
  check_option("min_radius", options.min_radius);
  internal::ThrottledProgress tick(progress, "domain_balls", from, to);
  tick(0);
  const Eigen::Index n = candidates.centers.rows();
  if (candidates.radii.size() != n) {
    throw InputError("domain balls: " + std::to_string(n) + " centers but " +
                     std::to_string(candidates.radii.size()) + " radii");
  }
  std::vector<int> order;
  order.reserve(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double r = candidates.radii[i];
    if (!std::isfinite(r) || !candidates.centers.row(i).allFinite()) {
      throw InputError("domain balls: candidate " + std::to_string(i) + " is not finite");
    }
    if (r >= options.min_radius && r > 0) order.push_back(static_cast<int>(i));
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    const double ra = candidates.radii[a], rb = candidates.radii[b];
    return ra != rb ? ra > rb : a < b;
  });
  DomainBalls out;
  if (order.empty()) {
    out.balls.centers.resize(0, 3);
    out.balls.radii.resize(0);
    return out;
  }
  const double gap = options.min_gap;
  double cell = candidates.radii[order[order.size() / 2]];
  cell = std::max({cell, gap + 2.0 * options.min_radius, 1e-9});
  Eigen::RowVector3d lo = candidates.centers.row(order[0]);
  for (int i : order) lo = lo.cwiseMin(candidates.centers.row(i));
  auto cell_coord = [&](double x, int axis) {
    return static_cast<std::int64_t>(std::floor((x - lo[axis]) / cell));
  };
  auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return static_cast<std::uint64_t>(((x & 0x1fffff) << 42) | ((y & 0x1fffff) << 21) |
                                      (z & 0x1fffff));
  };
  std::unordered_map<std::uint64_t, std::vector<int>> grid;
  std::vector<int> accepted;
  std::size_t visited = 0;
  for (int i : order) {
    if ((visited++ & 255) == 0) tick(static_cast<double>(visited) / order.size());
    const Eigen::RowVector3d c = candidates.centers.row(i);
    const double r = candidates.radii[i];
    const double h = r + 0.5 * gap;
    std::int64_t b0[3], b1[3], m[3];
    for (int a = 0; a < 3; ++a) {
      b0[a] = cell_coord(c[a] - h, a);
      b1[a] = cell_coord(c[a] + h, a);
      m[a] = cell_coord(c[a], a);
    }
    const std::int64_t shells = std::max(
        {m[0] - b0[0], b1[0] - m[0], m[1] - b0[1], b1[1] - m[1], m[2] - b0[2], b1[2] - m[2]});
    bool conflict = false;
    for (std::int64_t s = 0; s <= shells && !conflict; ++s) {
      for (std::int64_t x = std::max(b0[0], m[0] - s); x <= std::min(b1[0], m[0] + s) && !conflict;
           ++x)
        for (std::int64_t y = std::max(b0[1], m[1] - s);
             y <= std::min(b1[1], m[1] + s) && !conflict; ++y)
          for (std::int64_t z = std::max(b0[2], m[2] - s);
               z <= std::min(b1[2], m[2] + s) && !conflict; ++z) {
            // Only the cells of shell s (Chebyshev distance s from the center's cell).
            if (std::max({std::abs(x - m[0]), std::abs(y - m[1]), std::abs(z - m[2])}) != s)
              continue;
            auto it = grid.find(key(x, y, z));
            if (it == grid.end()) continue;
            for (int j : it->second) {
              const double rr = r + candidates.radii[j] + gap;
              if ((candidates.centers.row(j) - c).squaredNorm() <= rr * rr) {
                conflict = true;
                break;
              }
            }
          }
    }
    if (conflict) continue;
    accepted.push_back(i);
    for (std::int64_t x = b0[0]; x <= b1[0]; ++x)
      for (std::int64_t y = b0[1]; y <= b1[1]; ++y)
        for (std::int64_t z = b0[2]; z <= b1[2]; ++z) grid[key(x, y, z)].push_back(i);
  }
  const Eigen::Index k = static_cast<Eigen::Index>(accepted.size());
  out.balls.centers.resize(k, 3);
  out.balls.radii.resize(k);
  out.source = accepted;
  for (Eigen::Index a = 0; a < k; ++a) {
    out.balls.centers.row(a) = candidates.centers.row(accepted[a]);
    out.balls.radii[a] = candidates.radii[accepted[a]];
  }
  return out;
}

}  // namespace dcg
