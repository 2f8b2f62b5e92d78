// A mesh numbered by its geometry alone. See canonical_order.h.
#include "canonical_order.h"

#include <algorithm>
#include <array>
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
  const Eigen::RowVector3d centre =
      mesh.V.rows() > 0 ? Eigen::RowVector3d(mesh.V.colwise().mean()) : Eigen::RowVector3d::Zero();
  std::vector<double> reach(mesh.V.rows());
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) reach[i] = (mesh.V.row(i) - centre).squaredNorm();
  return ordered_by(mesh, reach);
}

}  // namespace dcg::internal
