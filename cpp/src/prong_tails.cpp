// Stage 3, tails (dcg/prongs.h, ProngHierarchy's class comment): a peak past tau kept as a prong
// because it is a pointed tip on the mirror plane between a pair of limbs: a tail.
//
// Implementation notes:
// - The cheap tests come first (ratio, f, the prong its region ended in, that prong's twin, the
//   plane); the mirror test (a thousand nearest-vertex queries) runs once per pair of prongs;
//   the tip test last, for the strongest kMaxTipTests peaks that get that far (a scan's noise
//   adds many weak peaks).
// - The tip test is Gauss-Bonnet's: the angle deficits (2 pi less the angles at a vertex) of
//   the vertices of a geodesic disc add up to the curvature the disc holds: near a full turn for
//   the point of a cone, 0 for a ridge or a flat side, whatever the mesh's resolution. A small
//   tail meets the body in a crease of negative curvature, so the sum over one disc swings with
//   where its rim falls (on spot with 0.3% noise, -0.5 to +0.5 turns at one radius); the test
//   takes the most that any disc up to kTailRadius diagonals holds (the running sum over the
//   vertices by their distance along the edges; one Dijkstra per peak that gets that far).
#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "dcg/prongs.h"
#include "vertex_grid.h"

namespace dcg {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The angle at each vertex: the sum of its faces' corner angles.
std::vector<double> vertex_angles(const Mesh& mesh) {
  std::vector<double> angles(static_cast<std::size_t>(mesh.V.rows()), 0.0);
  for (Eigen::Index t = 0; t < mesh.F.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(t, k);
      const Eigen::Vector3d u = mesh.V.row(mesh.F(t, (k + 1) % 3)) - mesh.V.row(a);
      const Eigen::Vector3d w = mesh.V.row(mesh.F(t, (k + 2) % 3)) - mesh.V.row(a);
      angles[a] += std::atan2(u.cross(w).norm(), u.dot(w));
    }
  }
  return angles;
}

// The most curvature (in full turns: angle deficits / 2 pi) that a geodesic disc around `source`
// of radius at most `radius` holds: the vertices by distance, the largest running sum of their
// deficits.
double most_turns(const Mesh& mesh, const std::vector<double>& angles, int source, double radius) {
  const Eigen::VectorXd distance = edge_geodesics(mesh, source);
  std::vector<std::pair<double, int>> disc;
  for (Eigen::Index v = 0; v < distance.size(); ++v)
    if (distance[v] < radius) disc.emplace_back(distance[v], static_cast<int>(v));
  std::sort(disc.begin(), disc.end());
  double sum = 0, most = 0;
  for (const auto& [d, v] : disc) {
    sum += 2 * kPi - angles[v];
    most = std::max(most, sum);
  }
  return most / (2 * kPi);
}

}  // namespace

std::vector<const Peak*> ProngHierarchy::tails(const std::vector<const Peak*>& kept) const {
  std::unordered_set<int> prong_vertices;
  for (const Peak* p : kept) prong_vertices.insert(p->vertex);
  if (!grid_) return {};
  const double diagonal = grid_->diagonal(), mean = f_.mean();
  // A prong's mirror twin among the prongs (nullptr: none), found once per prong.
  std::map<int, const Peak*> twin_of;
  const auto twin = [&](const Peak& p) {
    const auto known = twin_of.find(p.vertex);
    if (known != twin_of.end()) return known->second;
    const Peak* found = nullptr;
    for (const Peak* t : kept)
      if (t != &p && mirror_image(*t, p)) {
        found = t;
        break;
      }
    return twin_of[p.vertex] = found;
  };
  constexpr int kMaxTipTests = 8;  // the strongest that get that far; each costs a Dijkstra
  std::vector<const Peak*> out;
  std::vector<double> angles;  // each vertex's, once a peak gets that far
  int tip_tests = 0;
  for (const Peak& q : peaks_) {
    if (!(q.ratio < kMidlineRatio) || tip_tests >= kMaxTipTests) break;  // sorted by ratio
    if (q.global || prong_vertices.count(q.vertex) || q.value < mean) continue;
    const auto owner = peak_at_.find(region_prong(q, prong_vertices));
    if (owner == peak_at_.end() || !prong_vertices.count(owner->first)) continue;
    if ((mesh_.V.row(owner->first) - mesh_.V.row(q.vertex)).norm() < kTwinLength * mean) continue;
    const Peak* t = twin(peaks_[owner->second]);
    if (!t) continue;  // a nose on a head: the head's prong has no twin
    if (off_halfway(owner->first, t->vertex, q.vertex) > kTailPlane * diagonal) continue;
    if (angles.empty()) angles = vertex_angles(mesh_);
    ++tip_tests;
    if (most_turns(mesh_, angles, q.vertex, kTailRadius * diagonal) >= kTailTip) out.push_back(&q);
  }
  return out;
}

}  // namespace dcg
