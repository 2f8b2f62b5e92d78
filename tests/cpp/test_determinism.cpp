// Determinism: the same input and options give bit-identical results run after run and on 1 or
// 2 TBB threads (tbb::global_control caps the parallelism around dcg::Extractor). Checked
// stage by stage, so a failure names the first stage that differs.
#include <gtest/gtest.h>

#include <optional>
#include <random>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "dcg/io.h"
#include "dcg/pipeline.h"
#include "shapes.h"

namespace {

// Everything the stages up to the skeleton return, copied out of the extractor.
struct Run {
  dcg::Mesh working;
  dcg::Balls voronoi;
  dcg::Balls domain;
  Eigen::VectorXi prong_vertices;
  dcg::Skeleton skeleton;
};

Run run(const dcg::Mesh& mesh, const dcg::Options& options, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  dcg::Extractor ex(mesh.V, mesh.F, options);
  Run r;
  r.working = ex.prepare().working;
  const dcg::Balls& v = ex.voronoi_balls();
  r.voronoi = v;
  const auto& d = ex.domain_balls();
  r.domain = d.balls;
  r.prong_vertices = ex.prongs().prongs.vertices;
  r.skeleton = ex.skeleton();
  return r;
}

// Bit-identical: Eigen's operator== compares every coefficient exactly (NaN would differ).
void expect_identical(const Run& a, const Run& b, const std::string& what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(a.working.V, b.working.V) << "stage 0 (working mesh vertices)";
  ASSERT_EQ(a.working.F, b.working.F) << "stage 0 (working mesh faces)";
  ASSERT_EQ(a.voronoi.centers, b.voronoi.centers) << "stage 1";
  ASSERT_EQ(a.voronoi.radii, b.voronoi.radii) << "stage 1";
  ASSERT_EQ(a.domain.centers, b.domain.centers) << "stage 2";
  ASSERT_EQ(a.domain.radii, b.domain.radii) << "stage 2";
  ASSERT_EQ(a.prong_vertices, b.prong_vertices) << "stage 3";
  const dcg::Skeleton &s = a.skeleton, &t = b.skeleton;
  EXPECT_EQ(s.method, t.method);
  ASSERT_EQ(s.positions, t.positions) << "skeleton positions";
  EXPECT_EQ(s.kinds, t.kinds);
  EXPECT_EQ(s.radii, t.radii);
  EXPECT_EQ(s.significance, t.significance);
  EXPECT_EQ(s.links, t.links);
  ASSERT_EQ(s.polylines.size(), t.polylines.size());
  for (std::size_t l = 0; l < s.polylines.size(); ++l) EXPECT_EQ(s.polylines[l], t.polylines[l]);
  EXPECT_EQ(s.root, t.root);
  EXPECT_EQ(s.face_labels, t.face_labels);
}

void check_deterministic(const dcg::Mesh& mesh, const dcg::Options& options, bool twice = true) {
  const Run one = run(mesh, options, 1);
  if (twice) expect_identical(one, run(mesh, options, 1), "1 thread, run twice");
  const Run two = run(mesh, options, 2);
  expect_identical(one, two, "1 thread vs 2 threads");
  if (twice) expect_identical(two, run(mesh, options, 2), "2 threads, run twice");
}

dcg::Options fast_options() {
  dcg::Options options;
  options.prepare.target_faces = 5000;
  options.voronoi.samples = 1200;
  return options;
}

TEST(Determinism, SpotIsBitIdenticalOnOneAndTwoThreads) {
  check_deterministic(dcg::read_mesh(dcg::test::repo_file("data/spot.obj")), fast_options());
}

TEST(Determinism, StarWithOtherSeedIsBitIdentical) {
  dcg::Options options = fast_options();
  options.seed = 12345;
  check_deterministic(dcg::test::star(5), options, /*twice=*/false);
}

TEST(Determinism, RepairedOpenMeshIsBitIdentical) {
  // An open, noisy mesh goes through alpha wrapping (the repair path) and remeshing.
  std::mt19937 rng(7);
  const dcg::Mesh open = dcg::test::cut_above(
      dcg::test::with_noise(dcg::test::capsule(0.5, 2.0, 8, 24, 8), 0.002, rng), 1.0);
  dcg::Options options = fast_options();
  options.prepare.target_faces = 3000;
  check_deterministic(open, options, /*twice=*/false);  // the wrap is slow under the sanitizers
}

}  // namespace
