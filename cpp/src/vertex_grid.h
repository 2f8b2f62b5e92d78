// Nearest-vertex distances by a uniform grid: the mirror tests of stage 3 (ProngHierarchy::
// mirrors_mesh) ask for a thousand of them per plane, which a scan of every vertex made cost
// tens of milliseconds a plane on a 12k-vertex mesh. The grid keeps its own copy of the points
// (in cell order), so it can be shared by copies of its owner.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "dcg/types.h"

namespace dcg::internal {

class VertexGrid {
 public:
  /// A grid over V's bounding box, about kPerCell vertices a cell.
  explicit VertexGrid(const Points& V) {
    const auto n = static_cast<double>(V.rows());
    if (V.rows() == 0) return;
    lo_ = V.colwise().minCoeff().transpose();
    const Eigen::Vector3d extent = V.colwise().maxCoeff().transpose() - lo_;
    diagonal_ = extent.norm();
    // About n / kPerCell cells: the side of a cube of the box's volume over that count, or of a
    // square of its largest face's area, or a length of its longest side, whichever is largest
    // (a flat cloud has no volume, a straight one no area either).
    std::array<double, 3> e = {extent[0], extent[1], extent[2]};
    std::sort(e.begin(), e.end(), std::greater<double>());
    const double per_cell = kPerCell / n;
    cell_ = std::max({std::cbrt(e[0] * e[1] * e[2] * per_cell), std::sqrt(e[0] * e[1] * per_cell),
                      e[0] * per_cell, 1e-300});
    for (int k = 0; k < 3; ++k) size_[k] = static_cast<int>(extent[k] / cell_) + 1;
    start_.assign(static_cast<std::size_t>(size_[0]) * size_[1] * size_[2] + 1, 0);
    for (Eigen::Index v = 0; v < V.rows(); ++v) ++start_[index(cell_of(V.row(v))) + 1];
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    points_.resize(static_cast<std::size_t>(V.rows()));
    for (Eigen::Index v = 0; v < V.rows(); ++v)
      points_[fill[index(cell_of(V.row(v)))]++] = V.row(v).transpose();
  }

  /// The diagonal of the vertices' bounding box (0 without vertices).
  double diagonal() const { return diagonal_; }

  /// The distance from p to the nearest vertex (infinity without vertices): the rings of cells
  /// around p's cell (clamped into the grid) one by one, until the next ring is farther than
  /// the nearest found (a vertex r + 1 rings out is at least r cells away, p inside or out).
  double nearest(const Eigen::Vector3d& p) const {
    double best = std::numeric_limits<double>::infinity();
    if (points_.empty()) return best;
    const Eigen::Vector3i c = cell_of(p.transpose());
    const int rings = std::max({size_[0], size_[1], size_[2]});
    for (int r = 0; r < rings && !(best <= (r - 1) * cell_); ++r) {
      for (int x = std::max(c[0] - r, 0); x <= std::min(c[0] + r, size_[0] - 1); ++x)
        for (int y = std::max(c[1] - r, 0); y <= std::min(c[1] + r, size_[1] - 1); ++y) {
          // The ring's shell: all of z on its x and y faces, else its two z faces only.
          const bool face = std::abs(x - c[0]) == r || std::abs(y - c[1]) == r;
          const int step = face || r == 0 ? 1 : 2 * r;
          for (int z = c[2] - r; z <= c[2] + r; z += step)
            if (z >= 0 && z < size_[2]) visit(Eigen::Vector3i(x, y, z), p, best);
        }
    }
    return best;
  }

 private:
  static constexpr double kPerCell = 2;

  void visit(const Eigen::Vector3i& c, const Eigen::Vector3d& p, double& best) const {
    const std::size_t cell = index(c);
    for (int i = start_[cell]; i < start_[cell + 1]; ++i)
      best = std::min(best, (points_[i] - p).norm());
  }
  Eigen::Vector3i cell_of(const Eigen::RowVector3d& p) const {
    Eigen::Vector3i c;
    for (int k = 0; k < 3; ++k) {
      const double at = std::floor((p[k] - lo_[k]) / cell_);
      c[k] = static_cast<int>(std::clamp(at, 0.0, static_cast<double>(size_[k] - 1)));
    }
    return c;
  }
  std::size_t index(const Eigen::Vector3i& c) const {
    return (static_cast<std::size_t>(c[0]) * size_[1] + c[1]) * size_[2] + c[2];
  }

  Eigen::Vector3d lo_ = Eigen::Vector3d::Zero();
  double diagonal_ = 0;
  double cell_ = 1;
  int size_[3] = {1, 1, 1};
  std::vector<int> start_;               // cell -> first slot in points_ (counting sort)
  std::vector<Eigen::Vector3d> points_;  // the vertices by cell
};

}  // namespace dcg::internal
