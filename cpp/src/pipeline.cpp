// The pipeline: the stepwise Extractor and extract_skeleton(), a chain of calls to the stages
// (see dcg/pipeline.h). Each stage's work is in its own files; the options are in options.cpp,
// the fallback skeleton in interim_graph.cpp.
#include "dcg/pipeline.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <stdexcept>
#include <thread>
#include <utility>

#include "dcg/errors.h"
#include "dcg/interim_graph.h"
#include "dcg/keep_inside.h"
#include "dcg/surface_query.h"
#include "polling.h"

namespace dcg {
namespace {

// Each stage's share of the whole run: it reports from its start to the next one's (see
// dcg/progress.h), in the order skeleton() runs them.
constexpr double kPrepare = 0.0, kVoronoi = 0.25, kDomain = 0.55, kProngs = 0.6, kField = 0.65,
                 kConnection = 0.7, kGraph = 0.8, kRemap = 0.9, kSkeleton = 0.97, kDone = 1.0;

double now_seconds() {
  using Clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

}  // namespace

// --- extractor ----------------------------------------------------------------------------------

Extractor::Extractor(Vertices V, Faces F, Options options, ProgressCallback progress)
    : V_(std::move(V)), F_(std::move(F)), options_(options), progress_(std::move(progress)) {
  options_.validate();
  validate_mesh(V_, F_);
}

Extractor::~Extractor() = default;

double Extractor::timings_seconds(const std::string& stage) const {
  for (const auto& t : timings_)
    if (t.first == stage) return t.second;
  return 0;
}

void Extractor::timed(const std::string& stage, double seconds) {
  for (auto& t : timings_) {
    if (t.first == stage) {  // a stage timed in two parts (force_field: build, domain points)
      t.second += seconds;
      return;
    }
  }
  timings_.emplace_back(stage, seconds);
}

const PreparedMesh& Extractor::prepare() {
  if (!prepared_) {
    const double t0 = now_seconds();
    prepared_ = prepare_mesh(V_, F_, options_.prepare_options(), progress_, kPrepare, kVoronoi);
    timed("prepare", now_seconds() - t0);
  }
  return *prepared_;
}

const SurfaceQuery& Extractor::query() { return *prepare().query; }

const Balls& Extractor::voronoi_balls() {
  if (!voronoi_) {
    const Mesh& working = prepare().working;
    const double t0 = now_seconds();
    VoronoiBallsOptions vo = options_.voronoi;
    vo.samples = voronoi_samples(vo, options_.prepare, working.F.rows());
    vo.seed = options_.seed;
    voronoi_ = compute_voronoi_balls(working, query(), vo, progress_, kVoronoi, kDomain);
    timed("voronoi_balls", now_seconds() - t0);
  }
  return *voronoi_;
}

const DomainBalls& Extractor::domain_balls() {
  if (!domain_) {
    const Balls& candidates = voronoi_balls();
    const double t0 = now_seconds();
    domain_ = compute_domain_balls(candidates, options_.domain, progress_, kDomain, kProngs);
    timed("domain_balls", now_seconds() - t0);
  }
  return *domain_;
}

ProngFeatures Extractor::compute_prongs_stage(const Progress& progress) {
  ProngOptions po = options_.prongs;
  po.seed = options_.seed;
  return compute_prongs(prepare().working, po, progress, kProngs, kField);
}

const ProngFeatures& Extractor::prongs() {
  if (!prongs_) {
    prepare();
    const double t0 = now_seconds();
    prongs_ = compute_prongs_stage(progress_);
    timed("prongs", now_seconds() - t0);
  }
  return *prongs_;
}

// Stage 3 needs the working mesh only (and so does the shape's mirror plane, found after it on
// the same thread: 1-10 ms hidden). Stage 1's sampling and Delaunay triangulation run on one
// thread (a third of a small mesh's run), so on a second thread the scale function's Dijkstras
// fill the cores meanwhile (hand.obj 133 -> 112 ms, cheetah 75 -> 64 ms). The second thread reports
// no progress (the user sees stages 1-2, then stage 3 done); it polls a flag that this thread sets
// when it stops early (cancelled, or an error), and this thread waits for it before anything
// propagates. Its results are those of prongs() run alone (every stage's result is independent of
// threads).
void Extractor::prongs_beside_balls() {
  prepare();
  if (prongs_ || voronoi_ || internal::max_threads() < 2) return;
  std::atomic<bool> stop{false};
  std::optional<ProngFeatures> found;
  std::optional<MirrorPlane> plane;  // the shape's mirror plane needs the working mesh only too
  std::exception_ptr failed;
  double seconds = 0, plane_seconds = 0;
  internal::Completion done;
  // Started before the worker: a worker that runs ahead of this thread (a loaded machine)
  // must not make the overlap larger than either side's own time.
  const double started = now_seconds();
  std::thread worker([&] {
    const double t0 = now_seconds();
    try {
      found = compute_prongs_stage(Progress([&](const std::string&, double) { return !stop; }));
      seconds = now_seconds() - t0;
      if (!mirror_ && !stop) {
        plane = find_mirror_plane(prepare().working, query());
        plane_seconds = now_seconds() - t0 - seconds;
      }
    } catch (...) {
      failed = std::current_exception();
      seconds = now_seconds() - t0;
    }
    done.set();
  });
  try {
    voronoi_balls();
    domain_balls();
    const auto waiting = [&] { progress_.report("prongs", kProngs); };
    waiting();
    done.wait_polling(waiting);
  } catch (...) {
    stop = true;
    worker.join();
    throw;
  }
  worker.join();
  if (failed) std::rethrow_exception(failed);
  const double together = now_seconds() - started;
  const double alone =
      timings_seconds("voronoi_balls") + timings_seconds("domain_balls") + seconds + plane_seconds;
  overlapped_ += std::max(0.0, alone - together);
  prongs_ = std::move(found);
  timed("prongs", seconds);
  if (plane) {
    mirror_ = plane;
    timed("symmetry", plane_seconds);
  }
}

Prongs Extractor::prongs_at(double tau) { return prongs().hierarchy.prongs(tau); }

void Extractor::retune(double tau) {
  Options retuned = options_;
  retuned.prongs.tau = tau;
  retuned.validate();
  options_ = retuned;
  if (!prongs_) return;  // stage 3 will run at the new tau
  const double t0 = now_seconds();
  prongs_->prongs = prongs_->hierarchy.prongs(tau);
  end_points_.reset();
  graph_.reset();
  remapped_.reset();
  skeleton_.reset();
  // The dropped stages are timed afresh when they run again; "retune" is the last re-threshold.
  const auto dropped = [](const std::pair<std::string, double>& t) {
    return t.first == "end_points" || t.first == "domain_graph" || t.first == "remap" ||
           t.first == "skeleton" || t.first == "interim_graph" || t.first == "retune";
  };
  timings_.erase(std::remove_if(timings_.begin(), timings_.end(), dropped), timings_.end());
  timed("retune", now_seconds() - t0);
}

const EndPoints& Extractor::end_points() {
  if (!end_points_) {
    const Balls& balls = voronoi_balls();
    const Prongs& found = prongs().prongs;
    const double t0 = now_seconds();
    end_points_ = find_end_points(found, balls, query(), 0.5 * options_.domain.min_radius);
    timed("end_points", now_seconds() - t0);
  }
  return *end_points_;
}

const ForceField& Extractor::force_field() {
  if (!field_) {
    const PreparedMesh& pm = prepare();
    progress_.report("force_field", kField);
    const double t0 = now_seconds();
    field_.emplace(pm.query, options_.field);
    timed("force_field", now_seconds() - t0);
  }
  return *field_;
}

const FieldSamples& Extractor::domain_field() {
  if (!domain_field_) {
    const DomainBalls& domain = domain_balls();
    const ForceField& field = force_field();
    const double t0 = now_seconds();
    domain_field_ = field.evaluate(domain.balls.centers);
    timed("force_field", now_seconds() - t0);
  }
  return *domain_field_;
}

const ConnectionPoints& Extractor::connection_points() {
  if (!connection_) {
    const DomainBalls& domain = domain_balls();
    const ForceField& field = force_field();
    const double t0 = now_seconds();
    connection_ = compute_connection_points(domain.balls.centers, field, options_.connection,
                                            progress_, kConnection, kGraph);
    timed("connection_points", now_seconds() - t0);
  }
  return *connection_;
}

const DomainGraph& Extractor::domain_graph() {
  if (!graph_) {
    const PreparedMesh& pm = prepare();
    domain_balls();
    const EndPoints& ends = end_points();
    const ConnectionPoints& cp = connection_points();
    const double t0 = now_seconds();
    const GraphPoints points =
        graph_points(cp, ends, prongs().prongs, pm.working, query(), domain_->balls.centers);
    graph_ =
        compute_domain_graph(pm.working, force_field(), points.points, points.radii, points.prong,
                             pm.genus, DomainGraphOptions{}, progress_, kGraph, kRemap);
    timed("domain_graph", now_seconds() - t0);
  }
  return *graph_;
}

const Remapped& Extractor::remap() {
  if (!remapped_) {
    const DomainGraph& g = domain_graph();
    const ConnectionPoints& cp = connection_points();
    const double t0 = now_seconds();
    const Eigen::Index n = static_cast<Eigen::Index>(g.nodes.size());
    Points nodes(n, 3);
    Eigen::VectorXd radii(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      nodes.row(i) = g.points.row(g.nodes[i]);
      radii[i] = g.radii[g.nodes[i]];
    }
    // Waypoints for links that leave the shape: points known to be inside (the stage-1 balls
    // are dense in thin parts).
    const Points& balls = voronoi_balls().centers;
    Points waypoints(cp.shrunk.rows() + g.points.rows() + balls.rows(), 3);
    waypoints << cp.shrunk, g.points, balls;
    // A link that leaves the shape where the waypoints hold no way round (a thin plate, such as
    // a cow's ear at the input's own resolution, has few stage-1 balls) tries again with one
    // more waypoint behind every face: the middle of its inward chord.
    const SurfaceQuery& surface = query();
    const MoreWaypoints chords = [&](const Progress& progress, double from, double to) {
      return chord_midpoints(prepared_->working, surface, progress, from, to);
    };
    remapped_ = remap_links(nodes, radii, g.links, force_field(), waypoints, options_.remap, chords,
                            progress_, kRemap, kSkeleton);
    timed("remap", now_seconds() - t0);
  }
  return *remapped_;
}

const MirrorPlane& Extractor::mirror_plane() {
  if (!mirror_) {
    const double t0 = now_seconds();
    mirror_ = find_mirror_plane(prepare().working, query());
    timed("symmetry", now_seconds() - t0);
  }
  return *mirror_;
}

void Extractor::finish(Skeleton& s) {
  measure_polyline_radii(s, query());
  skeleton_to_input(s, *prepared_, F_, V_.rows());
  // The plane n . w = o of the working mesh is n . x = o scale + n . offset in the input's.
  const MirrorPlane& m = mirror_plane();
  s.mirror_plane << m.normal, m.offset * prepared_->scale + prepared_->offset.dot(m.normal);
  s.mirror_error = m.error;
  s.timings = timings_;
  double total = 0;
  for (const auto& t : timings_) total += t.second;
  s.timings.emplace_back("total", std::max(0.0, total - overlapped_));
}

Skeleton Extractor::interim_skeleton() {
  const DomainBalls& domain = domain_balls();
  const Prongs& found = prongs().prongs;
  const double t0 = now_seconds();
  Skeleton s = build_interim_graph(domain.balls);
  mark_prong_ends(found, s);
  timed("interim_graph", now_seconds() - t0);
  finish(s);
  return s;
}

const Skeleton& Extractor::skeleton() {
  if (!skeleton_) {
    // Stage by stage, in the order of their progress fractions.
    prepare();
    prongs_beside_balls();
    voronoi_balls();
    domain_balls();
    prongs();
    std::string failure;
    Skeleton s;
    try {
      end_points();
      connection_points();
      domain_graph();
      const Remapped& remapped = remap();
      progress_.report("skeleton", kSkeleton);
      const double t0 = now_seconds();
      const DomainGraph& g = *graph_;
      if (g.nodes.empty()) throw std::runtime_error("stage 6 kept no node");
      s = assemble_skeleton(g, remapped, prongs_->prongs.significance);
      // The working mesh of a remeshed input may bulge out of it in concave places: hold the
      // skeleton to the input's own surface when that is closed (else to the working mesh).
      keep_inside_input(s, *prepared_, V_, F_, query(), progress_, kSkeleton, kDone);
      timed("skeleton", now_seconds() - t0);
    } catch (const Cancelled&) {
      throw;
    } catch (const std::exception& e) {
      failure = e.what();
    }
    if (failure.empty()) {
      finish(s);
    } else {
      s = interim_skeleton();
      s.method = "interim_graph (fallback: " + failure + ")";
    }
    progress_.report("done", kDone);
    skeleton_ = std::move(s);
  }
  return *skeleton_;
}

Skeleton extract_skeleton(const Vertices& V, const Faces& F, const Options& options,
                          ProgressCallback progress) {
  Extractor extractor(V, F, options, std::move(progress));
  return extractor.skeleton();
}

}  // namespace dcg
