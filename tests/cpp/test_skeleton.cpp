// Stage 8 and the whole pipeline (dcg::Extractor::skeleton, method "dcg"): synthetic shapes with
// a known skeleton (torus, capsule, stars, sphere), the closed public meshes of ../shared/meshes
// (connected, every node and polyline point inside, every face labelled, cycles == genus, ends
// against MANIFEST.tsv), and the stability of ends and joints under rotation, scale, noise and
// another remeshing seed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "dcg/io.h"
#include "dcg/pipeline.h"
#include "manifest.h"
#include "shapes.h"
#include "skeleton_checks.h"

namespace {

using dcg::Mesh;
namespace test = dcg::test;

// Smaller working meshes than the defaults: the synthetic shapes are smooth.
dcg::Options fast_options() {
  dcg::Options o;
  o.prepare.target_faces = 5000;
  o.voronoi.samples = 1500;
  return o;
}

struct PipelineRun {
  dcg::Skeleton skeleton;
  test::SkeletonQuality quality;
};

PipelineRun run_pipeline(const Mesh& m, const dcg::Options& options = fast_options()) {
  dcg::Extractor extractor(m.V, m.F, options);
  PipelineRun r{extractor.skeleton(), {}};
  r.quality = test::skeleton_quality(m, r.skeleton);
  return r;
}

void expect_sound(const PipelineRun& r, const std::string& name) {
  const test::SkeletonQuality& q = r.quality;
  EXPECT_EQ(r.skeleton.method, "dcg") << name;
  EXPECT_EQ(q.components, 1) << name << ": " << test::describe(q);
  EXPECT_EQ(q.inside, q.points) << name << ": " << test::describe(q);
  EXPECT_EQ(q.unlabelled_faces, 0) << name << ": " << test::describe(q);
  EXPECT_EQ(q.kind_mismatches, 0) << name;
  EXPECT_EQ(q.polyline_mismatches, 0) << name;
  EXPECT_EQ(r.skeleton.polylines.size(), static_cast<size_t>(q.links)) << name;
  ASSERT_GE(r.skeleton.root, 0) << name;
  for (Eigen::Index i = 0; i < r.skeleton.radii.size(); ++i)
    EXPECT_GT(r.skeleton.radii[i], 0) << name;
  for (const auto& p : r.skeleton.polylines)
    EXPECT_GE(p.rows(), 5) << name << ": at least 3 inner points";
}

TEST(Skeleton, TorusHasNoEndAndExactlyOneCycle) {
  const PipelineRun r = run_pipeline(test::torus(1.0, 0.4));
  expect_sound(r, "torus");
  EXPECT_EQ(r.quality.ends, 0) << test::describe(r.quality);
  EXPECT_EQ(r.quality.cycles, 1) << test::describe(r.quality);
  EXPECT_EQ(r.skeleton.genus, 1);
  // The ring follows the middle of the tube: every point within half the tube's radius of the
  // core circle.
  for (const auto& p : r.skeleton.polylines) {
    for (Eigen::Index i = 0; i < p.rows(); ++i) {
      const double rho = std::hypot(p(i, 0), p(i, 1));
      EXPECT_LT(std::hypot(rho - 1.0, p(i, 2)), 0.2) << "polyline point " << p.row(i);
    }
  }
}

TEST(Skeleton, CapsuleHasTwoEndsAndNoJoint) {
  const PipelineRun r = run_pipeline(test::capsule(0.5, 2.0));
  expect_sound(r, "capsule");
  EXPECT_EQ(r.quality.ends, 2) << test::describe(r.quality);
  EXPECT_EQ(r.quality.joints, 0) << test::describe(r.quality);
  EXPECT_EQ(r.quality.cycles, 0);
  // A chain along the axis; the ends (stage-1 balls that see the tips, not shrunk) in the caps.
  for (Eigen::Index i = 0; i < r.skeleton.positions.rows(); ++i) {
    const Eigen::RowVector3d p = r.skeleton.positions.row(i);
    if (r.skeleton.kinds[i] == dcg::NodeKind::End) {
      EXPECT_GT(std::abs(p.z()), 0.8) << "end " << i;
    } else {
      EXPECT_LT(p.head<2>().norm(), 0.15) << "node " << i;
    }
  }
}

TEST(Skeleton, StarWithKArmsHasKEndsAndAJoint) {
  for (int k : {3, 4, 5, 6}) {
    const PipelineRun r = run_pipeline(test::star(k));
    expect_sound(r, "star" + std::to_string(k));
    EXPECT_EQ(r.quality.ends, k) << "star" << k << ": " << test::describe(r.quality);
    EXPECT_GE(r.quality.joints, 1) << "star" << k << ": " << test::describe(r.quality);
    EXPECT_EQ(r.quality.cycles, 0) << "star" << k;
    // Each end sits in its own arm's tip.
    const auto dirs = test::fibonacci_directions(k);
    std::vector<int> per_arm(k, 0);
    for (Eigen::Index i = 0; i < r.skeleton.positions.rows(); ++i) {
      if (r.skeleton.kinds[i] != dcg::NodeKind::End) continue;
      const Eigen::Vector3d p = r.skeleton.positions.row(i).transpose();
      int best = 0;
      for (int a = 1; a < k; ++a)
        if (p.dot(dirs[a]) > p.dot(dirs[best])) best = a;
      EXPECT_GT(p.dot(dirs[best]), 2.0) << "star" << k << " end " << i << " is not in an arm's tip";
      ++per_arm[best];
    }
    for (int a = 0; a < k; ++a) EXPECT_EQ(per_arm[a], 1) << "star" << k << " arm " << a;
    EXPECT_EQ(r.skeleton.kinds[r.skeleton.root], dcg::NodeKind::Joint) << "star" << k;
  }
}

TEST(Skeleton, MirroredInputStaysInside) {
  // x -> -x turns the triangles inside out: stage 0 orients its working mesh, and the final
  // inside check against the input's own surface must not trust the input's winding.
  Mesh m = test::capsule(0.35, 2.0);
  m.V.col(0) *= -1.5;
  m.V.rightCols(2) *= 1.5;
  const PipelineRun r = run_pipeline(m);
  expect_sound(r, "mirrored capsule");
  EXPECT_EQ(r.quality.ends, 2);
  for (Eigen::Index i = 0; i < r.skeleton.positions.rows(); ++i) {
    EXPECT_LT(r.skeleton.positions.row(i).head<2>().norm(), 0.2) << "node " << i;
  }
}

TEST(Skeleton, SphereKeepsASpine) {
  // No prong, no handle: the longest tree path, so that a blob still gets a bone.
  const PipelineRun r = run_pipeline(test::icosphere(3));
  expect_sound(r, "sphere");
  EXPECT_GE(r.quality.links, 1);
  EXPECT_EQ(r.quality.joints, 0);
  EXPECT_EQ(r.quality.cycles, 0);
}

TEST(Skeleton, StagesAreExposedAndTimed) {
  const Mesh m = test::capsule(0.5, 2.0);
  dcg::Extractor ex(m.V, m.F, fast_options());
  const dcg::FieldSamples& field = ex.domain_field();
  EXPECT_EQ(field.magnitude.size(), ex.domain_balls().balls.radii.size());
  const dcg::ConnectionPoints& cp = ex.connection_points();
  EXPECT_EQ(cp.shrunk.rows(), ex.domain_balls().balls.centers.rows());
  EXPECT_GT(cp.positions.rows(), 0);
  const dcg::DomainGraph& g = ex.domain_graph();
  EXPECT_EQ(g.face_labels.size(), ex.prepare().working.F.rows());
  const dcg::Remapped& rm = ex.remap();
  EXPECT_EQ(rm.polylines.size(), static_cast<size_t>(g.links.rows()));
  const dcg::Skeleton& s = ex.skeleton();
  EXPECT_EQ(s.method, "dcg");
  std::vector<std::string> names;
  for (const auto& t : s.timings) names.push_back(t.first);
  for (const char* stage :
       {"prepare", "voronoi_balls", "domain_balls", "prongs", "end_points", "force_field",
        "connection_points", "domain_graph", "remap", "skeleton", "total"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), stage), names.end()) << stage;
  }
  // The interim graph stays reachable as the explicit fallback.
  const dcg::Skeleton interim = ex.interim_skeleton();
  EXPECT_EQ(interim.method, "interim_graph");
  EXPECT_GT(interim.positions.rows(), 0);
}

TEST(Skeleton, EndsAndJointsSurviveRotationScaleAndNoise) {
  std::mt19937 rng(7);
  for (int k : {5}) {
    const Mesh base = test::star(k);
    const PipelineRun a = run_pipeline(base);
    const Mesh moved = test::with_noise(
        test::transformed(base, test::random_rotation(rng), 37.0, Eigen::Vector3d(1, 2, 3)), 0.003,
        rng);
    dcg::Options o = fast_options();
    o.seed = 3;
    const PipelineRun b = run_pipeline(moved, o);
    EXPECT_EQ(a.quality.ends, b.quality.ends) << "star" << k;
    EXPECT_EQ(a.quality.joints, b.quality.joints)
        << "star" << k << ": " << test::describe(a.quality) << " vs " << test::describe(b.quality);
  }
}

// --- the public meshes ---------------------------------------------------------------------------

TEST(SkeletonPublic, ClosedMeshesAreSoundAndMatchTheManifest) {
  const std::string dir = test::meshes_dir();
  const std::string manifest = dir + "/MANIFEST.tsv";
  if (!std::filesystem::exists(manifest)) GTEST_SKIP() << manifest << " not found (set DCG_MESHES)";
  // Rows whose ends are asserted exactly. horse: its sixth prong (ratio 0.979) is too shallow for
  // tau 0.85, and too loosely mirrored for a tail (spot's, ratio 0.973, is kept as one).
  const std::map<std::string, bool> exact = {
      {"octopus-low.obj", true},   {"hand.obj", true},      {"spot.obj", true},
      {"torus.off", true},         {"eight.off", true},     {"cow.off", true},
      {"armadillo-1k.off", true},  {"knight.off", true},    {"cheetah.off", true},
      {"elephant-cgal.off", true}, {"homer.obj", true},     {"dino.off", true},
      {"kitten.off", true},        {"fertility.off", true}, {"horse.ply", false},
      {"armadillo.obj", true}};
  // Stability (the list): ends and joints under a random rotation, a scale, 0.3% noise
  // and another remeshing seed: 'e' ends, 'j' joints, asserted on all six with this draw.
  // octopus-low needs stage 1 to drop balls whose center is outside (its noisy tentacles fold
  // through themselves, and such balls took their end points) and an end point for a folded
  // tip; knight the merging of directly linked junctions less than a ball apart; hand, knight
  // and cheetah the merging of junctions closer than the body is wide across them. Over
  // dcg_bench's stability seeds 1-36 the joints hold on hand, octopus-low and homer; not on
  // knight in 2 (hips and shoulders then farther apart than the torso is wide), cheetah in 2 (a
  // small junction of a short spur on a limb; front and hind junctions less than a ball apart,
  // directly linked) and armadillo-1k in 1 (a hip junction 1.04 chords from the torso's). The
  // ends, chosen before stage 6, hold but in 5 draws on octopus-low and 1 each on hand and
  // cheetah.
  const std::map<std::string, std::string> stable = {
      {"hand.obj", "ej"},  {"octopus-low.obj", "ej"}, {"knight.off", "ej"},
      {"homer.obj", "ej"}, {"cheetah.off", "ej"},     {"armadillo-1k.off", "ej"}};
  std::mt19937 rng(11);
  std::printf("\n%-18s %-34s %4s %6s %6s %5s %7s %7s %8s %7s\n", "mesh", "expected ends (MANIFEST)",
              "ends", "joints", "conn.", "links", "cycles", "genus", "inside%", "stable");
  int matches = 0, rows = 0;
  for (const test::ManifestRow& row : test::read_manifest(manifest)) {
    if (!row.closed) continue;
    const std::string path = dir + "/" + row.file;
    if (!std::filesystem::exists(path)) continue;
    const Mesh m = dcg::read_mesh(path);
    const PipelineRun r = run_pipeline(m, dcg::Options{});
    const test::SkeletonQuality& q = r.quality;
    std::string stability = "-";
    if (stable.count(row.file)) {
      const std::string& held = stable.at(row.file);
      const double scale = std::pow(10.0, std::uniform_real_distribution<double>(-2, 2)(rng));
      const Mesh moved = test::with_noise(
          test::transformed(m, test::random_rotation(rng), scale, Eigen::Vector3d(-1, 0.5, 2)),
          0.003, rng);
      dcg::Options o;
      o.seed = 5;
      const PipelineRun p = run_pipeline(moved, o);
      const bool same = p.quality.ends == q.ends && p.quality.joints == q.joints;
      stability =
          same ? "yes"
               : ("no:" + std::to_string(p.quality.ends) + "/" + std::to_string(p.quality.joints));
      if (held.find('e') != std::string::npos) {
        EXPECT_EQ(p.quality.ends, q.ends)
            << row.file << " perturbed: " << test::describe(p.quality);
      }
      if (held.find('j') != std::string::npos) {
        EXPECT_EQ(p.quality.joints, q.joints)
            << row.file << " perturbed: " << test::describe(p.quality);
      }
    }
    const bool match = q.ends >= row.low && q.ends <= row.high;
    std::printf("%-18s %-34.34s %4d %6d %6d %5d %7d %7d %8.1f %7s%s\n", row.file.c_str(),
                row.expected.c_str(), q.ends, q.joints, q.connections, q.links, q.cycles, row.genus,
                q.inside_percent(), stability.c_str(), match ? "" : "   <- ends differ");
    std::fflush(stdout);
    ++rows;
    matches += match;
    expect_sound(r, row.file);
    // No segment out through the surface either (the cow's ear at its own resolution had one
    // until stage 7 routed round it). Not asserted on the perturbed runs: a polyline there can
    // still cross a self-intersecting noise fold (1 segment in the kitten's draws).
    EXPECT_EQ(q.crossing_segments, 0) << row.file << ": " << test::describe(q);
    EXPECT_EQ(q.cycles, row.genus) << row.file;
    EXPECT_EQ(r.skeleton.genus, row.genus) << row.file;
    EXPECT_LE(q.ends, row.high + 2) << row.file;
    EXPECT_GE(q.ends, row.low - 2) << row.file;
    auto it = exact.find(row.file);
    if (it != exact.end() && it->second) {
      EXPECT_TRUE(match) << row.file << ": " << q.ends << " ends";
    }
  }
  std::printf("%d of %d closed meshes have the MANIFEST's ends\n", matches, rows);
  EXPECT_GE(2 * matches, rows) << "most meshes must match";
}

// Runs of `m` under a random rotation, a scale 10^U(-2,2), a move and 0.3% noise, with engine
// seeds 10, 11, ...: the same draws for every mesh.
std::vector<PipelineRun> perturbed_runs(const Mesh& m, int draws = 3) {
  std::mt19937 rng(3);
  std::vector<PipelineRun> runs;
  for (int draw = 0; draw < draws; ++draw) {
    const double scale = std::pow(10.0, std::uniform_real_distribution<double>(-2, 2)(rng));
    const Mesh moved = test::with_noise(
        test::transformed(m, test::random_rotation(rng), scale, Eigen::Vector3d(2, -1, 0.5)), 0.003,
        rng);
    dcg::Options o;
    o.seed = 10 + draw;
    runs.push_back(run_pipeline(moved, o));
  }
  return runs;
}

// perturbed_runs() of the public mesh `file`, each checked sound; none when the public meshes
// are not there (the caller skips).
std::vector<PipelineRun> sound_perturbed_public_runs(const std::string& file) {
  const std::string path = test::meshes_dir() + "/" + file;
  if (!std::filesystem::exists(path)) return {};
  std::vector<PipelineRun> runs = perturbed_runs(dcg::read_mesh(path));
  for (const PipelineRun& r : runs) expect_sound(r, file + " perturbed");
  return runs;
}

// The digit eight's prongs sit on its loops and are bumps, not limbs. They became ends (1-2)
// under any change of seed, rotation or noise until the bumps pass followed the loop's bend
// (domain_graph.cpp, arc_distance): three perturbed draws keep 0 ends and both loops.
TEST(SkeletonPublic, EightKeepsNoEndsWhenPerturbed) {
  const std::vector<PipelineRun> runs = sound_perturbed_public_runs("eight.off");
  if (runs.empty()) GTEST_SKIP() << "eight.off not found (set DCG_MESHES)";
  for (std::size_t draw = 0; draw < runs.size(); ++draw) {
    const PipelineRun& r = runs[draw];
    EXPECT_EQ(r.quality.ends, 0) << "draw " << draw << ": " << test::describe(r.quality);
    EXPECT_EQ(r.quality.cycles, 2) << "draw " << draw << ": " << test::describe(r.quality);
  }
}

// The kitten's tail is a thin handle. Its loop was lost in half of the perturbed draws while a
// link also had to see only backs of faces from every sample (a 0.3% noise fold in view failed
// that); links now only have to stay inside (domain_graph.cpp, link costs).
TEST(SkeletonPublic, KittenKeepsItsLoopWhenPerturbed) {
  const std::vector<PipelineRun> runs = sound_perturbed_public_runs("kitten.off");
  if (runs.empty()) GTEST_SKIP() << "kitten.off not found (set DCG_MESHES)";
  for (std::size_t draw = 0; draw < runs.size(); ++draw) {
    EXPECT_EQ(runs[draw].quality.cycles, 1)
        << "draw " << draw << ": " << test::describe(runs[draw].quality);
  }
}

}  // namespace
