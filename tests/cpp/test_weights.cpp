// dcg/weights.h (stage 9): the cotangent Laplacian, nearest visible bones, bone heat on small
// shapes (monotonic across a joint, one bone per part, blind parts), the transfer to the input
// vertices (rows sum to 1, at most max_influences), scale invariance, errors and cancellation.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dcg/errors.h"
#include "dcg/io.h"
#include "dcg/options.h"
#include "dcg/prepare.h"
#include "dcg/weights.h"
#include "shapes.h"

namespace {

using dcg::Bones;
using dcg::Mesh;

// --- small shapes (self-contained: these tests need nothing else) -----------------------------

// The shared capsule (shapes.h) with the resolution these tests were tuned on; `ring` receives
// each vertex's latitude row.
Mesh capsule(double radius, double length, std::vector<int>* ring = nullptr, int rings = 10,
             int segments = 24, int sections = 24) {
  return dcg::test::capsule(radius, length, rings, segments, sections, ring);
}

// UV sphere of `radius` at `center`: `rings` latitude steps, `segments` around.
Mesh sphere(const Eigen::RowVector3d& center, double radius, int rings = 12, int segments = 20) {
  Mesh m;
  m.V.resize(2 + (rings - 1) * segments, 3);
  m.V.row(0) << 0, 0, radius;
  for (int r = 1; r < rings; ++r)
    for (int j = 0; j < segments; ++j) {
      const double theta = M_PI * r / rings, phi = 2 * M_PI * j / segments;
      m.V.row(1 + (r - 1) * segments + j) << radius * std::sin(theta) * std::cos(phi),
          radius * std::sin(theta) * std::sin(phi), radius * std::cos(theta);
    }
  const int bottom = static_cast<int>(m.V.rows()) - 1;
  m.V.row(bottom) << 0, 0, -radius;
  m.V.rowwise() += center;
  auto id = [&](int r, int j) { return 1 + (r - 1) * segments + (j + segments) % segments; };
  std::vector<std::array<int, 3>> F;
  for (int j = 0; j < segments; ++j) {
    F.push_back({0, id(1, j), id(1, j + 1)});
    F.push_back({bottom, id(rings - 1, j + 1), id(rings - 1, j)});
  }
  for (int r = 1; r + 1 < rings; ++r)
    for (int j = 0; j < segments; ++j) {
      F.push_back({id(r, j), id(r + 1, j), id(r + 1, j + 1)});
      F.push_back({id(r, j), id(r + 1, j + 1), id(r, j + 1)});
    }
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t f = 0; f < F.size(); ++f) m.F.row(f) << F[f][0], F[f][1], F[f][2];
  return m;
}

using dcg::test::merged;

Bones bones_from(std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> list) {
  Bones b;
  b.heads.resize(static_cast<Eigen::Index>(list.size()), 3);
  b.tails.resize(static_cast<Eigen::Index>(list.size()), 3);
  for (std::size_t i = 0; i < list.size(); ++i) {
    b.heads.row(i) = list[i].first.transpose();
    b.tails.row(i) = list[i].second.transpose();
  }
  return b;
}

// A two-bone chain along the capsule's axis, jointed at z = 0.
Bones chain() { return bones_from({{{0, 0, -1.2}, {0, 0, 0}}, {{0, 0, 0}, {0, 0, 1.2}}}); }

// BoneHeat::nearest_visible_bones of vertex v of m (-1: it sees none).
int nearest_visible_bone(const Mesh& m, const Bones& bones, Eigen::Index v) {
  dcg::BoneHeat heat(m);
  Eigen::VectorXi nearest;
  Eigen::VectorXd distance;
  heat.nearest_visible_bones(bones, nearest, distance);
  return nearest[v];
}

dcg::Options keep_input() {
  dcg::Options o;
  o.prepare.target_faces = 0;
  return o;
}

// Every vertex has 1..max entries, positive, summing to 1; rows sorted, cols in range.
void expect_valid(const dcg::SkinWeights& w, int vertex_count, int bone_count, int max = 4) {
  ASSERT_EQ(w.vertex_count, vertex_count);
  ASSERT_EQ(w.bone_count, bone_count);
  ASSERT_EQ(w.rows.size(), w.cols.size());
  ASSERT_EQ(w.rows.size(), w.values.size());
  std::vector<int> count(vertex_count, 0);
  std::vector<double> sum(vertex_count, 0.0);
  for (Eigen::Index e = 0; e < w.rows.size(); ++e) {
    ASSERT_GE(w.rows[e], 0);
    ASSERT_LT(w.rows[e], vertex_count);
    ASSERT_GE(w.cols[e], 0);
    ASSERT_LT(w.cols[e], bone_count);
    ASSERT_GT(w.values[e], 0.0);
    if (e > 0) {
      ASSERT_LE(w.rows[e - 1], w.rows[e]);
    }
    ++count[w.rows[e]];
    sum[w.rows[e]] += w.values[e];
  }
  int bad = 0;
  for (int v = 0; v < vertex_count; ++v)
    if (count[v] < 1 || count[v] > max || std::abs(sum[v] - 1) > 1e-9) ++bad;
  EXPECT_EQ(bad, 0) << "vertices with no weights, too many or not summing to 1";
  EXPECT_EQ(w.fallback_vertices, 0);
}

// --- the Laplacian ----------------------------------------------------------------------------

TEST(WeightsLaplacian, SymmetricRowsSumToZeroAreasSumToTheSurface) {
  const Mesh m = sphere(Eigen::RowVector3d::Zero(), 1.0, 24, 40);
  dcg::BoneHeat heat(m);
  const Eigen::SparseMatrix<double>& L = heat.laplacian();
  const Eigen::MatrixXd D = L.toDense();
  EXPECT_LT((D - D.transpose()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(D.rowwise().sum().cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_NEAR(heat.areas().sum(), 4 * M_PI, 0.1);  // the polygon is a little smaller
  // -L is positive semi-definite: x^T (-L) x = sum of w_ij (x_i - x_j)^2 >= 0 for x = z.
  const Eigen::VectorXd z = m.V.col(2);
  EXPECT_GT(-z.dot(L * z), 0.0);
  // L x = -2 H n A on a sphere (the mean curvature normal): L z ~ -2 z A / r^2 (as a whole: the
  // skinny triangles at the poles of a UV sphere make single vertices less accurate).
  const Eigen::VectorXd expected = -2 * z.cwiseProduct(heat.areas());
  EXPECT_LT((L * z - expected).norm(), 0.05 * expected.norm());
}

// --- nearest visible bones ----------------------------------------------------------------------

TEST(WeightsVisibility, EachSphereSeesOnlyTheBoneInsideIt) {
  // Two spheres 0.2 apart; the other sphere's bone is nearer to the facing side of each than
  // its own bone, but behind the other sphere's surface.
  const Mesh a = sphere(Eigen::RowVector3d(0, 0, 0), 1.0);
  const Mesh b = sphere(Eigen::RowVector3d(2.2, 0, 0), 1.0);
  const Mesh m = merged(a, b);
  // Bone 0 along a's far side, bone 1 near the facing side of b: the facing side of a is
  // nearer to bone 1 (0.3 away from b's surface, 0.5 from a's) than to bone 0 (1.9 away).
  const Bones bones =
      bones_from({{{-0.9, 0, -0.1}, {-0.9, 0, 0.1}}, {{1.5, 0, -0.1}, {1.5, 0, 0.1}}});
  dcg::BoneHeat heat(m);
  Eigen::VectorXi nearest;
  Eigen::VectorXd distance;
  heat.nearest_visible_bones(bones, nearest, distance);
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    ASSERT_EQ(nearest[v], v < a.V.rows() ? 0 : 1) << "vertex " << v;
    EXPECT_TRUE(std::isfinite(distance[v]));
  }
  const Eigen::MatrixXd W = heat.solve(bones);
  for (Eigen::Index v = 0; v < m.V.rows(); ++v)
    EXPECT_NEAR(W(v, v < a.V.rows() ? 0 : 1), 1.0, 1e-6) << "vertex " << v;
}

TEST(WeightsVisibility, APartThatSeesNoBoneTakesTheNearestBoneThroughTheVolume) {
  // Bone 0 inside sphere a, bone 1 above sphere b, outside everything: b's upper half sees
  // bone 1 through empty space, its lower half sees no bone (bone 1 is behind b's own surface,
  // bone 0 behind a's) and takes its weights by diffusion from the upper half.
  const Mesh a = sphere(Eigen::RowVector3d(0, 0, 0), 1.0);
  const Mesh b = sphere(Eigen::RowVector3d(5, 0, 0), 1.0);
  const Mesh m = merged(a, b);
  const Bones bones = bones_from({{{0, 0, -0.5}, {0, 0, 0.5}}, {{5, 0, 3}, {5, 0, 4}}});
  dcg::BoneHeat heat(m);
  dcg::BoneHeat::Report report;
  const Eigen::MatrixXd W = heat.solve(bones, {}, &report);
  EXPECT_EQ(report.blind_components, 0);
  EXPECT_GT(report.unseen_vertices, 0);
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    EXPECT_NEAR(W.row(v).sum(), 1.0, 1e-6) << "vertex " << v;
    EXPECT_NEAR(W(v, v < a.V.rows() ? 0 : 1), 1.0, 1e-6) << "vertex " << v;
  }
}

TEST(WeightsVisibility, AClosedPartAroundNoBoneIsStillWeighted) {
  // Sphere b is seen by no bone at all (bone 1 is inside a as well): b is blind and takes the
  // nearest bone of each vertex through the volume.
  const Mesh a = sphere(Eigen::RowVector3d(0, 0, 0), 1.0);
  const Mesh b = sphere(Eigen::RowVector3d(5, 0, 0), 1.0);
  const Mesh m = merged(a, b);
  const Bones bones = bones_from({{{-0.5, 0, 0}, {0, 0, 0}}, {{0, 0, 0}, {0.5, 0, 0}}});
  dcg::BoneHeat heat(m);
  dcg::BoneHeat::Report report;
  const Eigen::MatrixXd W = heat.solve(bones, {}, &report);
  EXPECT_EQ(report.blind_components, 1);
  EXPECT_EQ(report.unseen_vertices, b.V.rows());
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    EXPECT_NEAR(W.row(v).sum(), 1.0, 1e-6) << "vertex " << v;
    if (v >= a.V.rows()) {
      EXPECT_NEAR(W(v, 1), 1.0, 1e-6) << "vertex " << v;
    }
  }
}

TEST(WeightsVisibility, AClosedPartShowsTheBonesItHoldsThroughItsBackFaces) {
  // Bone 1 rises out of the sphere's top (head inside at (0.5, 0, 0)). Vertex p near the top on
  // the other side is nearest to the part of bone 1 outside the sphere: the segment between them
  // crosses the sphere once, leaving it (a face seen from behind, as Blender's back-face
  // culling ignores), so p sees bone 1. Bone 0 lies low inside, farther from p.
  const Mesh a = sphere(Eigen::RowVector3d(0, 0, 0), 1.0);
  const Eigen::Vector3d out(-0.3, 0, 0.95);
  Eigen::Index p = 0;
  (a.V * out.normalized()).maxCoeff(&p);
  const std::pair<Eigen::Vector3d, Eigen::Vector3d> low = {{0, 0, -0.8}, {0, 0, -0.6}};
  const Eigen::Vector3d inside(0.5, 0, 0), outside(0.5, 0, 2);
  auto nearest_of_p = [&](const Mesh& m, const Bones& b) { return nearest_visible_bone(m, b, p); };
  const Bones rising = bones_from({low, {inside, outside}});
  EXPECT_EQ(nearest_of_p(a, rising), 1);
  // Nor does a crack between coincident vertices (the pole split in two: half of its fan uses a
  // copy of it), as game meshes have where stage 0 dropped a face between coincident vertices.
  Mesh split = a;
  split.V.conservativeResize(a.V.rows() + 1, 3);
  split.V.row(a.V.rows()) = a.V.row(0);
  for (Eigen::Index f = 0, fan = 0; f < split.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (split.F(f, k) == 0 && fan++ % 2) split.F(f, k) = static_cast<int>(a.V.rows());
  EXPECT_EQ(nearest_of_p(split, rising), 1);
  // A part elsewhere changes nothing.
  EXPECT_EQ(nearest_of_p(merged(a, sphere(Eigen::RowVector3d(5, 0, 0), 1.0)), rising), 1);
  // A head outside the shape marks a control bone (a root on the floor): not seen through.
  EXPECT_EQ(nearest_of_p(a, bones_from({low, {outside, inside}})), 0);
  // Nor a bone whose head is in another part (a small sphere around it, above a).
  const Eigen::Vector3d above(0.5, 0, 1.5);
  EXPECT_EQ(
      nearest_of_p(merged(a, sphere(above.transpose(), 0.1)), bones_from({low, {above, inside}})),
      0);
  // Another part hides even from behind: with p inside a small sphere pushed into a (shells
  // pushed into each other), every segment from p leaves that sphere through a face seen from
  // behind, and p sees no bone (-1; it is then heated by diffusion).
  EXPECT_EQ(nearest_of_p(merged(a, sphere(a.V.row(p), 0.1)), rising), -1);
}

// --- rigs' conventions (IK feet, accessories) ----------------------------------------------------

TEST(WeightsRigs, ALeafThatStopsShortReachesTheFootItPointsAt) {
  // A leg (capsule along z, radius 0.3, from z = -1.3 to 1.3): thigh and shin down its axis, the
  // shin a leaf that ends at z = -0.2; the foot hangs from a root below the leg (an IK foot), its
  // head at z = -0.8. Vertex p on the side at z = -0.6 lies nearer the foot's head than the
  // shin's tail, but with the tree given the shin reaches the foot's head and takes p.
  std::vector<int> ring;
  const Mesh leg = capsule(0.3, 2.0, &ring, 6, 16, 20);
  Eigen::Index p = 0;
  (leg.V.rowwise() - Eigen::RowVector3d(0.3, 0, -0.6)).rowwise().squaredNorm().minCoeff(&p);
  ASSERT_NEAR(leg.V(p, 2), -0.6, 1e-9);
  Bones bones = bones_from({{{0, 0, -3.0}, {0, 0, -2.8}},      // 0 root, on the floor
                            {{0, 0, 1.0}, {0, 0, 0.4}},        // 1 thigh
                            {{0, 0, 0.4}, {0, 0, -0.2}},       // 2 shin, a leaf
                            {{0, 0, -0.8}, {0.2, 0, -1.1}}});  // 3 foot
  auto nearest_of_p = [&](const Mesh& m, const Bones& b) { return nearest_visible_bone(m, b, p); };
  EXPECT_EQ(nearest_of_p(leg, bones), 3) << "no tree given: the shin stops where it ends";
  bones.parents.resize(4);
  bones.parents << -1, 0, 1, 0;
  EXPECT_EQ(nearest_of_p(leg, bones), 2);
  // The weights follow: p binds to the shin.
  dcg::BoneHeat heat(leg);
  EXPECT_GT(heat.solve(bones)(p, 2), 0.5);
  // Nor when another chain ends where the shin ends (the plan closing a cycle of the skeleton
  // there): the two leaves meet, and neither reaches on.
  Bones meeting = bones;
  meeting.heads.conservativeResize(5, 3);
  meeting.tails.conservativeResize(5, 3);
  meeting.parents.conservativeResize(5);
  meeting.heads.row(4) << -0.2, 0, 0.9;
  meeting.tails.row(4) << 0, 0, -0.2;
  meeting.parents[4] = 0;
  EXPECT_EQ(nearest_of_p(leg, meeting), 3);
  // Not to a head outside its cone (60 degrees): the foot's head off to the side.
  Bones aside = bones;
  aside.heads.row(3) << 0.25, 0, -0.25;
  aside.tails.row(3) << 0.25, 0, -0.6;
  EXPECT_NE(nearest_of_p(leg, aside), 2);
  // Nor across the outside: the foot in a part of its own (a ball below a shorter leg).
  const Mesh shorter = capsule(0.3, 1.0, nullptr, 6, 16, 10);  // z from -0.8 to 0.8
  const Mesh split = merged(shorter, sphere(Eigen::RowVector3d(0, 0, -1.4), 0.3));
  Bones apart = bones;
  apart.heads.row(3) << 0, 0, -1.3;
  apart.tails.row(3) << 0, 0, -1.5;
  dcg::BoneHeat split_heat(split);
  Eigen::VectorXi nearest;
  Eigen::VectorXd with, without;
  split_heat.nearest_visible_bones(apart, nearest, with);
  apart.parents.resize(0);
  split_heat.nearest_visible_bones(apart, nearest, without);
  EXPECT_LT((with - without).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(WeightsRigs, APartThatHoldsNoBoneMovesRigidlyWithWhereItIsAttached) {
  // A head (sphere of radius 1) with two bones meeting at its center, and an eye (a small
  // sphere pushed into its side just above the joint): heat alone blends the two bones across
  // the eye; as an accessory it follows the upper bone, which weighs most on the head's surface
  // where the eye is attached.
  const Mesh head = sphere(Eigen::RowVector3d(0, 0, 0), 1.0, 24, 32);
  const Mesh eye = sphere(Eigen::RowVector3d(0.95, 0, 0.2), 0.15);
  // A ball beside a bone that no part holds (a wing's stub of a bone, outside everything).
  const Mesh wing = sphere(Eigen::RowVector3d(4, 0, 0), 0.5);
  const Mesh m = merged(merged(head, eye), wing);
  Bones bones =
      bones_from({{{0, 0, -0.8}, {0, 0, 0}}, {{0, 0, 0}, {0, 0, 0.8}}, {{3.2, 0, 0}, {3.3, 0, 0}}});
  bones.parents.resize(3);
  bones.parents << -1, 0, 0;
  dcg::BoneHeat heat(m);
  dcg::BoneHeat::Report report;
  const Eigen::MatrixXd W = heat.solve(bones, {}, &report);
  EXPECT_EQ(report.rigid_parts, 1);
  const Eigen::Index e0 = head.V.rows(), e1 = e0 + eye.V.rows();
  for (Eigen::Index v = e0; v < e1; ++v) {
    EXPECT_EQ(W(v, 1), 1.0) << "eye vertex " << v;
    EXPECT_EQ(W.row(v).sum(), 1.0) << "eye vertex " << v;
  }
  // The wing keeps its heat (its bone is held by no part), the head its blend.
  EXPECT_NEAR(W.bottomRows(wing.V.rows()).col(2).minCoeff(), 1.0, 1e-6);
  EXPECT_GT(W.topRows(e0).col(0).maxCoeff(), 0.99);
  // Without the head's bones inside it the eye is no accessory: bones held by no part.
  Bones outside = bones;
  outside.heads.topRows(2).col(0).array() += 3;
  outside.tails.topRows(2).col(0).array() += 3;
  heat.solve(outside, {}, &report);
  EXPECT_EQ(report.rigid_parts, 0);
}

// --- bone heat ----------------------------------------------------------------------------------

TEST(WeightsHeat, OneBoneWeighsEverythingOne) {
  const Mesh m = capsule(0.5, 2.0);
  const Bones one = bones_from({{{0, 0, -1}, {0, 0, 1}}});
  const dcg::SkinWeights w = dcg::compute_skin_weights(m.V, m.F, one, keep_input());
  expect_valid(w, static_cast<int>(m.V.rows()), 1, 1);
  EXPECT_EQ(w.rows.size(), m.V.rows());
  EXPECT_LT((w.values.array() - 1).abs().maxCoeff(), 1e-12);
}

TEST(WeightsHeat, CapsuleChainIsMonotonicAcrossTheJoint) {
  std::vector<int> ring;
  const Mesh m = capsule(0.5, 2.0, &ring);
  const dcg::SkinWeights w = dcg::compute_skin_weights(m.V, m.F, chain(), keep_input());
  expect_valid(w, static_cast<int>(m.V.rows()), 2);
  const Eigen::MatrixXd W = w.dense();
  // Mean weight of the upper bone per latitude ring, from the bottom pole to the top one.
  std::map<double, std::pair<double, int>> by_z;  // z -> (sum, count)
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    auto& slot = by_z[std::round(m.V(v, 2) * 1e9) / 1e9];
    slot.first += W(v, 1);
    ++slot.second;
  }
  double previous = -1;
  std::vector<std::pair<double, double>> profile;
  for (const auto& [z, s] : by_z) {
    const double mean = s.first / s.second;
    profile.emplace_back(z, mean);
    EXPECT_GE(mean, previous - 1e-9) << "not monotonic at z = " << z;
    previous = mean;
  }
  // Far from the joint each end belongs to its own bone; at the joint they share.
  EXPECT_LT(profile.front().second, 0.01);
  EXPECT_GT(profile.back().second, 0.99);
  for (const auto& [z, mean] : profile) {
    if (std::abs(z) < 1e-9) {
      EXPECT_NEAR(mean, 0.5, 0.05);
    }
    if (z < -0.05) {
      EXPECT_LT(mean, 0.5);
    }
    if (z > 0.05) {
      EXPECT_GT(mean, 0.5);
    }
  }
  // Smooth fall-off: the blend spans some of the cylinder, not one ring.
  int blended = 0;
  for (const auto& [z, mean] : profile) blended += mean > 0.1 && mean < 0.9;
  EXPECT_GE(blended, 3);
  // Every vertex of a ring has about the same weight (the capsule is round).
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    const auto& s = by_z[std::round(m.V(v, 2) * 1e9) / 1e9];
    EXPECT_NEAR(W(v, 1), s.first / s.second, 0.02) << "vertex " << v;
  }
}

TEST(WeightsHeat, ABoneThatDoesNotDeformGetsNoWeightAndKeepsTheNumbering) {
  // A root control from below the capsule to the chain's first head, parent of the chain:
  // its column stays empty and the chain's weights are those of the chain alone.
  const Mesh m = capsule(0.5, 2.0);
  const Bones alone = chain();
  Bones rooted;
  rooted.heads.resize(3, 3);
  rooted.tails.resize(3, 3);
  rooted.heads << 0, 0, -2, alone.heads;
  rooted.tails << alone.heads.row(0), alone.tails;
  rooted.parents.resize(3);
  rooted.parents << -1, 0, 1;
  rooted.deform = {0, 1, 1};
  const dcg::SkinWeights w = dcg::compute_skin_weights(m.V, m.F, rooted, keep_input());
  expect_valid(w, static_cast<int>(m.V.rows()), 3);
  const Eigen::MatrixXd W = w.dense();
  EXPECT_EQ(W.col(0).cwiseAbs().maxCoeff(), 0.0);
  const Eigen::MatrixXd expected = dcg::compute_skin_weights(m.V, m.F, alone, keep_input()).dense();
  EXPECT_LT((W.rightCols(2) - expected).cwiseAbs().maxCoeff(), 1e-12);
  rooted.deform = {0, 0, 0};
  EXPECT_THROW(dcg::compute_skin_weights(m.V, m.F, rooted, keep_input()), dcg::InputError);
  rooted.deform = {1};
  EXPECT_THROW(dcg::compute_skin_weights(m.V, m.F, rooted, keep_input()), dcg::InputError);
}

TEST(WeightsHeat, SolveMatchesADenseSolveOfTheHeatEquation) {
  // (-L + M H) w_b = M H p_b assembled here from the Laplacian, the areas and the nearest
  // visible bones, solved densely; 10 bones cover a full block of 8 and a partial one.
  const Mesh m = capsule(0.5, 2.0, nullptr, 5, 12, 8);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> list;
  for (int b = 0; b < 10; ++b) {
    const double z0 = -1.2 + 0.24 * b;
    list.push_back({{0.1 * std::cos(b), 0.1 * std::sin(b), z0}, {0, 0, z0 + 0.24}});
  }
  const Bones bones = bones_from(list);
  dcg::WeightsOptions o;
  o.tie_tolerance = 0;
  dcg::BoneHeat heat(m);
  const Eigen::MatrixXd W = heat.solve(bones, o);
  Eigen::VectorXi nearest;
  Eigen::VectorXd distance;
  heat.nearest_visible_bones(bones, nearest, distance);
  const Eigen::Index n = m.V.rows();
  Eigen::MatrixXd A = -heat.laplacian().toDense();
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(n, 10);
  for (Eigen::Index v = 0; v < n; ++v) {
    ASSERT_GE(nearest[v], 0);
    const double mh = heat.areas()[v] * o.heat / (distance[v] * distance[v]);
    A(v, v) += mh;
    B(v, nearest[v]) = mh;
  }
  const Eigen::MatrixXd reference = A.ldlt().solve(B).cwiseMax(0.0).cwiseMin(1.0);
  EXPECT_LT((W - reference).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(WeightsHeat, MaxInfluencesPrunesAndRenormalizes) {
  const Mesh m = capsule(0.5, 2.0);
  Bones four = bones_from({{{0, 0, -1.2}, {0, 0, -0.6}},
                           {{0, 0, -0.6}, {0, 0, 0}},
                           {{0, 0, 0}, {0, 0, 0.6}},
                           {{0, 0, 0.6}, {0, 0, 1.2}}});
  dcg::Options o = keep_input();
  o.weights.min_weight = 0;
  for (int max : {1, 2, 4}) {
    o.weights.max_influences = max;
    const dcg::SkinWeights w = dcg::compute_skin_weights(m.V, m.F, four, o);
    expect_valid(w, static_cast<int>(m.V.rows()), 4, max);
    if (max == 1) {
      EXPECT_EQ(w.rows.size(), m.V.rows());
    }
  }
}

TEST(WeightsHeat, SameWeightsAtEveryScale) {
  const Mesh m = capsule(0.5, 2.0);
  const Bones bones = chain();
  const Eigen::MatrixXd reference =
      dcg::compute_skin_weights(m.V, m.F, bones, keep_input()).dense();
  for (double scale : {0.01, 100.0}) {
    const Eigen::RowVector3d shift(3, -2, 7);
    Mesh s = m;
    s.V = ((m.V * scale).rowwise() + shift * scale).eval();
    Bones b = bones;
    b.heads = ((bones.heads * scale).rowwise() + shift * scale).eval();
    b.tails = ((bones.tails * scale).rowwise() + shift * scale).eval();
    const dcg::SkinWeights w = dcg::compute_skin_weights(s.V, s.F, b, keep_input());
    expect_valid(w, static_cast<int>(m.V.rows()), 2);
    EXPECT_LT((w.dense() - reference).cwiseAbs().maxCoeff(), 1e-5) << "scale " << scale;
  }
}

TEST(WeightsHeat, RemeshedWorkingMeshTransfersToTheInput) {
  std::vector<int> ring;
  const Mesh m = capsule(0.5, 2.0, &ring, 6, 16, 8);  // coarse input, remeshed finer
  dcg::Options o;
  o.prepare.target_faces = 4000;
  o.prepare.upsample = true;
  const dcg::PreparedMesh prepared = dcg::prepare_mesh(m.V, m.F, o.prepare_options());
  const dcg::SkinWeights w = dcg::compute_skin_weights(prepared, chain(), o.weights);
  expect_valid(w, static_cast<int>(m.V.rows()), 2);
  EXPECT_GT(w.working_vertices, m.V.rows());
  const Eigen::MatrixXd W = w.dense();
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    if (m.V(v, 2) > 1.0) {
      EXPECT_GT(W(v, 1), 0.9) << "vertex " << v;
    }
    if (m.V(v, 2) < -1.0) {
      EXPECT_GT(W(v, 0), 0.9) << "vertex " << v;
    }
    if (m.V(v, 2) > 0.1) {
      EXPECT_GT(W(v, 1), 0.5) << "vertex " << v;
    }
    if (m.V(v, 2) < -0.1) {
      EXPECT_GT(W(v, 0), 0.5) << "vertex " << v;
    }
  }
}

TEST(WeightsHeat, OpenAndMultiPartInputIsWeightedEverywhere) {
  // A capsule with its top cap removed, plus a small closed sphere floating inside it.
  Mesh open = capsule(0.5, 2.0);
  std::vector<std::array<int, 3>> kept;
  for (Eigen::Index f = 0; f < open.F.rows(); ++f) {
    const double z =
        (open.V(open.F(f, 0), 2) + open.V(open.F(f, 1), 2) + open.V(open.F(f, 2), 2)) / 3;
    if (z < 1.2) kept.push_back({open.F(f, 0), open.F(f, 1), open.F(f, 2)});
  }
  open.F.resize(static_cast<Eigen::Index>(kept.size()), 3);
  for (std::size_t f = 0; f < kept.size(); ++f) open.F.row(f) << kept[f][0], kept[f][1], kept[f][2];
  const Mesh m = merged(open, sphere(Eigen::RowVector3d(0, 0, -0.5), 0.2, 6, 8));
  dcg::Options o;
  o.prepare.target_faces = 4000;
  const dcg::SkinWeights w = dcg::compute_skin_weights(m.V, m.F, chain(), o);
  expect_valid(w, static_cast<int>(m.V.rows()), 2);
}

TEST(WeightsHeat, TwoPartsEachGetOnlyTheirOwnBones) {
  // Two capsules 0.1 apart, one bone each, default options: the weights solve on the input
  // itself, part by part, so no part takes the other's bone (an alpha wrap would glue them).
  const Mesh a = capsule(0.5, 2.0);
  Mesh b = a;
  b.V.col(0).array() += 1.1;
  const Mesh m = merged(a, b);
  const Bones bones = bones_from({{{0, 0, -1}, {0, 0, 1}}, {{1.1, 0, -1}, {1.1, 0, 1}}});
  const dcg::SkinWeights w = dcg::compute_skin_weights(m.V, m.F, bones, dcg::Options());
  expect_valid(w, static_cast<int>(m.V.rows()), 2);
  EXPECT_EQ(w.working_vertices, m.V.rows());
  const Eigen::MatrixXd W = w.dense();
  for (Eigen::Index v = 0; v < m.V.rows(); ++v)
    EXPECT_EQ(W(v, v < a.V.rows() ? 0 : 1), 1.0) << "vertex " << v;
}

// --- errors and cancellation --------------------------------------------------------------------

TEST(WeightsErrors, BadBonesAndOptionsAreInputErrors) {
  const Mesh m = capsule(0.5, 2.0);
  Bones none;
  none.heads.resize(0, 3);
  none.tails.resize(0, 3);
  EXPECT_THROW(dcg::compute_skin_weights(m.V, m.F, none, keep_input()), dcg::InputError);
  Bones mismatched = chain();
  mismatched.tails.conservativeResize(1, 3);
  EXPECT_THROW(dcg::compute_skin_weights(m.V, m.F, mismatched, keep_input()), dcg::InputError);
  Bones nan = chain();
  nan.heads(1, 2) = std::nan("");
  EXPECT_THROW(dcg::compute_skin_weights(m.V, m.F, nan, keep_input()), dcg::InputError);
  for (auto change : std::vector<std::function<void(dcg::Options&)>>{
           [](dcg::Options& o) { o.weights.max_influences = 0; },
           [](dcg::Options& o) { o.weights.heat = 0; },
           [](dcg::Options& o) { o.weights.min_weight = 1; },
           [](dcg::Options& o) { o.weights.tie_tolerance = -1; }}) {
    dcg::Options o = keep_input();
    change(o);
    EXPECT_THROW(dcg::compute_skin_weights(m.V, m.F, chain(), o), dcg::InputError);
  }
}

TEST(WeightsErrors, ProgressCallbackCancelsAndSeesIncreasingFractions) {
  const Mesh m = capsule(0.5, 2.0);
  std::vector<double> seen;
  dcg::compute_skin_weights(m.V, m.F, chain(), keep_input(), [&](const std::string&, double f) {
    seen.push_back(f);
    return true;
  });
  ASSERT_GE(seen.size(), 3u);
  for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]);
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
  int calls = 0;
  EXPECT_THROW(dcg::compute_skin_weights(m.V, m.F, chain(), keep_input(),
                                         [&](const std::string& stage, double) {
                                           return !(stage == "weights" && ++calls > 2);
                                         }),
               dcg::Cancelled);
}

// --- public meshes (left out of the sanitizer run: *Public*) ------------------------------

TEST(WeightsPublic, HandIsWeightedEverywhere) {
  const std::string file = dcg::test::meshes_dir() + "/hand.obj";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "public meshes not found";
  const Mesh m = dcg::read_mesh(file);
  // Bones: the three principal axes' halves through the center, a crude armature.
  const Eigen::RowVector3d lo = m.V.colwise().minCoeff(), hi = m.V.colwise().maxCoeff();
  const Eigen::Vector3d c = (0.5 * (lo + hi)).transpose(), e = (0.25 * (hi - lo)).transpose();
  const Bones bones = bones_from({{c, c + Eigen::Vector3d(e.x(), 0, 0)},
                                  {c, c - Eigen::Vector3d(e.x(), 0, 0)},
                                  {c, c + Eigen::Vector3d(0, e.y(), 0)},
                                  {c, c - Eigen::Vector3d(0, e.y(), 0)},
                                  {c, c + Eigen::Vector3d(0, 0, e.z())}});
  const dcg::SkinWeights w = dcg::compute_skin_weights(m.V, m.F, bones, dcg::Options{});
  expect_valid(w, static_cast<int>(m.V.rows()), 5);
}

}  // namespace
