// dcg/prepare.h (stage 0): validation errors, welding, repair of open and multi-part input,
// remeshing, normalization, genus and the map back to the input vertices; and its internal steps
// (cpp/src): mesh topology and orientation, compaction, the fast decimator for huge inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "dcg/errors.h"
#include "dcg/io.h"
#include "dcg/prepare.h"
#include "dcg/surface_query.h"
#include "shapes.h"
// Internal steps of stage 0 (not installed headers).
#include "../../cpp/src/compact_mesh.h"
#include "../../cpp/src/decimate.h"
#include "../../cpp/src/fins.h"
#include "../../cpp/src/mesh_topology.h"

namespace {

using dcg::InputError;
using dcg::Mesh;
namespace test = dcg::test;

// Runs prepare_mesh and returns the InputError's message ("" when nothing was thrown).
std::string prepare_error(const Mesh& m, const dcg::PrepareOptions& options = {}) {
  try {
    dcg::prepare_mesh(m.V, m.F, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Coefficient of variation (std / mean) of the edge lengths, each edge once per face side.
double edge_length_variation(const Mesh& m) {
  std::vector<double> lengths;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      lengths.push_back((m.V.row(m.F(f, k)) - m.V.row(m.F(f, (k + 1) % 3))).norm());
  double mean = 0, var = 0;
  for (double l : lengths) mean += l / static_cast<double>(lengths.size());
  for (double l : lengths) var += (l - mean) * (l - mean) / static_cast<double>(lengths.size());
  return std::sqrt(var) / mean;
}

dcg::PrepareOptions keep_input() {
  dcg::PrepareOptions o;
  o.target_faces = 0;
  return o;
}

// --- validation ------------------------------------------------------------------------------

TEST(Validate, NonFiniteCoordinatesAreRejectedWithTheVertex) {
  Mesh m = test::icosphere(1);
  m.V(7, 1) = std::nan("");
  EXPECT_TRUE(contains(prepare_error(m), "vertex 7 has a non-finite coordinate"));
  m.V(7, 1) = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(contains(prepare_error(m), "vertex 7"));
  EXPECT_THROW(dcg::validate_mesh(m.V, m.F), InputError);
}

TEST(Validate, OutOfRangeIndicesAreRejectedWithTheFace) {
  Mesh m = test::icosphere(1);
  m.F(3, 2) = static_cast<int>(m.V.rows());
  EXPECT_TRUE(contains(prepare_error(m), "face 3 has vertex index"));
  EXPECT_TRUE(contains(prepare_error(m), "out of range"));
  m.F(3, 2) = -1;
  EXPECT_TRUE(contains(prepare_error(m), "face 3"));
}

TEST(Validate, TooFewVerticesOrFaces) {
  Mesh tiny;
  tiny.V = dcg::Vertices::Zero(3, 3);
  tiny.V.row(1) << 1, 0, 0;
  tiny.V.row(2) << 0, 1, 0;
  tiny.F.resize(1, 3);
  tiny.F << 0, 1, 2;
  EXPECT_TRUE(contains(prepare_error(tiny), "at least 4 vertices"));
  Mesh m = test::icosphere(0);
  m.F.conservativeResize(3, 3);
  EXPECT_TRUE(contains(prepare_error(m), "at least 4 faces"));
  Mesh empty;
  EXPECT_THROW(dcg::validate_mesh(empty.V, empty.F), InputError);
}

TEST(Validate, DegenerateMeshesAreRejected) {
  // Every face repeats an index: nothing is left after dropping degenerate faces.
  Mesh m = test::icosphere(1);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) m.F(f, 2) = m.F(f, 1);
  EXPECT_TRUE(contains(prepare_error(m), "fewer than 4 faces are left"));
  // All vertices at one point: no extent.
  Mesh point = test::icosphere(1);
  point.V.setConstant(2.0);
  EXPECT_TRUE(contains(prepare_error(point), "no extent"));
  // A flat mesh (all vertices in one plane) encloses nothing, even closed (a double sheet).
  Mesh flat = test::icosphere(2);
  const Eigen::Matrix3d R = [] {
    std::mt19937 rng(3);
    return test::random_rotation(rng);
  }();
  flat.V.col(2).setZero();
  flat = test::transformed(flat, R, 5.0);
  EXPECT_TRUE(contains(prepare_error(flat), "flat"));
}

// --- closed input ------------------------------------------------------------------------------

TEST(Prepare, ClosedInputIsKeptNormalizedAndMappedExactly) {
  std::mt19937 rng(1);
  const Mesh m = test::transformed(test::icosphere(3), test::random_rotation(rng), 37.0,
                                   Eigen::Vector3d(5, -2, 100));
  const dcg::PreparedMesh pm = dcg::prepare_mesh(m.V, m.F, keep_input());
  EXPECT_FALSE(pm.repaired);
  EXPECT_FALSE(pm.remeshed);
  EXPECT_TRUE(pm.report.closed_manifold());
  EXPECT_EQ(pm.report.components, 1);
  EXPECT_EQ(pm.report.welded_vertices, 0);
  EXPECT_EQ(pm.report.dropped_faces, 0);
  EXPECT_EQ(pm.genus, 0);
  EXPECT_EQ(pm.working.F.rows(), m.F.rows());
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
  const double diag =
      (pm.working.V.colwise().maxCoeff() - pm.working.V.colwise().minCoeff()).norm();
  EXPECT_NEAR(diag, 1.0, 1e-12);
  // The map puts every input vertex back where it was.
  ASSERT_EQ(pm.map_face.size(), m.V.rows());
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    Eigen::RowVector3d p = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 3; ++k)
      p += pm.map_barycentric(i, k) * pm.working.V.row(pm.working.F(pm.map_face[i], k));
    EXPECT_LT((pm.to_input(p) - m.V.row(i)).norm(), 1e-9 * pm.scale) << i;
  }
  ASSERT_TRUE(pm.query);
  EXPECT_TRUE(pm.query->inside(Eigen::Vector3d::Zero()));
}

TEST(PrepareInput, OpenMultiPartAndFlatInputsAreKeptAndMappedOntoTheirCorners) {
  // An open capsule, a second part and an unused vertex: cleaned only (nothing wrapped or
  // remeshed, even with a target), every used vertex on its own corner, the unused one on
  // its closest point.
  Mesh m = test::merged(test::cut_above(test::capsule(0.5, 2.0), 1.0),
                        test::transformed(test::icosphere(2), Eigen::Matrix3d::Identity(), 0.3,
                                          Eigen::Vector3d(2, 0, 0)));
  m.V.conservativeResize(m.V.rows() + 1, 3);
  m.V.row(m.V.rows() - 1) << 2, 0, 0.5;  // in no face, 0.2 above the sphere
  const dcg::PreparedMesh pm = dcg::prepare_input(m.V, m.F, dcg::PrepareOptions());
  EXPECT_FALSE(pm.repaired);
  EXPECT_FALSE(pm.remeshed);
  EXPECT_GT(pm.report.border_edges, 0);
  EXPECT_EQ(pm.report.components, 2);
  std::vector<char> used(m.V.rows(), 0);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[m.F(f, k)] = 1;
  EXPECT_EQ(pm.working.V.rows(), std::count(used.begin(), used.end(), 1));
  ASSERT_EQ(pm.map_face.size(), m.V.rows());
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    Eigen::RowVector3d p = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 3; ++k)
      p += pm.map_barycentric(i, k) * pm.working.V.row(pm.working.F(pm.map_face[i], k));
    const double gap = (pm.to_input(p) - m.V.row(i)).norm();
    if (used[i]) {
      EXPECT_LT(gap, 1e-9 * pm.scale) << i;
    }
    if (i + 1 == m.V.rows()) {
      EXPECT_NEAR(gap, 0.2, 0.01);
    }
  }
  // A flat sheet is fine here (stage 0 proper rejects it: it encloses nothing).
  Mesh flat = test::icosphere(2);
  flat.V.col(2).setZero();
  EXPECT_NO_THROW(dcg::prepare_input(flat.V, flat.F));
}

TEST(Prepare, InwardFacingInputIsOrientedOutward) {
  Mesh m = test::icosphere(2);
  m.F.col(1).swap(m.F.col(2));  // every face inward
  const dcg::PreparedMesh pm = dcg::prepare_mesh(m.V, m.F, keep_input());
  EXPECT_FALSE(pm.repaired);
  double volume = 0;
  for (Eigen::Index f = 0; f < pm.working.F.rows(); ++f) {
    const Eigen::Vector3d a = pm.working.V.row(pm.working.F(f, 0)),
                          b = pm.working.V.row(pm.working.F(f, 1)),
                          c = pm.working.V.row(pm.working.F(f, 2));
    volume += a.dot(b.cross(c)) / 6.0;
  }
  EXPECT_GT(volume, 0);
}

TEST(Prepare, GenusOfSphereTorusAndTwoTori) {
  EXPECT_EQ(dcg::mesh_genus(test::icosphere(2)), 0);
  EXPECT_EQ(dcg::mesh_genus(test::torus(1.0, 0.3)), 1);
  EXPECT_EQ(dcg::mesh_genus(
                test::merged(test::torus(1.0, 0.3),
                             test::transformed(test::torus(1.0, 0.3), Eigen::Matrix3d::Identity(),
                                               1.0, Eigen::Vector3d(5, 0, 0)))),
            2);
  // Through prepare, with and without remeshing.
  const Mesh torus = test::torus(1.0, 0.35, 64, 32);
  EXPECT_EQ(dcg::prepare_mesh(torus.V, torus.F, keep_input()).genus, 1);
  dcg::PrepareOptions remesh;
  remesh.target_faces = 12000;  // 4096 faces: too far from the target to be kept
  remesh.upsample = true;
  const dcg::PreparedMesh pm = dcg::prepare_mesh(torus.V, torus.F, remesh);
  EXPECT_TRUE(pm.remeshed);
  EXPECT_EQ(pm.genus, 1);
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
}

// Without upsample (the Extractor's default), an input under target_faces / 2.5 is its own
// working mesh when it has at least kMinKeptFaces even faces; a tiny one is remeshed, to about
// kSmallRemeshFaces only; with upsample, both go up to target_faces.
TEST(Prepare, SmallInputsAreKeptUnlessTinyWithoutUpsample) {
  const Mesh torus = test::torus(1.0, 0.35, 64, 32);  // 4096 even faces
  const Mesh tiny = test::torus(1.0, 0.35, 16, 8);    // 256 faces
  dcg::PrepareOptions o;
  o.target_faces = 20000;
  o.upsample = false;
  const dcg::PreparedMesh kept = dcg::prepare_mesh(torus.V, torus.F, o);
  EXPECT_FALSE(kept.remeshed);
  EXPECT_EQ(kept.working.F.rows(), torus.F.rows());
  const dcg::PreparedMesh small = dcg::prepare_mesh(tiny.V, tiny.F, o);
  EXPECT_TRUE(small.remeshed);
  EXPECT_GT(small.working.F.rows(), dcg::kSmallRemeshFaces / 2);
  EXPECT_LT(small.working.F.rows(), 2 * dcg::kSmallRemeshFaces);
  EXPECT_EQ(small.genus, 1);
  o.upsample = true;
  const dcg::PreparedMesh up = dcg::prepare_mesh(torus.V, torus.F, o);
  EXPECT_TRUE(up.remeshed);
  EXPECT_GT(up.working.F.rows(), 10000);
}

TEST(Prepare, RemeshingReachesAboutTheTargetAndMapsNearby) {
  const Mesh m = test::capsule(0.5, 2.0, 8, 24, 6);  // few, long triangles
  dcg::PrepareOptions o;
  o.target_faces = 5000;
  o.upsample = true;
  const dcg::PreparedMesh pm = dcg::prepare_mesh(m.V, m.F, o);
  EXPECT_TRUE(pm.remeshed);
  EXPECT_GT(pm.working.F.rows(), 2500);
  EXPECT_LT(pm.working.F.rows(), 10000);
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    Eigen::RowVector3d p = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 3; ++k)
      p += pm.map_barycentric(i, k) * pm.working.V.row(pm.working.F(pm.map_face[i], k));
    EXPECT_LT((pm.to_input(p) - m.V.row(i)).norm(), 0.01 * pm.scale) << i;
    EXPECT_NEAR(pm.map_barycentric.row(i).sum(), 1.0, 1e-12);
    EXPECT_GE(pm.map_barycentric.row(i).minCoeff(), 0.0);
  }
  // A large mesh is decimated down to about the target as well.
  const Mesh big = test::icosphere(6);  // 81,920 faces
  o.target_faces = 8000;
  const dcg::PreparedMesh small = dcg::prepare_mesh(big.V, big.F, o);
  EXPECT_GT(small.working.F.rows(), 4000);
  EXPECT_LT(small.working.F.rows(), 16000);
  EXPECT_TRUE(test::is_closed_oriented_manifold(small.working));
  // So is an uneven one above the target (collapsed where it is fine first, then remeshed): a
  // capsule with fine caps and one section of long triangles between them.
  const Mesh uneven = test::capsule(0.5, 2.0, 40, 64, 1);
  ASSERT_GT(uneven.F.rows(), 10000);
  EXPECT_GE(edge_length_variation(uneven), dcg::kMaxKeptVariation);
  o.target_faces = 5000;
  o.upsample = false;
  const dcg::PreparedMesh even = dcg::prepare_mesh(uneven.V, uneven.F, o);
  EXPECT_TRUE(even.remeshed);
  EXPECT_GT(even.working.F.rows(), 2500);
  EXPECT_LT(even.working.F.rows(), 10000);
  EXPECT_LT(edge_length_variation(even.working), 0.5);
  EXPECT_TRUE(test::is_closed_oriented_manifold(even.working));
  EXPECT_EQ(even.genus, 0);
}

// The remeshing follows the surface, not how its vertices and faces are numbered: CGAL 5.5 and
// 6 number what they make differently, and the steps after (flips, relaxation) visit the mesh
// in that order, so before the remeshing ran its steps on a canonical mesh, Debian 12 and 13
// gave different working meshes, and different skeletons, for the same input.
TEST(Prepare, RemeshingGivesTheSameMeshWhateverTheInputsNumbering) {
  const Mesh m = test::capsule(0.5, 2.0, 8, 24, 6);  // few, long triangles: remeshed
  std::mt19937 rng(7);
  std::vector<int> order(m.V.rows());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::shuffle(order.begin(), order.end(), rng);
  Mesh shuffled;
  shuffled.V.resize(m.V.rows(), 3);
  for (std::size_t i = 0; i < order.size(); ++i) shuffled.V.row(order[i]) = m.V.row(i);
  std::vector<int> faces(m.F.rows());
  for (std::size_t f = 0; f < faces.size(); ++f) faces[f] = static_cast<int>(f);
  std::shuffle(faces.begin(), faces.end(), rng);
  shuffled.F.resize(m.F.rows(), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const int turn = static_cast<int>(f % 3);  // each face from another corner, same way round
    for (int k = 0; k < 3; ++k) shuffled.F(f, k) = order[m.F(faces[f], (k + turn) % 3)];
  }
  dcg::PrepareOptions o;
  o.target_faces = 5000;
  o.upsample = true;
  const dcg::PreparedMesh a = dcg::prepare_mesh(m.V, m.F, o);
  const dcg::PreparedMesh b = dcg::prepare_mesh(shuffled.V, shuffled.F, o);
  ASSERT_TRUE(a.remeshed && b.remeshed);
  ASSERT_EQ(a.working.V.rows(), b.working.V.rows());
  ASSERT_EQ(a.working.F.rows(), b.working.F.rows());
  EXPECT_EQ((a.working.V - b.working.V).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE(a.working.F == b.working.F);
}

// Normalized, a scaled and moved copy differs from the original in the last bits only, and the
// remeshing starts from its input snapped to a grid far finer than any shape: the working
// meshes are the same. (Without the snap, equally long edges split and collapsed in an order
// the last bits decided, and a small ellipsoid scaled by 1e-6 lost 12% of its diagonal on one
// end.)
TEST(Prepare, ScaledAndMovedCopiesRemeshAlike) {
  const Mesh m = test::transformed(test::icosphere(1), Eigen::Vector3d(2.0, 1.0, 0.6).asDiagonal(),
                                   1.0, Eigen::Vector3d::Zero());
  dcg::PrepareOptions o;
  o.target_faces = 3000;
  o.upsample = true;
  const dcg::PreparedMesh a = dcg::prepare_mesh(m.V, m.F, o);
  ASSERT_TRUE(a.remeshed);
  for (const double scale : {1e-6, 1e6}) {
    const Mesh copy = test::transformed(m, Eigen::Matrix3d::Identity(), scale,
                                        Eigen::Vector3d(3 * scale, -scale, 0.5 * scale));
    const dcg::PreparedMesh b = dcg::prepare_mesh(copy.V, copy.F, o);
    ASSERT_EQ(a.working.V.rows(), b.working.V.rows()) << scale;
    ASSERT_EQ(a.working.F.rows(), b.working.F.rows()) << scale;
    EXPECT_TRUE(a.working.F == b.working.F) << scale;
    EXPECT_LT((a.working.V - b.working.V).cwiseAbs().maxCoeff(), 1e-9) << scale;
  }
}

TEST(Prepare, HugeInputIsReducedFastIntoAClosedManifoldWithACompleteMap) {
  // 160,000 faces: far above 3 x target_faces, so stage 0 first reduces it by its pass-wise edge
  // collapse (to 1.5 x target_faces) before the remeshing.
  const Mesh big = test::torus(1.0, 0.35, 400, 200);
  dcg::PrepareOptions o;
  o.target_faces = 5000;
  std::vector<double> fractions;
  const dcg::Progress progress([&](const std::string& stage, double f) {
    EXPECT_EQ(stage, "prepare");
    fractions.push_back(f);
    return true;
  });
  const dcg::PreparedMesh pm = dcg::prepare_mesh(big.V, big.F, o, progress, 0.0, 1.0);
  EXPECT_TRUE(pm.remeshed);
  EXPECT_GT(pm.working.F.rows(), 2500);
  EXPECT_LT(pm.working.F.rows(), 10000);
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
  EXPECT_EQ(pm.genus, 1);
  ASSERT_EQ(pm.map_face.size(), big.V.rows());
  double worst = 0;
  for (Eigen::Index i = 0; i < big.V.rows(); ++i) {
    ASSERT_GE(pm.map_face[i], 0);
    ASSERT_LT(pm.map_face[i], pm.working.F.rows());
    Eigen::RowVector3d p = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 3; ++k)
      p += pm.map_barycentric(i, k) * pm.working.V.row(pm.working.F(pm.map_face[i], k));
    worst = std::max(worst, (pm.to_input(p) - big.V.row(i)).norm() / pm.scale);
  }
  EXPECT_LT(worst, 0.01);
  // Polled all along (at most every 10 ms), with fractions that never go back.
  EXPECT_GT(fractions.size(), 5u);
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_LE(fractions.back(), 1.0);
  // A cancel request in the middle stops it.
  int calls = 0;
  const int stop_at = static_cast<int>(fractions.size()) / 2;
  const dcg::Progress cancel([&](const std::string&, double) { return ++calls < stop_at; });
  EXPECT_THROW(dcg::prepare_mesh(big.V, big.F, o, cancel, 0.0, 1.0), dcg::Cancelled);
  EXPECT_EQ(calls, stop_at);
}

// --- welding -------------------------------------------------------------------------------------

TEST(Prepare, TriangleSoupIsWeldedIntoAClosedMesh) {
  const Mesh m = test::icosphere(2);
  Mesh soup;
  soup.V.resize(3 * m.F.rows(), 3);
  soup.F.resize(m.F.rows(), 3);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      soup.V.row(3 * f + k) = m.V.row(m.F(f, k));
      soup.F(f, k) = static_cast<int>(3 * f + k);
    }
  const dcg::PreparedMesh pm = dcg::prepare_mesh(soup.V, soup.F, keep_input());
  EXPECT_FALSE(pm.repaired);
  EXPECT_EQ(pm.report.welded_vertices, soup.V.rows() - m.V.rows());
  EXPECT_EQ(pm.working.V.rows(), m.V.rows());
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
}

TEST(Prepare, CoincidingVerticesOfAClosedMeshAreNotWelded) {
  // Two distinct, non-adjacent vertices at the same place (as in cow.off and dino.off): welding
  // them would pinch the closed surface into a non-manifold one and force a repair.
  Mesh m = test::icosphere(3);
  const int a = m.F(0, 0);
  std::vector<char> near_a(m.V.rows(), 0);  // a and its neighbours
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    if (m.F(f, 0) == a || m.F(f, 1) == a || m.F(f, 2) == a)
      for (int k = 0; k < 3; ++k) near_a[m.F(f, k)] = 1;
  int b = -1;  // the closest vertex that shares no face with a
  for (Eigen::Index v = 0; v < m.V.rows(); ++v) {
    if (near_a[v]) continue;
    if (b < 0 || (m.V.row(v) - m.V.row(a)).norm() < (m.V.row(b) - m.V.row(a)).norm())
      b = static_cast<int>(v);
  }
  m.V.row(b) = m.V.row(a);
  const dcg::PreparedMesh pm = dcg::prepare_mesh(m.V, m.F, keep_input());
  EXPECT_EQ(pm.report.welded_vertices, 0);
  EXPECT_FALSE(pm.repaired);
  EXPECT_EQ(pm.working.V.rows(), m.V.rows());
}

// --- open and multi-part input
// ---------------------------------------------------------------------

TEST(Repair, OpenMeshRaisesWithRepairNoneNamingTheHoles) {
  const Mesh open = test::cut_above(test::icosphere(3), 0.8);
  dcg::PrepareOptions o;
  o.repair = dcg::Repair::None;
  const std::string message = prepare_error(open, o);
  EXPECT_TRUE(contains(message, "not a single closed manifold")) << message;
  EXPECT_TRUE(contains(message, "border edges")) << message;
  EXPECT_TRUE(contains(message, "1 border loops")) << message;
}

TEST(Repair, OpenMeshIsWrappedIntoAClosedManifold) {
  // A hole of about 1/7 of the diagonal at the top (a scan hole, not a cup: the wrap is a solid
  // only while its ball cannot pass the hole, see prepare.cpp).
  const Mesh open = test::cut_above(test::capsule(0.5, 2.0), 1.45);
  dcg::PrepareOptions o;
  o.target_faces = 4000;
  const dcg::PreparedMesh pm = dcg::prepare_mesh(open.V, open.F, o);
  EXPECT_TRUE(pm.repaired);
  EXPECT_GT(pm.wrap_alpha, 0);
  EXPECT_GT(pm.report.border_edges, 0);
  EXPECT_EQ(pm.report.border_loops, 1);
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
  EXPECT_EQ(test::component_count(pm.working), 1);
  EXPECT_EQ(pm.genus, 0);
  // The capsule's center (the origin of the input) is inside the proxy.
  EXPECT_TRUE(pm.query->inside((-pm.offset / pm.scale).transpose()));
}

TEST(Repair, MultiPartInputRaisesOrIsWrapped) {
  const Mesh two = test::merged(
      test::icosphere(2), test::transformed(test::icosphere(2), Eigen::Matrix3d::Identity(), 1.0,
                                            Eigen::Vector3d(1.5, 0, 0)));
  dcg::PrepareOptions none;
  none.repair = dcg::Repair::None;
  const std::string message = prepare_error(two, none);
  EXPECT_TRUE(contains(message, "2 components")) << message;
  // Overlapping spheres: the wrap is their union, one closed shell.
  dcg::PrepareOptions o;
  o.target_faces = 4000;
  const dcg::PreparedMesh pm = dcg::prepare_mesh(two.V, two.F, o);
  EXPECT_TRUE(pm.repaired);
  EXPECT_EQ(pm.report.components, 2);
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
  EXPECT_EQ(test::component_count(pm.working), 1);
}

// Closed parts that overlap, nest and stand apart: their union, not a wrap. Each part is a
// closed solid, so stage 0 unites them (the overlapping pair into one shell, the nested sphere
// swallowed by the one around it, the far one kept as its own shell) and keeps their surface.
TEST(Repair, ClosedPartsAreUnitedNotWrapped) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Mesh big = test::icosphere(3);
  Mesh parts = test::merged(big, test::transformed(test::icosphere(3), I, 0.8, {1.3, 0, 0}));
  parts = test::merged(parts, test::transformed(test::icosphere(2), I, 0.3, {-0.2, 0, 0}));
  parts = test::merged(parts, test::transformed(test::icosphere(2), I, 0.25, {0, 3, 0}));
  dcg::PrepareOptions o;
  o.target_faces = 0;
  const dcg::PreparedMesh pm = dcg::prepare_mesh(parts.V, parts.F, o);
  EXPECT_EQ(pm.report.components, 4);
  EXPECT_TRUE(pm.repaired);
  EXPECT_EQ(pm.wrap_alpha, 0) << "united, not wrapped";
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
  EXPECT_EQ(test::component_count(pm.working), 2);
  // The surface is the input's own: every working vertex lies on one of the outer spheres (no
  // offset), none on the nested one or inside the overlap.
  const Eigen::RowVector3d c0 = (Eigen::RowVector3d(0, 0, 0) - pm.offset) / pm.scale,
                           c1 = (Eigen::RowVector3d(1.3, 0, 0) - pm.offset) / pm.scale,
                           c3 = (Eigen::RowVector3d(0, 3, 0) - pm.offset) / pm.scale;
  const double r0 = 1 / pm.scale, r1 = 0.8 / pm.scale, r3 = 0.25 / pm.scale;
  for (Eigen::Index v = 0; v < pm.working.V.rows(); ++v) {
    const Eigen::RowVector3d p = pm.working.V.row(v);
    const double d0 = (p - c0).norm() - r0, d1 = (p - c1).norm() - r1, d3 = (p - c3).norm() - r3;
    const double tol = 0.02 * r0;  // the icospheres' facets lie inside their spheres
    const bool on_union = (std::abs(d0) < tol && d1 > -tol) || (std::abs(d1) < tol && d0 > -tol);
    EXPECT_TRUE(on_union || std::abs(d3) < tol) << "vertex " << v;
  }
  EXPECT_TRUE(
      pm.query->inside(((Eigen::RowVector3d(0.9, 0, 0) - pm.offset) / pm.scale).transpose()))
      << "the overlap is inside the union";
  EXPECT_TRUE(
      pm.query->inside(((Eigen::RowVector3d(-0.2, 0, 0) - pm.offset) / pm.scale).transpose()))
      << "the nested sphere's centre is inside the union";
}

// Four overlapping closed parts, one of which crosses itself (a vertex pushed through to the far
// side, as a noise does where faces nearly touch): only that part is wrapped, then all are
// united, and the others keep their own surface (they were all wrapped, every detail smoothed).
// With two of the four crossing, the whole is wrapped (union.cpp, kMostRewrapped).
TEST(Repair, APartThatCrossesItselfIsWrappedAloneThenUnited) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Mesh crossing = test::icosphere(2);
  Eigen::Index top = 0;
  crossing.V.col(2).maxCoeff(&top);
  crossing.V.row(top) << 0, 0, -1.4;  // through the centre and out under the bottom
  const Mesh other = test::transformed(test::icosphere(3), I, 0.8, {1.3, 0, 0});
  const Mesh small = test::transformed(test::icosphere(2), I, 0.3, {1.3, 0.8, 0});
  const Mesh first = test::merged(crossing, other);
  const Mesh parts = test::merged(
      first, test::merged(small, test::transformed(test::icosphere(2), I, 0.3, {1.3, -0.8, 0})));
  const Mesh twice =
      test::merged(first, test::merged(small, test::transformed(crossing, I, 0.3, {1.3, -0.8, 0})));
  EXPECT_GT(dcg::prepare_mesh(twice.V, twice.F, keep_input()).wrap_alpha, 0);
  const dcg::PreparedMesh pm = dcg::prepare_mesh(parts.V, parts.F, keep_input());
  EXPECT_TRUE(pm.repaired);
  EXPECT_EQ(pm.wrap_alpha, 0) << "united, not wrapped whole";
  EXPECT_EQ(pm.report.wrapped_parts, 1);
  EXPECT_DOUBLE_EQ(pm.report.part_wrap_alpha, 0.01);
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
  EXPECT_EQ(test::component_count(pm.working), 1);
  // The far side of the other part is its own surface: its vertices there, exactly.
  int kept = 0, far = 0;
  for (Eigen::Index v = 0; v < other.V.rows(); ++v) {
    if (other.V(v, 0) < 1.6) continue;
    ++far;
    const Eigen::RowVector3d p = (other.V.row(v) - pm.offset) / pm.scale;
    for (Eigen::Index w = 0; w < pm.working.V.rows(); ++w)
      if ((pm.working.V.row(w) - p).norm() < 1e-12) {
        ++kept;
        break;
      }
  }
  EXPECT_GT(far, 50);
  EXPECT_EQ(kept, far);
}

// Two spheres that share one vertex (a pinched, non-manifold vertex): the vertex is split into
// one copy per fan, and the two spheres stay as they are (touching at that point), not wrapped.
TEST(Repair, PinchedVertexIsSplitNotWrapped) {
  const Mesh a = test::icosphere(3);
  Eigen::Index top = 0;
  a.V.col(0).maxCoeff(&top);
  Mesh b = test::transformed(a, -Eigen::Matrix3d::Identity(), 1.0, 2 * a.V.row(top).transpose());
  Mesh pinched = test::merged(a, b);
  const int nv = static_cast<int>(a.V.rows());
  for (Eigen::Index f = 0; f < pinched.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (pinched.F(f, k) == nv + top) pinched.F(f, k) = static_cast<int>(top);
  dcg::PrepareOptions o;
  o.target_faces = 0;
  const dcg::PreparedMesh pm = dcg::prepare_mesh(pinched.V, pinched.F, o);
  EXPECT_EQ(pm.report.non_manifold_vertices, 1);
  EXPECT_EQ(pm.report.components, 2) << "components are counted over shared edges";
  EXPECT_TRUE(pm.repaired);
  EXPECT_EQ(pm.wrap_alpha, 0) << "split, not wrapped";
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
  EXPECT_EQ(test::component_count(pm.working), 2);
  EXPECT_EQ(pm.working.F.rows(), pinched.F.rows()) << "the input's own faces";
  EXPECT_EQ(pm.working.V.rows(), 2 * nv) << "the pinched vertex in two copies";
}

// A part that is open is no closed solid: the whole mesh is wrapped as before.
TEST(Repair, AnOpenPartSendsTheWholeMeshToTheWrap) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Mesh parts = test::merged(
      test::icosphere(3),
      test::transformed(test::cut_above(test::icosphere(3), 0.9), I, 0.5, {1.2, 0, 0}));
  dcg::PrepareOptions o;
  o.target_faces = 4000;
  const dcg::PreparedMesh pm = dcg::prepare_mesh(parts.V, parts.F, o);
  EXPECT_TRUE(pm.repaired);
  EXPECT_GT(pm.wrap_alpha, 0);
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
}

// `m` with a one-quad fin (two triangles, zero volume) hung outward on the edge F(0,0)-F(0,1).
Mesh with_fin(const Mesh& m) {
  const int a = m.F(0, 0), b = m.F(0, 1), n = static_cast<int>(m.V.rows());
  Mesh out = m;
  out.V.conservativeResize(n + 2, 3);
  out.V.row(n) = 1.5 * m.V.row(a);
  out.V.row(n + 1) = 1.5 * m.V.row(b);
  out.F.conservativeResize(m.F.rows() + 2, 3);
  out.F.row(m.F.rows()) << a, b, n + 1;
  out.F.row(m.F.rows() + 1) << a, n + 1, n;
  return out;
}

// A 2 x 1 x 1 box of unit squares divided in two by an inner wall at x = 1: the wall's four
// edges have three faces each.
Mesh box_with_wall() {
  std::vector<Eigen::Vector3d> V;
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 2; ++y)
      for (int z = 0; z < 2; ++z) V.emplace_back(x, y, z);
  auto id = [](int x, int y, int z) { return 4 * x + 2 * y + z; };
  std::vector<std::array<int, 3>> F;
  auto square = [&](int a, int b, int c, int d) {
    F.push_back({a, b, c});
    F.push_back({a, c, d});
  };
  for (int x : {0, 1, 2})
    square(id(x, 0, 0), id(x, 1, 0), id(x, 1, 1), id(x, 0, 1));  // x = 1: wall
  for (int x = 0; x < 2; ++x) {
    square(id(x, 0, 0), id(x, 0, 1), id(x + 1, 0, 1), id(x + 1, 0, 0));
    square(id(x, 1, 0), id(x + 1, 1, 0), id(x + 1, 1, 1), id(x, 1, 1));
    square(id(x, 0, 0), id(x + 1, 0, 0), id(x + 1, 1, 0), id(x, 1, 0));
    square(id(x, 0, 1), id(x, 1, 1), id(x + 1, 1, 1), id(x + 1, 0, 1));
  }
  return test::make_mesh(V, F);
}

TEST(Fins, AFinAndAnInnerWallAreDroppedAndTheClosedPartsKept) {
  const Mesh sphere = test::icosphere(2);
  const auto fin = dcg::internal::drop_fins(with_fin(sphere));
  ASSERT_TRUE(fin.has_value());
  EXPECT_EQ(fin->dropped_faces, 2);
  EXPECT_EQ(fin->mesh.F.rows(), sphere.F.rows());
  EXPECT_EQ(fin->mesh.V.rows(), sphere.V.rows()) << "the fin's own vertices go with it";
  const auto wall = dcg::internal::drop_fins(box_with_wall());
  ASSERT_TRUE(wall.has_value());
  EXPECT_EQ(wall->dropped_faces, 2) << "the wall, not one of the half boxes it divides";
  EXPECT_EQ(wall->mesh.F.rows(), 20);
  const dcg::internal::Topology t = dcg::internal::analyze_topology(wall->mesh.V, wall->mesh.F);
  EXPECT_EQ(t.border_edges + t.non_manifold_edges, 0);
  EXPECT_EQ(t.components, 1);
}

TEST(Fins, NothingIsDroppedWhenTheRestIsNotClosedOrThereIsNoFin) {
  EXPECT_FALSE(dcg::internal::drop_fins(test::icosphere(2)).has_value()) << "no fin";
  EXPECT_FALSE(
      dcg::internal::drop_fins(with_fin(test::cut_above(test::icosphere(2), 0.5))).has_value())
      << "the part the fin hangs on is open";
  // Three triangles on one edge and nothing closed: dropping would leave a hole.
  const Mesh sheets = test::make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}},
                                      {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  EXPECT_FALSE(dcg::internal::drop_fins(sheets).has_value());
}

// `m` and a small closed sphere apart from it (a second part).
Mesh beside_a_small_sphere(const Mesh& m) {
  return test::merged(
      m, test::transformed(test::icosphere(2), Eigen::Matrix3d::Identity(), 0.5, {3, 0, 0}));
}

// A repaired working mesh that is the union of `components` closed parts, not a wrap.
void expect_united_not_wrapped(const dcg::PreparedMesh& pm, int components) {
  EXPECT_TRUE(pm.repaired);
  EXPECT_EQ(pm.wrap_alpha, 0) << "united, not wrapped";
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
  EXPECT_EQ(test::component_count(pm.working), components);
}

// The box [lo, hi], 12 triangles facing outward.
Mesh box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  std::vector<Eigen::Vector3d> V;
  for (int i = 0; i < 8; ++i)
    V.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  std::vector<std::array<int, 3>> F;
  const Eigen::Vector3d centre = (lo + hi) / 2;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = 1 << ((axis + 1) % 3), w = 1 << ((axis + 2) % 3);
    for (int side : {0, 1 << axis}) {
      for (std::array<int, 3> t : {std::array<int, 3>{side, side + u, side + u + w},
                                   std::array<int, 3>{side, side + u + w, side + w}}) {
        const Eigen::Vector3d normal = (V[t[1]] - V[t[0]]).cross(V[t[2]] - V[t[0]]);
        if (normal.dot(V[t[0]] - centre) < 0) std::swap(t[1], t[2]);
        F.push_back(t);
      }
    }
  }
  return test::make_mesh(V, F);
}

// Six slabs, the walls of a hollow box, each overlapping its neighbours: each is a solid, but
// their union encloses the box's inside, a void whose walls CGAL's union keeps as a shell facing
// inward. Stage 0 fills it: one shell, the void inside the solid, and the report says so.
TEST(Repair, AVoidThePartsEncloseIsFilled) {
  Mesh walls = box({0.8, -1, -1}, {1, 1, 1});
  for (const auto& [lo, hi] : std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>{
           {{-1, -1, -1}, {-0.8, 1, 1}},
           {{-0.9, 0.78, -0.96}, {0.9, 0.98, 0.96}},
           {{-0.9, -0.98, -0.96}, {0.9, -0.78, 0.96}},
           {{-0.88, -0.93, 0.76}, {0.88, 0.93, 0.94}},
           {{-0.88, -0.93, -0.94}, {0.88, 0.93, -0.76}}})
    walls = test::merged(walls, box(lo, hi));
  const dcg::PreparedMesh pm = dcg::prepare_mesh(walls.V, walls.F, keep_input());
  EXPECT_EQ(pm.report.components, 6);
  EXPECT_EQ(pm.report.cavities, 1);
  expect_united_not_wrapped(pm, 1);
  EXPECT_TRUE(pm.query->inside(((Eigen::RowVector3d(0, 0, 0) - pm.offset) / pm.scale).transpose()))
      << "the void is inside the solid";
  const Mesh apart = beside_a_small_sphere(test::icosphere(2));
  EXPECT_EQ(dcg::prepare_mesh(apart.V, apart.F, keep_input()).report.cavities, 0)
      << "a part beside another encloses nothing";
}

// Stage 0 unites what is left instead of wrapping, and says how many faces it left out.
TEST(Repair, FinsOnClosedPartsAreDroppedAndThePartsUnitedNotWrapped) {
  const Mesh parts = beside_a_small_sphere(with_fin(test::icosphere(3)));
  const dcg::PreparedMesh pm = dcg::prepare_mesh(parts.V, parts.F, keep_input());
  EXPECT_EQ(pm.report.non_manifold_edges, 1);
  EXPECT_EQ(pm.report.fin_faces, 2);
  expect_united_not_wrapped(pm, 2);
  EXPECT_EQ(pm.working.F.rows(), parts.F.rows() - 2) << "the input's own faces but the fin's";
  EXPECT_EQ(pm.map_face.size(), parts.V.rows()) << "the fin's vertices are mapped too";
}

// A part with a small hole (a cap cut off) is closed by filling the hole and united with the
// others, not wrapped; a hole too large for that still sends the mesh to the wrap.
TEST(Repair, SmallHolesAreFilledAndThePartsUnitedNotWrapped) {
  // A hole 1/20 of the diagonal.
  const Mesh parts = beside_a_small_sphere(test::cut_above(test::icosphere(4), 0.99));
  const dcg::PreparedMesh pm = dcg::prepare_mesh(parts.V, parts.F, keep_input());
  EXPECT_GT(pm.report.border_edges, 0);
  EXPECT_EQ(pm.report.filled_holes, 1);
  expect_united_not_wrapped(pm, 2);
  EXPECT_GT(pm.working.F.rows(), parts.F.rows()) << "the input's faces and the hole's patch";
  const dcg::PreparedMesh big =
      dcg::prepare_mesh(test::cut_above(test::icosphere(3), 0.3).V,
                        test::cut_above(test::icosphere(3), 0.3).F, keep_input());
  EXPECT_EQ(big.report.filled_holes, 0);
  EXPECT_GT(big.wrap_alpha, 0) << "a hole of most of the diagonal is not filled";
}

// Mannequiny (59 closed parts once its 7 small holes are filled) with its coordinates rounded to
// float32, as Blender hands every mesh over: the union with inexact constructions crosses itself
// there, and the exact one (union.cpp, unite_exactly) keeps its parts' own surface instead of
// the 2% wrap that smoothed its fingers away.
TEST(Repair, PartsUniteWhenTheirCoordinatesAreFloat32) {
  const std::string path = test::meshes_dir() + "/rigged/Mannequiny.obj";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not found (set DCG_MESHES)";
  Mesh m = dcg::read_mesh(path);
  m.V = m.V.cast<float>().cast<double>();
  const dcg::PreparedMesh pm = dcg::prepare_mesh(m.V, m.F, keep_input());
  EXPECT_EQ(pm.report.filled_holes, 7);
  EXPECT_EQ(pm.wrap_alpha, 0) << "united, not wrapped";
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
}

// The public open meshes of ../shared/meshes (DCG_MESHES).
class OpenMeshFile : public ::testing::TestWithParam<std::string> {};

TEST_P(OpenMeshFile, RepairAutoClosesItAndRepairNoneNamesTheProblem) {
  const std::string path = test::meshes_dir() + "/" + GetParam();
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not found (set DCG_MESHES)";
  const Mesh m = dcg::read_mesh(path);
  dcg::PrepareOptions none;
  none.repair = dcg::Repair::None;
  const std::string message = prepare_error(m, none);
  EXPECT_TRUE(contains(message, "border edges")) << message;
  if (GetParam() == "wolf-open.obj") {
    EXPECT_TRUE(contains(message, "128 border edges")) << message;
    EXPECT_TRUE(contains(message, "3 components")) << message;
    // Its 4 holes are small (the largest 7% of the diagonal) and filled, its parts cross
    // themselves (all 3, too many to wrap one by one: no union): the filled mesh is wrapped at 2%
    // of the diagonal, not at 0.6 x the largest hole (4.3%), whose wrap webbed the legs together
    // (4 ends of 6, 77% of the skeleton inside).
    const dcg::PreparedMesh kept = dcg::prepare_mesh(m.V, m.F, dcg::PrepareOptions());
    EXPECT_EQ(kept.report.filled_holes, 4);
    EXPECT_DOUBLE_EQ(kept.wrap_alpha, 0.02);
    EXPECT_EQ(kept.report.wrapped_parts, 0);
    EXPECT_TRUE(test::is_closed_oriented_manifold(kept.working));
  }
  dcg::PrepareOptions up;  // the proxy remeshed up to target_faces
  up.upsample = true;
  const dcg::PreparedMesh pm = dcg::prepare_mesh(m.V, m.F, up);
  EXPECT_TRUE(pm.repaired);
  EXPECT_TRUE(test::is_closed_oriented_manifold(pm.working));
  EXPECT_GT(pm.working.F.rows(), 10000);
  EXPECT_EQ(pm.map_face.size(), m.V.rows());
}

INSTANTIATE_TEST_SUITE_P(PublicMeshes, OpenMeshFile,
                         ::testing::Values("wolf-open.obj", "bunny-scan-open.obj"));

// --- internal steps: topology, orientation, compaction, decimation -------------------------------

// The unit tetrahedron (0, e_x, e_y, e_z), faces outward: volume 1/6.
Mesh tetrahedron() {
  return test::make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                         {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
}

double signed_volume(const Mesh& m) {
  double volume = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    volume += a.dot(b.cross(c)) / 6.0;
  }
  return volume;
}

TEST(MeshTopology, CountsOfAClosedAndAnOpenTetrahedron) {
  const Mesh tet = tetrahedron();
  const dcg::internal::Topology closed = dcg::internal::analyze_topology(tet.V, tet.F);
  EXPECT_EQ(closed.edges, 6);
  EXPECT_EQ(closed.border_edges, 0);
  EXPECT_EQ(closed.border_loops, 0);
  EXPECT_EQ(closed.non_manifold_edges, 0);
  EXPECT_EQ(closed.non_manifold_vertices, 0);
  EXPECT_EQ(closed.components, 1);
  EXPECT_EQ(closed.largest_hole, 0.0);
  // Face 0 (0, 2, 1) meets face 1 (0, 1, 3) over its edge 1 -> 0, its third slot.
  EXPECT_EQ(closed.neighbours[0][2], 1);
  // Without the face on the slanted side: one hole, its extent the triangle's bounding box.
  Mesh open = tet;
  open.F.conservativeResize(3, 3);
  const dcg::internal::Topology t = dcg::internal::analyze_topology(open.V, open.F);
  EXPECT_EQ(t.edges, 6);
  EXPECT_EQ(t.border_edges, 3);
  EXPECT_EQ(t.border_loops, 1);
  EXPECT_NEAR(t.largest_hole, std::sqrt(3.0), 1e-15);
  EXPECT_EQ(t.neighbours[0][2], 1);
  EXPECT_EQ(std::count(t.neighbours[0].begin(), t.neighbours[0].end(), -1), 1);
}

TEST(MeshTopology, NonManifoldEdgesVerticesAndComponents) {
  // Three triangles on one edge 0-1.
  const Mesh fin = test::make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}},
                                   {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  const dcg::internal::Topology t = dcg::internal::analyze_topology(fin.V, fin.F);
  EXPECT_EQ(t.non_manifold_edges, 1);
  EXPECT_EQ(t.border_edges, 6);
  EXPECT_EQ(t.components, 1);
  // Two tetrahedra touching at one vertex: a pinched vertex, two components over edges.
  Mesh two = test::merged(tetrahedron(),
                          test::transformed(tetrahedron(), -Eigen::Matrix3d::Identity(), 1.0));
  two.F = (two.F.array() == 4).select(0, two.F.array()).matrix();  // share vertex 0 (= -0)
  const dcg::internal::Topology p = dcg::internal::analyze_topology(two.V, two.F);
  EXPECT_EQ(p.non_manifold_vertices, 1);
  EXPECT_EQ(p.non_manifold_edges, 0);
  EXPECT_EQ(p.border_edges, 0);
  EXPECT_EQ(p.components, 2);
  EXPECT_EQ(p.component[0], 0);
  EXPECT_EQ(p.component[4], 1);
}

TEST(MeshTopology, OrientOutwardFlipsInconsistentAndInwardFaces) {
  Mesh tet = tetrahedron();
  std::swap(tet.F(2, 1), tet.F(2, 2));  // one face the wrong way
  dcg::internal::Topology t = dcg::internal::analyze_topology(tet.V, tet.F);
  dcg::internal::Orientation o = dcg::internal::orient_outward(tet.V, tet.F, t);
  EXPECT_TRUE(o.orientable);
  EXPECT_TRUE(test::is_closed_oriented_manifold(tet));
  EXPECT_NEAR(signed_volume(tet), 1.0 / 6, 1e-15);
  // All faces inward: flipped as one component.
  tet.F.col(1).swap(tet.F.col(2));
  o = dcg::internal::orient_outward(tet.V, tet.F, dcg::internal::analyze_topology(tet.V, tet.F));
  EXPECT_NEAR(signed_volume(tet), 1.0 / 6, 1e-15);
  EXPECT_NEAR(o.enclosed_volume, 1.0 / 6, 1e-15);
  // A Moebius strip of 6 quads cannot be oriented.
  std::vector<Eigen::Vector3d> V;
  std::vector<std::array<int, 3>> F;
  const int n = 6;
  for (int i = 0; i < n; ++i) {
    const double u = 2 * M_PI * i / n;
    V.emplace_back(std::cos(u), std::sin(u), 0.3);   // 2i: top
    V.emplace_back(std::cos(u), std::sin(u), -0.3);  // 2i + 1: bottom
  }
  for (int i = 0; i < n; ++i) {
    const int a = 2 * i, b = 2 * i + 1;
    // The last quad joins top to bottom: the half twist.
    const int c = i + 1 < n ? 2 * i + 2 : 1, d = i + 1 < n ? 2 * i + 3 : 0;
    F.push_back({a, b, d});
    F.push_back({a, d, c});
  }
  Mesh strip = test::make_mesh(V, F);
  t = dcg::internal::analyze_topology(strip.V, strip.F);
  EXPECT_EQ(t.border_loops, 1);  // a Moebius strip has one boundary
  EXPECT_FALSE(dcg::internal::orient_outward(strip.V, strip.F, t).orientable);
}

TEST(MeshTopology, FoldedEdgesAndGenusOfOpenMeshes) {
  EXPECT_EQ(dcg::internal::folded_edges(test::icosphere(1)), 0);
  // Two copies of one triangle, back to back: closed, every edge folded flat.
  const Mesh pillow = test::make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 1}});
  EXPECT_EQ(dcg::internal::folded_edges(pillow), 3);
  // Holes do not change the genus: a torus without one face, a sphere without its cap.
  Mesh torus = test::torus(1.0, 0.3, 16, 8);
  torus.F.conservativeResize(torus.F.rows() - 1, 3);
  EXPECT_EQ(dcg::mesh_genus(torus), 1);
  EXPECT_EQ(dcg::internal::analyze_topology(torus.V, torus.F).border_loops, 1);
  EXPECT_EQ(dcg::mesh_genus(test::cut_above(test::icosphere(3), 0.8)), 0);
  EXPECT_EQ(dcg::mesh_genus(test::cut_above(test::torus(1.0, 0.3), 0.0)), 0);  // an annulus
}

TEST(CompactMesh, KeepsTheUsedVerticesInOrderOfFirstUse) {
  dcg::Vertices V(5, 3);
  for (int i = 0; i < 5; ++i) V.row(i) << i, 0, 0;
  std::vector<int> index;
  const Mesh m = dcg::internal::compact_mesh(V, {{4, 2, 0}, {0, 2, 3}}, &index);
  EXPECT_EQ(index, (std::vector<int>{2, -1, 1, 3, 0}));
  ASSERT_EQ(m.V.rows(), 4);
  EXPECT_EQ(m.V(0, 0), 4);
  EXPECT_EQ(m.V(3, 0), 3);
  EXPECT_EQ(m.F.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(m.F.row(1), Eigen::RowVector3i(2, 1, 3));
}

TEST(Decimate, FastReduceReachesItsGoalAndStaysAClosedManifold) {
  const Mesh sphere = test::icosphere(6);  // 81,920 faces
  std::vector<double> fractions;
  const Mesh m =
      dcg::internal::fast_reduce(sphere, 20000, [&](double f) { fractions.push_back(f); });
  // Each collapse removes two faces; it stops as soon as it is at the goal.
  EXPECT_LE(m.F.rows(), 20000);
  EXPECT_GE(m.F.rows(), 19998);
  EXPECT_EQ(m.V.rows(), m.F.rows() / 2 + 2);  // a closed genus-0 mesh, no vertex left unused
  EXPECT_TRUE(test::is_closed_oriented_manifold(m));
  EXPECT_EQ(dcg::mesh_genus(m), 0);
  EXPECT_GT(signed_volume(m), 0);
  // Midpoints of short edges stay near the sphere.
  const Eigen::VectorXd radius = m.V.rowwise().norm();
  EXPECT_GT(radius.minCoeff(), 0.99);
  EXPECT_LE(radius.maxCoeff(), 1.0 + 1e-12);
  EXPECT_FALSE(fractions.empty());
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  // A torus keeps its handle.
  const Mesh torus = test::torus(1.0, 0.35, 200, 100);  // 40,000 faces
  const Mesh t = dcg::internal::fast_reduce(torus, 5000);
  EXPECT_LE(t.F.rows(), 5000);
  EXPECT_TRUE(test::is_closed_oriented_manifold(t));
  EXPECT_EQ(dcg::mesh_genus(t), 1);
}

}  // namespace
