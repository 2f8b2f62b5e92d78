// dcg/prongs.h (stage 3): the sampled scale function against the exact O(n^2) sum, prong counts
// on synthetic stars, capsules, spheres and tori under rotation, scaling and noise,
// re-thresholding without new geodesics, and the prong counts on the public meshes of
// ../shared/meshes against MANIFEST.tsv.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "dcg/end_points.h"
#include "dcg/errors.h"
#include "dcg/io.h"
#include "dcg/prepare.h"
#include "dcg/prongs.h"
#include "dcg/surface_query.h"
#include "dcg/voronoi_balls.h"
#include "manifest.h"
#include "shapes.h"
#include "vertex_grid.h"

namespace {

using dcg::Mesh;
namespace test = dcg::test;

// Stages 0 and 3 with the default options (target_faces 20000, 128 sources, tau 0.85).
dcg::ProngFeatures prongs_of(const Mesh& m, double tau = 0.85) {
  const dcg::PreparedMesh pm = dcg::prepare_mesh(m.V, m.F);
  dcg::ProngOptions o;
  o.tau = tau;
  return dcg::compute_prongs(pm.working, o);
}

std::string ratios(const dcg::ProngFeatures& pf, int count = 10) {
  std::ostringstream s;
  for (const auto& p : pf.hierarchy.peaks()) {
    if (count-- == 0) break;
    s << " " << p.ratio << (p.global ? "(global)" : "");
  }
  return s.str();
}

TEST(ScaleFunction, SampledSumIsWithinTwoPercentOfTheExactSum) {
  // A uniform working mesh of about 2,000 vertices.
  dcg::PrepareOptions po;
  po.target_faces = 4000;
  const Mesh shape = test::star(4, 3.0, 0.4, 40);
  const dcg::PreparedMesh pm = dcg::prepare_mesh(shape.V, shape.F, po);
  const Mesh& m = pm.working;
  ASSERT_GT(m.V.rows(), 1500);
  ASSERT_LT(m.V.rows(), 3000);
  const dcg::ScaleFunction sampled = dcg::compute_scale_function(m);  // 128 sources
  EXPECT_EQ(sampled.sources.size(), 128);
  EXPECT_EQ(sampled.values.size(), m.V.rows());
  const Eigen::VectorXd exact = dcg::exact_scale_function(m, true);   // area-weighted
  const Eigen::VectorXd plain = dcg::exact_scale_function(m, false);  // the paper's sum / n
  const double error = ((sampled.values - exact).array().abs() / exact.array()).maxCoeff();
  const double error_plain = ((sampled.values - plain).array().abs() / plain.array()).maxCoeff();
  std::printf(
      "scale function, %d vertices, 128 sources: max relative error %.4f (area-weighted "
      "sum), %.4f (plain sum)\n",
      static_cast<int>(m.V.rows()), error, error_plain);
  EXPECT_LT(error, 0.02);
  EXPECT_LT(error_plain, 0.02);
  // The weights are the areas of the sources' cells: they cover the surface.
  double area = 0;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  EXPECT_NEAR(sampled.weights.sum(), area, 1e-9 * area);
  EXPECT_GT(sampled.weights.minCoeff(), 0);
  // geodesic_sources 0: the exact sum itself.
  dcg::ScaleFunctionOptions all;
  all.geodesic_sources = 0;
  EXPECT_LT((dcg::compute_scale_function(m, all).values - exact).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(ScaleFunction, EdgeGeodesicsAndDeterminism) {
  const Mesh sphere = test::icosphere(4);
  int north = 0, south = 0;
  for (Eigen::Index v = 0; v < sphere.V.rows(); ++v) {
    if (sphere.V(v, 2) > sphere.V(north, 2)) north = static_cast<int>(v);
    if (sphere.V(v, 2) < sphere.V(south, 2)) south = static_cast<int>(v);
  }
  const Eigen::VectorXd d = dcg::edge_geodesics(sphere, north);
  EXPECT_EQ(d[north], 0);
  // Edges are chords of the unit sphere: a little shorter than arcs, zig-zags a little longer.
  EXPECT_GT(d[south], 0.97 * M_PI);
  EXPECT_LT(d[south], 1.1 * M_PI);
  const dcg::ScaleFunction a = dcg::compute_scale_function(sphere),
                           b = dcg::compute_scale_function(sphere);
  EXPECT_EQ(a.values, b.values);
  EXPECT_EQ(a.sources, b.sources);
  // Fewer sources than a chunk of the parallel sum (2 and 3 against at least 4): the mean
  // distance on a unit sphere lies between 0 (a source itself) and pi.
  for (const int count : {1, 2, 3}) {
    dcg::ScaleFunctionOptions few;
    few.geodesic_sources = count;
    const dcg::ScaleFunction f = dcg::compute_scale_function(sphere, few);
    EXPECT_EQ(f.sources.size(), count);
    EXPECT_TRUE(f.values.allFinite()) << count;
    EXPECT_GE(f.values.minCoeff(), 0) << count;
    EXPECT_LE(f.values.maxCoeff(), 1.1 * M_PI) << count;
  }
  dcg::ScaleFunctionOptions bad;
  bad.geodesic_sources = -1;
  EXPECT_THROW(dcg::compute_scale_function(sphere, bad), dcg::InputError);
  EXPECT_THROW(dcg::ProngHierarchy(sphere, Eigen::VectorXd::Zero(3)), dcg::InputError);
}

// Shapes with a known number of prongs, each also rotated, scaled and perturbed (0.3% noise).
struct Shape {
  std::string name;
  Mesh mesh;
  int prongs;
};

std::vector<Shape> known_shapes() {
  std::vector<Shape> shapes;
  for (int k = 3; k <= 8; ++k) shapes.push_back({"star" + std::to_string(k), test::star(k), k});
  shapes.push_back({"capsule", test::capsule(0.5, 2.0), 2});
  shapes.push_back({"sphere", test::icosphere(4), 0});
  shapes.push_back({"torus", test::torus(1.0, 0.4), 0});
  return shapes;
}

TEST(Prongs, KnownShapesGiveTheirProngCountUnderRotationScaleAndNoise) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> log_scale(-3.0, 3.0);
  for (const Shape& shape : known_shapes()) {
    for (int variant = 0; variant < 3; ++variant) {
      Mesh m = shape.mesh;
      std::string how = "as built";
      if (variant > 0) {
        const double scale = std::pow(10.0, log_scale(rng));
        m = test::with_noise(test::transformed(m, test::random_rotation(rng), scale,
                                               Eigen::Vector3d(scale, -2 * scale, 0.5)),
                             0.003, rng);
        how = "rotated, scaled by " + std::to_string(scale) + ", 0.3% noise";
      }
      const dcg::ProngFeatures pf = prongs_of(m);
      EXPECT_EQ(pf.prongs.vertices.size(), shape.prongs)
          << shape.name << " (" << how << "), ratios:" << ratios(pf);
      for (Eigen::Index i = 0; i < pf.prongs.significance.size(); ++i) {
        EXPECT_LT(pf.prongs.significance[i], 0.85);
        if (i > 0) {
          EXPECT_GE(pf.prongs.significance[i], pf.prongs.significance[i - 1]);
        }
      }
    }
  }
}

TEST(Prongs, StarProngsSitAtTheArmTips) {
  const int k = 5;
  const double length = 3.0;
  const Mesh m = test::star(k, length);
  const dcg::PreparedMesh pm = dcg::prepare_mesh(m.V, m.F);
  const dcg::ProngFeatures pf = dcg::compute_prongs(pm.working);
  ASSERT_EQ(pf.prongs.vertices.size(), k);
  const auto tips = test::fibonacci_directions(k);
  std::vector<char> used(k, 0);
  for (Eigen::Index i = 0; i < k; ++i) {
    const Eigen::Vector3d p = pm.to_input(pf.prongs.positions.row(i)).transpose();
    int best = 0;
    for (int t = 1; t < k; ++t)
      if ((p - length * tips[t]).norm() < (p - length * tips[best]).norm()) best = t;
    EXPECT_LT((p - length * tips[best]).norm(), 0.5) << "prong " << i;
    EXPECT_FALSE(used[best]) << "two prongs on arm " << best;
    used[best] = 1;
  }
}

TEST(Prongs, RethresholdingNeedsNoNewGeodesicsAndMatchesAFreshRun) {
  const Mesh m = test::star(6, 3.0, 0.35);
  const dcg::PreparedMesh pm = dcg::prepare_mesh(m.V, m.F);
  const dcg::ProngFeatures pf = dcg::compute_prongs(pm.working);
  Eigen::Index previous = 0;
  for (double tau : {0.3, 0.5, 0.6, 0.7, 0.85, 0.95, 0.99, 1.0}) {
    const dcg::Prongs again = pf.hierarchy.prongs(tau);
    dcg::ProngOptions o;
    o.tau = tau;
    const dcg::Prongs fresh = dcg::compute_prongs(pm.working, o).prongs;
    EXPECT_EQ(again.vertices, fresh.vertices) << "tau " << tau;
    EXPECT_EQ(again.significance, fresh.significance) << "tau " << tau;
    EXPECT_GE(again.vertices.size(), previous) << "a looser tau never loses a prong";
    previous = again.vertices.size();
  }
  EXPECT_EQ(pf.hierarchy.prongs(0.3).vertices.size(), 0);
  EXPECT_THROW(pf.hierarchy.prongs(0.0), dcg::InputError);
  EXPECT_THROW(pf.hierarchy.prongs(1.5), dcg::InputError);
  // Every peak of the hierarchy: sorted by ratio, ratios in (0, 1], exactly one global.
  int global = 0;
  const auto& peaks = pf.hierarchy.peaks();
  for (size_t i = 0; i < peaks.size(); ++i) {
    EXPECT_GT(peaks[i].ratio, 0);
    EXPECT_LE(peaks[i].ratio, 1);
    EXPECT_NEAR(peaks[i].ratio, peaks[i].valley / peaks[i].value, 1e-12);
    if (i > 0) {
      EXPECT_GE(peaks[i].ratio, peaks[i - 1].ratio);
    }
    global += peaks[i].global;
  }
  EXPECT_EQ(global, 1);
  EXPECT_TRUE(pf.hierarchy.global_cap_is_disk(0.85));
}

TEST(Prongs, EndPointsAreDistinctBallsThatSeeThePeaks) {
  const Mesh m = test::star(6, 3.0, 0.35);
  const dcg::PreparedMesh pm = dcg::prepare_mesh(m.V, m.F);
  const dcg::ProngFeatures pf = dcg::compute_prongs(pm.working);
  dcg::VoronoiBallsOptions vo;
  vo.samples = 2000;
  const dcg::Balls balls = dcg::compute_voronoi_balls(pm.working, *pm.query, vo);
  const double min_radius = 0.001;
  const dcg::EndPoints ends = dcg::find_end_points(pf.prongs, balls, *pm.query, min_radius);
  ASSERT_EQ(ends.ball.size(), 6);
  std::vector<int> seen;
  for (Eigen::Index p = 0; p < 6; ++p) {
    const int b = ends.ball[p];
    ASSERT_GE(b, 0) << "prong " << p << " has no end point";
    EXPECT_EQ(std::count(seen.begin(), seen.end(), b), 0) << "shared end point";
    seen.push_back(b);
    EXPECT_GE(ends.radii[p], min_radius);
    EXPECT_EQ(ends.centers.row(p), balls.centers.row(b));
    const Eigen::Vector3d c = ends.centers.row(p).transpose(),
                          peak = pf.prongs.positions.row(p).transpose();
    EXPECT_TRUE(pm.query->inside(c));
    // Near the tip (the arm radius is 0.35 of about 9.1 units of diagonal), and it sees the peak.
    EXPECT_LT((c - peak).norm(), 0.35 / 9.1) << "prong " << p;
    EXPECT_GE(pm.query->ray_hit(c, peak - c), (c - peak).norm() * 0.999);
    // No closer ball of the same size class sees the peak unless another prong took it.
    for (Eigen::Index q = 0; q < balls.radii.size(); ++q) {
      if (balls.radii[q] < min_radius ||
          (balls.centers.row(q).transpose() - peak).norm() >= (c - peak).norm())
        continue;
      const Eigen::Vector3d cq = balls.centers.row(q).transpose();
      const bool sees = pm.query->ray_hit(cq, peak - cq) >= (cq - peak).norm() * 0.999;
      EXPECT_TRUE(!sees || std::count(seen.begin(), seen.end(), static_cast<int>(q)) > 0)
          << "ball " << q << " is closer and sees prong " << p;
    }
  }
}

// --- the public meshes ---------------------------------------------------------------------------

TEST(Prongs, PublicMeshesMatchTheManifest) {
  const std::string dir = test::meshes_dir();
  const std::string manifest = dir + "/MANIFEST.tsv";
  if (!std::filesystem::exists(manifest)) GTEST_SKIP() << manifest << " not found (set DCG_MESHES)";
  // The rows that hold at tau 0.85 (the others, within 2, are reported): spot's 6 with its second
  // hind leg as a mirror twin and its tail as a tail; the eight's 2 ends sit on its loops (stage 6
  // turns them into connection points); the horse's sixth prong (ratio 0.979) is too shallow, and
  // its halves mirror each other too loosely for a tail.
  const std::map<std::string, bool> exact = {
      {"octopus-low.obj", true},   {"hand.obj", true},      {"spot.obj", true},
      {"torus.off", true},         {"eight.off", false},    {"cow.off", true},
      {"armadillo-1k.off", true},  {"knight.off", true},    {"cheetah.off", true},
      {"elephant-cgal.off", true}, {"homer.obj", true},     {"dino.off", true},
      {"kitten.off", true},        {"fertility.off", true}, {"horse.ply", false},
      {"armadillo.obj", true}};
  std::printf("\n%-20s %-44s %6s  %s\n", "mesh", "expected end points (MANIFEST)", "found",
              "ratios of the strongest peaks");
  int matches = 0, rows = 0;
  for (const test::ManifestRow& r : test::read_manifest(manifest)) {
    if (!r.closed) continue;
    const std::string path = dir + "/" + r.file;
    if (!std::filesystem::exists(path)) continue;
    const Mesh m = dcg::read_mesh(path);
    const dcg::ProngFeatures pf = prongs_of(m);
    const int found = static_cast<int>(pf.prongs.vertices.size());
    const bool match = found >= r.low && found <= r.high;
    std::printf("%-20s %-44s %6d  %s%s\n", r.file.c_str(), r.expected.c_str(), found,
                ratios(pf, 8).c_str(), match ? "" : "   <- differs");
    ++rows;
    matches += match;
    EXPECT_LE(found, r.high + 2) << r.file;
    EXPECT_GE(found, r.low - 2) << r.file;
    auto it = exact.find(r.file);
    if (it != exact.end() && it->second) {
      EXPECT_TRUE(match) << r.file << ": found " << found;
    }
  }
  std::printf("%d of %d closed meshes match the MANIFEST at tau 0.85\n", matches, rows);
  EXPECT_GE(2 * matches, rows) << "most meshes must match";
}

// Mannequiny's hands have four fingers; its body is about 30 finger lengths tall, so their
// ratios (0.94-0.97) lie past tau, beside spot's horns and ears (0.94-0.96) and cow's lone horn.
// Two long fingers and a thumb of each hand are found as fingers (the fourth finger ends at the
// hand's own end); no other public mesh has a hand of such peaks.
TEST(Prongs, AHandsFingersAreProngsTooAndHornsAreNot) {
  const std::string dir = test::meshes_dir();
  if (!std::filesystem::exists(dir + "/rigged/Mannequiny.obj")) GTEST_SKIP() << dir;
  const dcg::ProngFeatures body = prongs_of(dcg::read_mesh(dir + "/rigged/Mannequiny.obj"));
  ASSERT_EQ(body.prongs.fingers, 6) << ratios(body, 20);
  const Eigen::Index n = body.prongs.vertices.size();
  int at_hands = 0;  // the hands are the farthest from the mirror plane x = 0
  for (Eigen::Index i = 0; i < n; ++i) {
    EXPECT_LT(body.prongs.significance[i], dcg::ProngHierarchy::kFingerRatio);
    at_hands += body.prongs.significance[i] >= 0.85 && std::abs(body.prongs.positions(i, 0)) > 0.25;
  }
  EXPECT_EQ(at_hands, 6) << "every finger at a hand";
  for (const char* name : {"spot.obj", "cow.off", "armadillo.obj", "rigged/Q_Dragon.obj"}) {
    if (!std::filesystem::exists(dir + "/" + name)) continue;
    const dcg::ProngFeatures other = prongs_of(dcg::read_mesh(dir + "/" + name));
    EXPECT_EQ(other.prongs.fingers, 0) << name << ratios(other, 20);
  }
}

// A noise of 1e-5 of the diagonal must not change which of Mannequiny's peaks are fingers. Two
// fingers side by side meet at a saddle; the higher one's region, cut at its own valley, held
// both down to the knuckles, so its aspect (about 5 alone) fell below kFingerAspect whenever the
// noise made the other one the lower, and the hand lost its fingers: draw 9 of the 40 drawn
// (3 fingers). Now the region is cut at the other finger's valley (sibling_levels). (Draw 15
// still loses one thumb, before and after: its own valley moves with the geodesic sources.)
TEST(Prongs, AHandKeepsItsFingersUnderATinyNoise) {
  const std::string dir = test::meshes_dir();
  if (!std::filesystem::exists(dir + "/rigged/Mannequiny.obj")) GTEST_SKIP() << dir;
  const Mesh body = dcg::read_mesh(dir + "/rigged/Mannequiny.obj");
  for (unsigned seed : {1u, 2u, 3u, 9u}) {
    std::mt19937 rng(seed);
    const dcg::ProngFeatures pf = prongs_of(test::with_noise(body, 1e-5, rng));
    EXPECT_EQ(pf.prongs.fingers, 6) << "draw " << seed << ratios(pf, 20);
  }
}

// Spot's hind legs stand close: the second meets the first at the crotch (ratio 0.859, past tau)
// and is kept as its mirror twin; armadillo's second ear mirrors the first (ratio 0.861) but is a
// feature on the head, 0.26 of the mean geodesic distance long (kTwinLength 0.35), not a limb.
TEST(Prongs, AMirrorTwinOfAProngIsAProngTooWhenItIsALimb) {
  const std::string dir = test::meshes_dir();
  if (!std::filesystem::exists(dir + "/spot.obj")) GTEST_SKIP() << dir << " has no spot.obj";
  const dcg::ProngFeatures spot = prongs_of(dcg::read_mesh(dir + "/spot.obj"));
  ASSERT_EQ(spot.prongs.mirror_twins, 1) << ratios(spot);
  const Eigen::Index n = spot.prongs.vertices.size();
  ASSERT_EQ(n, 6) << "4 legs, the head and the tail";
  // The twin: the one past tau below kTwinRatio (the head's end and the tail past it too).
  Eigen::Index t = 0;
  while (t < n && spot.prongs.significance[t] < 0.85) ++t;
  ASSERT_LT(spot.prongs.significance[t], dcg::ProngHierarchy::kTwinRatio) << ratios(spot);
  ASSERT_LT(t, n) << ratios(spot);
  EXPECT_LT(spot.prongs.significance[t], dcg::ProngHierarchy::kTwinRatio);
  // Spot is symmetric about x = 0 (normalized units: the working mesh's): the twin's peak is the
  // mirror image of a prong's (a leg's), not another bump.
  const Eigen::RowVector3d twin = spot.prongs.positions.row(t);
  const Eigen::RowVector3d mirrored(-twin.x(), twin.y(), twin.z());
  double nearest = 1e9;
  for (Eigen::Index i = 0; i < n; ++i)
    if (i != t) nearest = std::min(nearest, (spot.prongs.positions.row(i) - mirrored).norm());
  EXPECT_LT(nearest, 0.02) << "the twin mirrors a leg";
  EXPECT_LT(twin.y(), -0.3) << "a hoof, at the bottom";

  if (!std::filesystem::exists(dir + "/armadillo.obj")) return;
  const dcg::ProngFeatures armadillo = prongs_of(dcg::read_mesh(dir + "/armadillo.obj"));
  EXPECT_EQ(armadillo.prongs.mirror_twins, 0) << ratios(armadillo);
  EXPECT_EQ(armadillo.prongs.vertices.size(), 6);
  // The ear it leaves out is a twin in all but length: same value, same plane, past tau (its
  // partner, the other ear, is no prong: the head's end moved from it to the snout).
  bool ear = false;
  for (const dcg::Peak& q : armadillo.hierarchy.peaks())
    ear |= q.ratio >= 0.85 && q.ratio < dcg::ProngHierarchy::kTwinRatio && !q.global;
  EXPECT_TRUE(ear) << "a candidate twin was there to be refused";
  EXPECT_EQ(armadillo.prongs.midline, 1) << ratios(armadillo);
}

// Q_Goblin's ears mirror each other, the head's end moves from one of them to the middle. The
// other ear, a candidate twin, is measured from the crotch where the two ears' regions meet: a
// vertex 0.07 from one ear and 0.15 from the other (kTwinLength: 0.12), and which ear was the
// candidate a noise of 1e-5 of the diagonal decided (the far one, so that both ears became
// ends, in 8 of draws 1-59 here, 11, 22 and 23 among them). Both ears are measured now.
TEST(Prongs, MirrorTwinsAreMeasuredFromBothSidesOfTheirCrotch) {
  const std::string dir = test::meshes_dir();
  if (!std::filesystem::exists(dir + "/rigged/Q_Goblin.obj")) GTEST_SKIP() << dir;
  const Mesh goblin = dcg::read_mesh(dir + "/rigged/Q_Goblin.obj");
  for (unsigned seed : {0u, 11u, 22u, 23u}) {
    std::mt19937 rng(seed);
    const dcg::ProngFeatures pf =
        prongs_of(seed == 0 ? goblin : test::with_noise(goblin, 1e-5, rng));
    EXPECT_EQ(pf.prongs.mirror_twins, 0) << "draw " << seed << ratios(pf);
    EXPECT_EQ(pf.prongs.midline, 1) << "draw " << seed << ratios(pf);
    EXPECT_EQ(pf.prongs.vertices.size(), 5) << "draw " << seed << ratios(pf);
  }
}

// Spot's and the cow's highest point is a horn: the head's end moves to the muzzle, on the
// mirror plane, and nothing else moves; a shape whose prongs are not one of a pair keeps them.
TEST(Prongs, AHeadEndOnOneOfTwoHornsMovesToTheMuzzle) {
  const std::string dir = test::meshes_dir();
  if (!std::filesystem::exists(dir + "/spot.obj")) GTEST_SKIP() << dir << " has no spot.obj";
  const dcg::ProngFeatures spot = prongs_of(dcg::read_mesh(dir + "/spot.obj"));
  EXPECT_EQ(spot.prongs.midline, 1) << ratios(spot);
  int legs = 0, heads = 0;
  for (Eigen::Index i = 0; i < spot.prongs.vertices.size(); ++i) {
    const Eigen::RowVector3d p = spot.prongs.positions.row(i);  // x = 0 mirrors it, y up
    if (p.y() < -0.3 || p.z() > 0.3) {  // the legs, and the tail at the back
      legs += p.y() < -0.3;
      continue;
    }
    ++heads;
    EXPECT_LT(std::abs(p.x()), 0.01) << "on the mirror plane, not on a horn: " << p;
    EXPECT_LT(p.z(), -0.2) << "the muzzle, at the front: " << p;
  }
  EXPECT_EQ(legs, 4);
  EXPECT_EQ(heads, 1);

  const Mesh hand = dcg::read_mesh(dir + "/hand.obj");  // five fingers side by side, no pair
  EXPECT_EQ(prongs_of(hand).prongs.midline, 0);
  if (!std::filesystem::exists(dir + "/cow.off")) return;
  const dcg::ProngFeatures cow = prongs_of(dcg::read_mesh(dir + "/cow.off"));
  EXPECT_EQ(cow.prongs.midline, 1) << ratios(cow);
  EXPECT_EQ(cow.prongs.vertices.size(), 6) << "4 legs, tail, head";
}

// Spot's tail is a flap at the rump (ratio 0.973), weaker than the middle of fertility.off's
// base's front edge (0.966): it is kept for standing on the mirror plane of its hind legs and for
// being pointed. Homer's nose is as pointed and on his plane, but it ends in the head's region,
// which has no twin; cow.off's teats are pointed and between its legs, but off the plane; the
// horse's tail stub is on a scan whose halves mirror each other too loosely.
TEST(Prongs, ATailIsAPointedTipOnThePlaneBetweenAPairOfLimbs) {
  const std::string dir = test::meshes_dir();
  if (!std::filesystem::exists(dir + "/spot.obj")) GTEST_SKIP() << dir << " has no spot.obj";
  const dcg::ProngFeatures spot = prongs_of(dcg::read_mesh(dir + "/spot.obj"));
  ASSERT_EQ(spot.prongs.tails, 1) << ratios(spot);
  Eigen::Index tail = -1;
  for (Eigen::Index i = 0; i < spot.prongs.vertices.size(); ++i)
    if (spot.prongs.significance[i] > dcg::ProngHierarchy::kTwinRatio) tail = i;
  ASSERT_GE(tail, 0) << ratios(spot);
  const Eigen::RowVector3d p = spot.prongs.positions.row(tail);  // x = 0 mirrors it, y up
  EXPECT_LT(std::abs(p.x()), 0.01) << "on the mirror plane: " << p;
  EXPECT_GT(p.z(), 0.3) << "at the back, the farthest from the muzzle: " << p;
  EXPECT_GT(p.y(), -0.2) << "at the rump, not at a hoof: " << p;
  EXPECT_LT(spot.prongs.significance[tail], dcg::ProngHierarchy::kMidlineRatio);
  for (const char* name : {"fertility.off", "homer.obj", "cow.off", "horse.ply", "hand.obj"}) {
    if (!std::filesystem::exists(dir + "/" + name)) continue;
    const dcg::ProngFeatures other = prongs_of(dcg::read_mesh(dir + "/" + name));
    EXPECT_EQ(other.prongs.tails, 0) << name << ratios(other, 20);
  }
}

// The mirror tests' nearest-vertex grid finds what a scan of every vertex finds, for points
// inside and far outside the box, on a solid cloud and on a flat one (no volume).
TEST(Prongs, TheVertexGridFindsTheNearestVertex) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (const double flat : {1.0, 0.0}) {
    dcg::Points V(500, 3);
    for (Eigen::Index i = 0; i < V.rows(); ++i)
      V.row(i) << unit(rng), 0.3 * unit(rng), flat * unit(rng);
    const dcg::internal::VertexGrid grid(V);
    for (int q = 0; q < 300; ++q) {
      const Eigen::Vector3d p(3 * unit(rng), 3 * unit(rng), 3 * unit(rng));
      const double scan = (V.rowwise() - p.transpose()).rowwise().norm().minCoeff();
      ASSERT_DOUBLE_EQ(grid.nearest(p), scan) << p.transpose() << " flat " << (flat == 0);
    }
  }
  EXPECT_TRUE(
      std::isinf(dcg::internal::VertexGrid(dcg::Points(0, 3)).nearest(Eigen::Vector3d::Zero())));
}

}  // namespace
