// Internal (not installed): the undirected edges of a triangle mesh, as the faces' corners sorted
// by edge. Shared by stage 0 (topology, folds), the 1-to-4 split before remeshing, the surface
// query's edge normals and stage 6's face adjacency.
#pragma once

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "dcg/types.h"
#include "polling.h"

namespace dcg::internal {

/// The key of the undirected edge a-b (the smaller index in the high half).
inline std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

/// Every face's three edges: (edge key, corner) with corner = 3 x face + k for the edge from
/// F(face, k) to F(face, k + 1), sorted by key (then corner), so that the faces around one edge
/// are one run of equal keys.
struct EdgeTable {
  std::vector<std::pair<std::uint64_t, int>> half;

  /// `poll` (if set) is called every 65,536 faces and between the steps of the sort.
  explicit EdgeTable(const Faces& F, const std::function<void()>& poll = {}) {
    half.reserve(static_cast<std::size_t>(F.rows()) * 3);
    for (int f = 0; f < F.rows(); ++f) {
      if (poll && (f & 65535) == 0) poll();
      for (int k = 0; k < 3; ++k)
        half.emplace_back(edge_key(F(f, k), F(f, (k + 1) % 3)), 3 * f + k);
    }
    sort_polling(half, poll);
  }
  static int face(int corner) { return corner / 3; }
  /// Calls fn(begin, end) for each run of equal keys [begin, end) in `half`: one edge each.
  template <class Fn>
  void for_each_edge(Fn fn) const {
    for (std::size_t i = 0; i < half.size();) {
      std::size_t j = i;
      while (j < half.size() && half[j].first == half[i].first) ++j;
      fn(i, j);
      i = j;
    }
  }
};

}  // namespace dcg::internal
