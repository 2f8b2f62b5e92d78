// dcg/pipeline.h: the option table and validation, and the whole pipeline on shipped meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "dcg/errors.h"
#include "dcg/io.h"
#include "dcg/pipeline.h"
#include "dcg/surface_query.h"
#include "shapes.h"

namespace {

using dcg::test::repo_file;

TEST(Options, DefaultsAreValidAndMatchTheDesign) {
  dcg::Options options;
  EXPECT_NO_THROW(options.validate());
  EXPECT_DOUBLE_EQ(dcg::get_numeric_option(options, "tau"), 0.85);
  EXPECT_DOUBLE_EQ(dcg::get_numeric_option(options, "samples"), 4000);
  EXPECT_DOUBLE_EQ(dcg::get_numeric_option(options, "min_gap"), 0.005);
  std::set<std::string> names;
  for (const auto& spec : dcg::option_specs()) {
    EXPECT_TRUE(names.insert(spec.name).second) << "duplicate option " << spec.name;
    EXPECT_FALSE(spec.description.empty()) << spec.name;
    if (spec.kind == dcg::OptionSpec::Kind::Choice) continue;
    EXPECT_LE(spec.minimum, dcg::get_numeric_option(options, spec.name)) << spec.name;
    EXPECT_GE(spec.maximum, dcg::get_numeric_option(options, spec.name)) << spec.name;
  }
}

TEST(Options, OutOfRangeUnknownAndFractionalValuesAreRejected) {
  dcg::Options options;
  EXPECT_THROW(dcg::set_numeric_option(options, "tau", 1.5), dcg::InputError);
  EXPECT_THROW(dcg::set_numeric_option(options, "tau", std::nan("")), dcg::InputError);
  EXPECT_THROW(dcg::set_numeric_option(options, "samples", 100.5), dcg::InputError);
  EXPECT_THROW(dcg::set_numeric_option(options, "no_such_option", 1), dcg::InputError);
  EXPECT_THROW(dcg::parse_repair("sometimes"), dcg::InputError);
  dcg::set_numeric_option(options, "samples", 500);
  EXPECT_EQ(options.voronoi.samples, 500);
  options.field.rays = 1;  // set behind the table's back
  EXPECT_THROW(options.validate(), dcg::InputError);
}

TEST(Pipeline, SpotGivesAConnectedTreeInsideTheShape) {
  const dcg::Mesh mesh = dcg::read_mesh(repo_file("data/spot.obj"));
  dcg::Options options;
  options.prepare.target_faces = 6000;
  options.voronoi.samples = 1500;
  std::vector<std::string> stages;
  dcg::Extractor extractor(mesh.V, mesh.F, options, [&](const std::string& stage, double) {
    stages.push_back(stage);
    return true;
  });
  const dcg::Skeleton& s = extractor.skeleton();
  const int n = static_cast<int>(s.positions.rows());
  ASSERT_GT(n, 1);
  ASSERT_EQ(s.kinds.size(), static_cast<size_t>(n));
  EXPECT_EQ(s.links.rows(), static_cast<Eigen::Index>(s.polylines.size()));
  EXPECT_EQ(s.links.rows(), n - 1) << "a genus-0 interim graph is a tree";
  EXPECT_GE(s.root, 0);
  EXPECT_EQ(s.face_labels.size(), mesh.F.rows());
  EXPECT_EQ(s.genus, 0);
  EXPECT_FALSE(stages.empty());
  EXPECT_EQ(stages.back(), "done");
  ASSERT_FALSE(s.timings.empty());
  EXPECT_EQ(s.timings.back().first, "total");

  // Every node and polyline point is inside the input mesh (a closed surface).
  dcg::SurfaceQuery inside(mesh);
  for (int i = 0; i < n; ++i) {
    EXPECT_TRUE(inside.inside(s.positions.row(i).transpose())) << "node " << i;
    EXPECT_GT(s.radii[i], 0);
  }
  for (size_t l = 0; l < s.polylines.size(); ++l) {
    const dcg::Points& p = s.polylines[l];
    ASSERT_GE(p.rows(), 2);
    EXPECT_TRUE(p.row(0).isApprox(s.positions.row(s.links(l, 0))));
    EXPECT_TRUE(p.row(p.rows() - 1).isApprox(s.positions.row(s.links(l, 1))));
  }
  // Each node's kind agrees with its degree.
  std::vector<int> degree(n, 0);
  for (Eigen::Index l = 0; l < s.links.rows(); ++l) {
    ++degree[s.links(l, 0)];
    ++degree[s.links(l, 1)];
  }
  for (int i = 0; i < n; ++i) {
    const dcg::NodeKind expected = degree[i] == 1   ? dcg::NodeKind::End
                                   : degree[i] >= 3 ? dcg::NodeKind::Joint
                                                    : dcg::NodeKind::Connection;
    EXPECT_EQ(s.kinds[i], expected) << "node " << i << " degree " << degree[i];
  }
}

// A star of separate closed parts (a ball with four capsule arms pushed into it, and a small
// detached "eye" beside it), as game characters come: four ends, one at each arm, and every node
// and polyline point inside one of the parts (the input's parity says little where parts
// overlap, so each part is asked on its own).
TEST(Pipeline, MultiPartStarGetsItsEndsInsideItsParts) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  std::vector<dcg::Mesh> parts = {dcg::test::icosphere(3)};
  const dcg::Mesh arm = dcg::test::capsule(0.3, 2.0);  // along z
  Eigen::Matrix3d to_x, to_y;
  to_x << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  to_y << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  parts.push_back(dcg::test::transformed(arm, to_x, 1.0, {1.8, 0, 0}));
  parts.push_back(dcg::test::transformed(arm, to_x, 1.0, {-1.8, 0, 0}));
  parts.push_back(dcg::test::transformed(arm, to_y, 1.0, {0, 1.8, 0}));
  parts.push_back(dcg::test::transformed(arm, to_y, 1.0, {0, -1.8, 0}));
  parts.push_back(dcg::test::transformed(dcg::test::icosphere(2), I, 0.15, {0.6, 0.6, 1.2}));
  dcg::Mesh mesh = parts[0];
  for (size_t i = 1; i < parts.size(); ++i) mesh = dcg::test::merged(mesh, parts[i]);
  dcg::Options options;
  options.prepare.target_faces = 8000;
  const dcg::Skeleton s = dcg::extract_skeleton(mesh.V, mesh.F, options);
  EXPECT_TRUE(s.repaired);
  int ends = 0;
  for (dcg::NodeKind k : s.kinds) ends += k == dcg::NodeKind::End;
  EXPECT_EQ(ends, 4);
  std::vector<std::unique_ptr<dcg::SurfaceQuery>> queries;
  for (const dcg::Mesh& part : parts) queries.push_back(std::make_unique<dcg::SurfaceQuery>(part));
  const auto in_a_part = [&](const Eigen::Vector3d& p) {
    return std::any_of(queries.begin(), queries.end(), [&](const auto& q) { return q->inside(p); });
  };
  for (Eigen::Index i = 0; i < s.positions.rows(); ++i) {
    EXPECT_TRUE(in_a_part(s.positions.row(i).transpose())) << "node " << i;
  }
  for (size_t l = 0; l < s.polylines.size(); ++l) {
    for (Eigen::Index i = 0; i < s.polylines[l].rows(); ++i) {
      EXPECT_TRUE(in_a_part(s.polylines[l].row(i).transpose())) << "link " << l << " point " << i;
    }
  }
}

// The polylines' radii: the distance from each point to the surface, in the input's units (a
// capsule of radius 3, 26 long, far from the origin): about 3 along its cylinder.
TEST(Pipeline, PolylineRadiiAreEachPointsDistanceToTheSurface) {
  const dcg::Mesh mesh = dcg::test::transformed(dcg::test::capsule(0.3, 2.0),
                                                Eigen::Matrix3d::Identity(), 10.0, {50, 0, 0});
  const dcg::Skeleton s = dcg::extract_skeleton(mesh.V, mesh.F);
  ASSERT_EQ(s.polyline_radii.size(), s.polylines.size());
  const dcg::SurfaceQuery surface(mesh);
  int along = 0;
  for (std::size_t l = 0; l < s.polylines.size(); ++l) {
    ASSERT_EQ(s.polyline_radii[l].size(), s.polylines[l].rows());
    for (Eigen::Index i = 0; i < s.polylines[l].rows(); ++i) {
      const Eigen::Vector3d p = s.polylines[l].row(i).transpose();
      const double r = s.polyline_radii[l][i];
      EXPECT_NEAR(r, surface.distance(p), 0.05) << "link " << l << " point " << i;
      if (std::abs(p.z()) < 7) {  // on the cylinder, away from the caps
        EXPECT_NEAR(r, 3.0, 0.15) << p.transpose();
        ++along;
      }
    }
  }
  EXPECT_GT(along, 0);
}

TEST(Pipeline, ProgressCallbackCancels) {
  const dcg::Mesh mesh = dcg::read_mesh(repo_file("data/meshes/torus.off"));
  dcg::Extractor extractor(mesh.V, mesh.F, {}, [](const std::string&, double) { return false; });
  EXPECT_THROW(extractor.skeleton(), dcg::Cancelled);
}

// Cancel latency (issue #7): "cancelling (the progress callback returning false, Esc in Blender)
// stops within 0.5 s and leaves nothing half-made". One extractor is cancelled again and again,
// resuming after each cancel: at the first call of every stage (its boundary), half the stage's
// reference duration after the resume (a wall-clock request, answered at the next poll) and at
// the middle call of the stage (mid-stage polls). Each time, the time from the request (the
// call that returned false, or the moment the delay passed) to the Cancelled exception is under
// 0.5 s; at the end the extractor's skeleton equals an uncancelled run's. ("Public" in the names
// keeps them out of the sanitizer run, whose slowdown would make the timing meaningless.)
using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

struct CancelProbe {
  // One request at a time: cancel at the `call`-th call with stage `stage` since arming
  // (call >= 1), or at the first call after `delay` seconds from arming (delay >= 0).
  std::string stage;
  int call = 0;
  double delay = -1;
  Clock::time_point armed_at, requested_at;
  bool requested = false, armed = false;
  std::map<std::string, int> seen;

  void arm_at_call(const std::string& s, int k) {
    *this = CancelProbe();
    stage = s;
    call = k;
    armed = true;
    armed_at = Clock::now();
  }
  void arm_after(double seconds) {
    *this = CancelProbe();
    delay = seconds;
    armed = true;
    armed_at = Clock::now();
  }
  void disarm() { *this = CancelProbe(); }
  bool operator()(const std::string& s, double) {
    if (!armed) return true;
    const Clock::time_point now = Clock::now();
    if (delay >= 0) {
      if (seconds_between(armed_at, now) < delay) return true;
      requested_at = armed_at + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(delay));
    } else {
      if (s != stage || ++seen[s] < call) return true;
      requested_at = now;
    }
    requested = true;
    armed = false;
    return false;
  }
};

struct StageCalls {
  std::vector<std::string> order;         // stages in the order of their first call
  std::map<std::string, int> calls;       // progress calls per stage
  std::map<std::string, double> seconds;  // from the stage's first call to the next stage's
};

void expect_cancel_latency(const std::string& name, double max_seconds = 0.5) {
  const std::string path = dcg::test::meshes_dir() + "/" + name;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " not found (set DCG_MESHES)";
  const dcg::Mesh mesh = dcg::read_mesh(path);

  // Reference run: the stages, their calls and durations.
  StageCalls ref;
  Clock::time_point stage_start = Clock::now();
  const dcg::ProgressCallback record = [&](const std::string& s, double) {
    const Clock::time_point now = Clock::now();
    if (ref.calls.count(s) == 0) {
      if (!ref.order.empty()) ref.seconds[ref.order.back()] = seconds_between(stage_start, now);
      ref.order.push_back(s);
      stage_start = now;
    }
    ++ref.calls[s];
    return true;
  };
  dcg::Extractor reference(mesh.V, mesh.F, {}, record);
  const dcg::Skeleton expected = reference.skeleton();

  CancelProbe probe;
  std::optional<dcg::Extractor> extractor;
  auto fresh_extractor = [&]() {
    extractor.emplace(mesh.V, mesh.F, dcg::Options{},
                      [&probe](const std::string& s, double f) { return probe(s, f); });
  };
  fresh_extractor();
  std::map<std::string, double> worst;
  int cancels = 0;
  auto run_expecting_cancel = [&](const std::string& what) {
    try {
      extractor->skeleton();
      // Stages poll by time (at most every 10 ms), so a stage can make fewer calls than in the
      // reference run: a cancel armed at a later call then never comes. Not an engine fault;
      // the run finished whole, so the next probes need a fresh Extractor.
      const bool fewer_calls = probe.delay < 0 && probe.seen[probe.stage] < probe.call;
      // Likewise a run faster than the reference (a loaded machine made the reference slow)
      // can end before a cancel armed by time: fine as long as it ended within the latency
      // bound of the moment the cancel was due.
      const double late = seconds_between(probe.armed_at, Clock::now()) - probe.delay;
      const bool ended_in_time = probe.delay >= 0 && !probe.requested && late < max_seconds;
      if (fewer_calls) {
        std::printf("[ %s: %s made %d calls this time, no cancel ]\n", name.c_str(),
                    probe.stage.c_str(), probe.seen[probe.stage]);
      } else if (ended_in_time) {
        std::printf("[ %s: the run ended %.3f s after the cancel was due (%s), no cancel ]\n",
                    name.c_str(), late, what.c_str());
      } else {
        ADD_FAILURE() << name << ": not cancelled (" << what << ")";
      }
      fresh_extractor();
    } catch (const dcg::Cancelled&) {
      const double latency = seconds_between(probe.requested_at, Clock::now());
      ASSERT_TRUE(probe.requested) << what;
      EXPECT_LT(latency, max_seconds) << name << ": " << what;
      worst[what.substr(0, what.find(' '))] =
          std::max(worst[what.substr(0, what.find(' '))], latency);
      ++cancels;
    }
  };
  for (const std::string& stage : ref.order) {
    if (stage == "done") continue;
    probe.arm_at_call(stage, 1);
    run_expecting_cancel(stage + " at its first call");
    const double duration = ref.seconds.count(stage) ? ref.seconds[stage] : 0.0;
    if (duration > 0.02) {
      probe.arm_after(0.5 * duration);
      run_expecting_cancel(stage + " after " + std::to_string(0.5 * duration) + " s");
    }
    if (ref.calls[stage] > 2) {
      probe.arm_at_call(stage, ref.calls[stage] / 2);
      run_expecting_cancel(stage + " at call " + std::to_string(ref.calls[stage] / 2));
    }
  }
  probe.disarm();
  const dcg::Skeleton& resumed = extractor->skeleton();
  EXPECT_GE(cancels, 8);
  EXPECT_EQ(resumed.method, expected.method);
  EXPECT_EQ(resumed.positions, expected.positions) << name << ": a cancel left something half-made";
  EXPECT_EQ(resumed.links, expected.links);
  EXPECT_EQ(resumed.kinds, expected.kinds);
  std::string report;
  for (const auto& [stage, seconds] : worst) report += " " + stage + " " + std::to_string(seconds);
  std::printf("[ cancel latency, %s, worst per stage (s):%s ]\n", name.c_str(), report.c_str());
}

TEST(Pipeline, PublicHorseCancelStopsWithinHalfASecondAndResumesWhole) {
  expect_cancel_latency("horse.ply");
}

TEST(Pipeline, PublicHandCancelStopsWithinHalfASecondAndResumesWhole) {
  expect_cancel_latency("hand.obj");
}

// An open scan: stage 0 repairs it with CGAL's alpha wrap, which runs on a worker thread so that
// a cancel need not wait for the wrap's long stretches without a callback (repair.cpp).
TEST(Pipeline, PublicOpenScanCancelStopsWithinHalfASecondAndResumesWhole) {
  expect_cancel_latency("bunny-scan-open.obj");
}

// Every stage polls while it works (dcg/progress.h): on a mid-size mesh, each stage of the
// Extractor that lasts 50 ms or more calls back at least 3 times, and its longest stretch
// without a call (from one of its calls to the next call, whatever stage that is in) is under
// half the stage. (Before every stage polled, stages 3, 5, 6 and 7 called back once, as they
// started: one stretch as long as the stage.) Relative to the stage's own length, so that a
// loaded machine, slowing the whole stage, does not make it fail; the absolute gaps are printed
// (about 10-20 ms for every stage but 0 and 1, whose CGAL steps run 30-60 ms without a call).
struct PollTrace {
  std::vector<std::string> order;         // stages in the order of their first call
  std::map<std::string, int> calls;       // calls per stage
  std::map<std::string, double> seconds;  // from the stage's first call to the next stage's
  std::map<std::string, double> gap;      // longest time from one of its calls to the next call
  std::map<std::string, double> gap_at;   // the fraction reported where that gap starts
};

PollTrace trace_polls(const dcg::Mesh& mesh) {
  PollTrace t;
  Clock::time_point last = Clock::now(), stage_start = last;
  std::string current;
  double fraction = 0;
  dcg::Extractor extractor(mesh.V, mesh.F, {}, [&](const std::string& s, double f) {
    const Clock::time_point now = Clock::now();
    if (!current.empty() && seconds_between(last, now) >= t.gap[current]) {
      t.gap[current] = seconds_between(last, now);
      t.gap_at[current] = fraction;
    }
    if (t.calls.count(s) == 0) {
      if (!current.empty()) t.seconds[current] = seconds_between(stage_start, now);
      t.order.push_back(s);
      stage_start = now;
    }
    ++t.calls[s];
    current = s;
    fraction = f;
    last = now;
    return true;
  });
  extractor.skeleton();
  return t;
}

TEST(Pipeline, PublicEveryStagePollsWhileItWorks) {
  std::string path = dcg::test::meshes_dir() + "/horse.ply";
  if (!std::filesystem::exists(path)) path = repo_file("data/spot.obj");
  const PollTrace t = trace_polls(dcg::read_mesh(path));
  std::string report;
  for (const std::string& stage : t.order) {
    if (stage == "done") continue;
    const double seconds = t.seconds.at(stage), gap = t.gap.at(stage);
    report += " " + stage + " " + std::to_string(t.calls.at(stage)) + " calls, " +
              std::to_string(seconds) + " s, gap " + std::to_string(gap) + " s at " +
              std::to_string(t.gap_at.at(stage)) + ";";
    if (seconds < 0.05) continue;
    EXPECT_GE(t.calls.at(stage), 3) << stage << " lasts " << seconds << " s";
    EXPECT_LE(gap, 0.5 * seconds) << stage << " lasts " << seconds << " s";
  }
  std::printf("[ polls, %s:%s ]\n", path.c_str(), report.c_str());
}

TEST(Pipeline, SameInputSameSkeleton) {
  const dcg::Mesh mesh = dcg::read_mesh(repo_file("data/meshes/torus.off"));
  dcg::Options options;
  options.voronoi.samples = 800;
  const dcg::Skeleton a = dcg::extract_skeleton(mesh.V, mesh.F, options);
  const dcg::Skeleton b = dcg::extract_skeleton(mesh.V, mesh.F, options);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.links, b.links);
  EXPECT_EQ(a.genus, 1);
}

// A live tau: the re-thresholded extractor gives what a fresh run at that tau gives, without
// running stages 0-2, 4 and 5 again, and a bad tau changes nothing.
TEST(Pipeline, RetuneGivesTheSkeletonOfAFreshRunAtThatTau) {
  const dcg::Mesh mesh = dcg::read_mesh(repo_file("data/spot.obj"));
  dcg::Options options;
  options.voronoi.samples = 1500;
  dcg::Extractor extractor(mesh.V, mesh.F, options);
  const Eigen::Index ends_before = extractor.end_points().ball.size();
  extractor.skeleton();
  const auto count = [&](const std::string& stage) {
    const auto& t = extractor.timings();
    return std::count_if(t.begin(), t.end(), [&](const auto& s) { return s.first == stage; });
  };
  for (const double tau : {0.7, 0.95}) {
    extractor.retune(tau);
    EXPECT_EQ(extractor.options().prongs.tau, tau);
    const dcg::Skeleton& retuned = extractor.skeleton();
    options.prongs.tau = tau;
    const dcg::Skeleton fresh = dcg::extract_skeleton(mesh.V, mesh.F, options);
    EXPECT_EQ(retuned.positions, fresh.positions) << "tau " << tau;
    EXPECT_EQ(retuned.links, fresh.links) << "tau " << tau;
    EXPECT_EQ(retuned.kinds, fresh.kinds) << "tau " << tau;
  }
  EXPECT_NE(extractor.end_points().ball.size(), ends_before) << "spot: 6 ends at 0.85, 7 at 0.95";
  for (const char* kept : {"prepare", "voronoi_balls", "prongs", "connection_points", "retune"})
    EXPECT_EQ(count(kept), 1) << kept;
  EXPECT_THROW(extractor.retune(0.0), dcg::InputError);
  EXPECT_EQ(extractor.options().prongs.tau, 0.95);
}

}  // namespace
