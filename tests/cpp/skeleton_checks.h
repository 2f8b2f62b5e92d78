// Invariants of a finished skeleton (ALGORITHM.md "Checks every stage can be held to"), computed
// independently of the engine's stages 4-8: counts by kind, independent cycles, connected
// components, the share of nodes and polyline points inside the input mesh, unlabelled faces.
#pragma once

#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "dcg/skeleton.h"
#include "dcg/surface_query.h"
#include "dcg/types.h"

namespace dcg::test {

struct SkeletonQuality {
  int nodes = 0, ends = 0, joints = 0, connections = 0, links = 0;
  int components = 0;
  int cycles = 0;               ///< links - nodes + components
  int points = 0;               ///< nodes + polyline points checked
  int inside = 0;               ///< of them strictly inside the input
  int unlabelled_faces = 0;     ///< input faces with label -1
  int kind_mismatches = 0;      ///< nodes whose kind disagrees with their degree
  int polyline_mismatches = 0;  ///< polylines that do not start / end at their link's nodes
  int crossing_segments = 0;    ///< polyline segments that cross the input's surface
  double inside_percent() const { return points ? 100.0 * inside / points : 100.0; }
};

inline SkeletonQuality skeleton_quality(const Mesh& input, const Skeleton& s) {
  SkeletonQuality q;
  q.nodes = static_cast<int>(s.positions.rows());
  q.links = static_cast<int>(s.links.rows());
  std::vector<int> degree(q.nodes, 0), parent(q.nodes);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (int l = 0; l < q.links; ++l) {
    const int a = s.links(l, 0), b = s.links(l, 1);
    ++degree[a];
    ++degree[b];
    parent[find(a)] = find(b);
  }
  for (int i = 0; i < q.nodes; ++i) {
    q.components += find(i) == i;
    q.ends += s.kinds[i] == NodeKind::End;
    q.joints += s.kinds[i] == NodeKind::Joint;
    q.connections += s.kinds[i] == NodeKind::Connection;
    const NodeKind expected = degree[i] == 1   ? NodeKind::End
                              : degree[i] >= 3 ? NodeKind::Joint
                                               : NodeKind::Connection;
    q.kind_mismatches += s.kinds[i] != expected;
  }
  q.cycles = q.links - q.nodes + q.components;
  const SurfaceQuery surface(input);
  for (int i = 0; i < q.nodes; ++i) {
    ++q.points;
    q.inside += surface.inside_by_parity(s.positions.row(i).transpose());
  }
  for (int l = 0; l < q.links && l < static_cast<int>(s.polylines.size()); ++l) {
    const Points& p = s.polylines[l];
    if (p.rows() < 2 || !p.row(0).isApprox(s.positions.row(s.links(l, 0))) ||
        !p.row(p.rows() - 1).isApprox(s.positions.row(s.links(l, 1)))) {
      ++q.polyline_mismatches;
    }
    for (Eigen::Index i = 1; i + 1 < p.rows(); ++i) {
      ++q.points;
      q.inside += surface.inside_by_parity(p.row(i).transpose());
    }
    // Two points inside with the segment between them out through a fold: a bone out of the
    // skin all the same.
    for (Eigen::Index i = 0; i + 1 < p.rows(); ++i) {
      q.crossing_segments +=
          surface.segment_blocked(p.row(i).transpose(), p.row(i + 1).transpose());
    }
  }
  for (Eigen::Index f = 0; f < s.face_labels.size(); ++f)
    q.unlabelled_faces += s.face_labels[f] < 0;
  return q;
}

inline std::string describe(const SkeletonQuality& q) {
  char buf[256];
  std::snprintf(
      buf, sizeof buf,
      "%d nodes (%d ends, %d joints, %d connections), %d links, %d cycles, %d components, "
      "%.1f%% of %d points inside, %d segments crossing out, %d faces unlabelled",
      q.nodes, q.ends, q.joints, q.connections, q.links, q.cycles, q.components, q.inside_percent(),
      q.points, q.crossing_segments, q.unlabelled_faces);
  return buf;
}

}  // namespace dcg::test
