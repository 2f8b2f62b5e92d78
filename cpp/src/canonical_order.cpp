// A mesh numbered by its geometry alone. See canonical_order.h.
#include "canonical_order.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

namespace dcg::internal {
namespace {

// `mesh` renumbered: vertices by increasing `key` (#V, ties by position, then by old index),
// faces as canonical_order says.
Mesh ordered_by(const Mesh& mesh, const std::vector<double>& key) {
  const Eigen::Index nv = mesh.V.rows(), nf = mesh.F.rows();
  std::vector<int> order(nv), rank(nv);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    if (key[a] != key[b]) return key[a] < key[b];
    const auto pa = mesh.V.row(a), pb = mesh.V.row(b);
    return std::lexicographical_compare(pa.data(), pa.data() + 3, pb.data(), pb.data() + 3);
  });
  Mesh out;
  out.V.resize(nv, 3);
  for (Eigen::Index i = 0; i < nv; ++i) {
    rank[order[i]] = static_cast<int>(i);
    out.V.row(i) = mesh.V.row(order[i]);
  }
  std::vector<std::array<int, 3>> faces(nf);
  for (Eigen::Index f = 0; f < nf; ++f) {
    std::array<int, 3> c = {rank[mesh.F(f, 0)], rank[mesh.F(f, 1)], rank[mesh.F(f, 2)]};
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());  // keeps orientation
    faces[f] = c;
  }
  std::sort(faces.begin(), faces.end());
  out.F.resize(nf, 3);
  for (Eigen::Index f = 0; f < nf; ++f) out.F.row(f) << faces[f][0], faces[f][1], faces[f][2];
  return out;
}

}  // namespace

Mesh canonical_order(const Mesh& mesh) {
  return ordered_by(mesh, std::vector<double>(mesh.V.rows(), 0.0));
}

Mesh centred_order(const Mesh& mesh) {
  // On a grid of 2^22 steps across the mesh's largest side, in integers: a mirror pair's two
  // distances are then equal, not a last bit apart, so rounding (a scaled or moved copy of the
  // mesh) does not decide which of the two comes first; the position decides.
  const Eigen::Index nv = mesh.V.rows();
  if (nv == 0) return mesh;
  const Eigen::RowVector3d low = mesh.V.colwise().minCoeff();
  const double side = (mesh.V.colwise().maxCoeff() - low).maxCoeff();
  const double step = side > 0 ? side / static_cast<double>(1 << 22) : 1.0;
  Eigen::Matrix<std::int64_t, Eigen::Dynamic, 3> grid(nv, 3);
  for (Eigen::Index i = 0; i < nv; ++i)
    for (int k = 0; k < 3; ++k) grid(i, k) = std::llround((mesh.V(i, k) - low(k)) / step);
  std::array<std::int64_t, 3> centre{};
  for (int k = 0; k < 3; ++k) centre[k] = grid.col(k).sum() / nv;
  std::vector<double> reach(nv);  // below 3 x 2^44: exact as a double
  for (Eigen::Index i = 0; i < nv; ++i) {
    std::int64_t squared = 0;
    for (int k = 0; k < 3; ++k) squared += (grid(i, k) - centre[k]) * (grid(i, k) - centre[k]);
    reach[i] = static_cast<double>(squared);
  }
  return ordered_by(mesh, reach);
}

}  // namespace dcg::internal
