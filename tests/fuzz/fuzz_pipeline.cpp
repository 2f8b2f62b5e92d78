// libFuzzer target: the whole engine as the add-on calls it, dcg::extract_skeleton (stages 0-8)
// and then dcg::compute_skin_weights for bones along the skeleton's links, on small meshes decoded
// from the fuzz bytes (tests/fuzz/fuzz_mesh.h). fuzz_prepare covers stage 0 alone at a higher
// rate; this one reaches the later stages with the odd working meshes stage 0 lets through (a
// self-intersecting closed input kept as it is, a few dozen faces, flat or needle-like parts).
// Expected failures are dcg::InputError; anything else (a crash, a sanitizer report, another
// exception, a broken promise below) is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dcg/errors.h"
#include "dcg/options.h"
#include "dcg/pipeline.h"
#include "dcg/weights.h"
#include "fuzz_mesh.h"

namespace {

// What the skeleton promises: finite nodes, links and labels in range, one polyline per link of
// at least two finite points.
void check_skeleton(const dcg::Skeleton& s, Eigen::Index input_faces) {
  const Eigen::Index n = s.positions.rows();
  if (!s.positions.allFinite() || static_cast<Eigen::Index>(s.kinds.size()) != n) __builtin_trap();
  if (s.polylines.size() != static_cast<std::size_t>(s.links.rows())) __builtin_trap();
  if (s.face_labels.size() != input_faces) __builtin_trap();
  for (Eigen::Index f = 0; f < s.face_labels.size(); ++f) {
    if (s.face_labels(f) < -1 || s.face_labels(f) >= n) __builtin_trap();
  }
  for (Eigen::Index l = 0; l < s.links.rows(); ++l) {
    const int a = s.links(l, 0), b = s.links(l, 1);
    if (a < 0 || a >= n || b < 0 || b >= n) __builtin_trap();
    const dcg::Points& line = s.polylines[l];
    if (line.rows() < 2 || !line.allFinite()) __builtin_trap();
  }
}

// What the weights promise: 1 to max_influences positive entries a vertex, summing to 1.
void check_weights(const dcg::SkinWeights& w, Eigen::Index vertices, Eigen::Index bones,
                   int max_influences) {
  if (w.vertex_count != vertices || w.bone_count != bones) __builtin_trap();
  std::vector<double> sum(vertices, 0.0);
  std::vector<int> count(vertices, 0);
  for (Eigen::Index e = 0; e < w.values.size(); ++e) {
    const int v = w.rows(e), b = w.cols(e);
    if (v < 0 || v >= vertices || b < 0 || b >= bones) __builtin_trap();
    if (!(w.values(e) > 0 && w.values(e) <= 1 + 1e-9)) __builtin_trap();
    sum[v] += w.values(e);
    ++count[v];
  }
  for (Eigen::Index v = 0; v < vertices; ++v) {
    if (count[v] < 1 || count[v] > max_influences || std::abs(sum[v] - 1) > 1e-6) {
      __builtin_trap();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  dcg_fuzz::Reader in{data, size};
  const dcg_fuzz::FuzzMesh mesh = dcg_fuzz::read_mesh(in);
  dcg::Options options;
  options.prepare.repair = (mesh.flags & 1) ? dcg::Repair::None : dcg::Repair::Auto;
  // 0 keeps the welded input as the working mesh when it is closed: raw geometry for stages 1-8.
  options.prepare.target_faces = (mesh.flags & 2) ? 0 : 64 + 64 * ((mesh.flags >> 2) & 3);
  options.seed = mesh.flags >> 4;
  try {
    const dcg::Skeleton s = dcg::extract_skeleton(mesh.V, mesh.F, options);
    check_skeleton(s, mesh.F.rows());
    dcg::Bones bones;
    bones.heads.resize(s.links.rows(), 3);
    bones.tails.resize(s.links.rows(), 3);
    for (Eigen::Index l = 0; l < s.links.rows(); ++l) {
      bones.heads.row(l) = s.positions.row(s.links(l, 0));
      bones.tails.row(l) = s.positions.row(s.links(l, 1));
    }
    if (bones.count() == 0) return 0;
    const dcg::SkinWeights w = dcg::compute_skin_weights(mesh.V, mesh.F, bones, options);
    check_weights(w, mesh.V.rows(), bones.count(), options.weights.max_influences);
  } catch (const dcg::InputError&) {
  }
  return 0;
}
