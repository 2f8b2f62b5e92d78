// Internal (not installed): a triangle list turned into a Mesh on only the vertices it uses.
// Shared by stage 0's cleaning and the decimator, which both leave unreferenced vertices behind.
#pragma once

#include <array>
#include <vector>

#include "dcg/types.h"

namespace dcg::internal {

/// The mesh of the triangles `faces` on the vertices of V they use, numbered in the order the
/// faces first use them.
///   V      #V by 3 vertex positions
///   faces  #F triangles, indices into V
///   index  (if set) gets #V entries: each vertex's index in the result, -1 when no face uses it
inline Mesh compact_mesh(const Vertices& V, const std::vector<std::array<int, 3>>& faces,
                         std::vector<int>* index = nullptr) {
  const int nv = static_cast<int>(V.rows());
  std::vector<int> local;
  std::vector<int>& map = index ? *index : local;
  map.assign(nv, -1);
  int n = 0;
  for (auto& t : faces)
    for (int v : t)
      if (map[v] < 0) map[v] = n++;
  Mesh out;
  out.V.resize(n, 3);
  for (int v = 0; v < nv; ++v)
    if (map[v] >= 0) out.V.row(map[v]) = V.row(v);
  out.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (int k = 0; k < 3; ++k) out.F(f, k) = map[faces[f][k]];
  return out;
}

}  // namespace dcg::internal
