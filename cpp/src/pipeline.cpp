// The pipeline: option table, stepwise Extractor and extract_skeleton(). See dcg/pipeline.h.
//
// Stages 4-8 are not implemented yet. Until they land, skeleton() builds an INTERIM graph from
// the domain points of stage 2 (method "interim_graph", see build_interim_graph below): a
// Euclidean minimum spanning tree, short twigs pruned, chains of degree-2 points turned into
// link polylines. It is real data from real stages, good enough to run the whole path into
// Blender, and it is replaced by stages 4-8 (ALGORITHM.md) without changing the Skeleton type.
// Stage 3 only sets the significance of its end nodes (mark_prong_ends).
#include "dcg/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <variant>

#include "dcg/errors.h"
#include "dcg/surface_query.h"

namespace dcg {
namespace {

using Field = std::variant<int Options::*, double Options::*, unsigned Options::*>;

struct OptionEntry {
  OptionSpec spec;
  Field field;
};

const std::vector<OptionEntry>& option_table() {
  static const std::vector<OptionEntry> table = {
      {{"target_faces", "Triangles of the uniform working mesh after remeshing (0: keep the input)",
        0, 2e6, true, ""}, &Options::target_faces},
      {{"samples", "Surface samples whose Voronoi vertices give the candidate balls", 100, 1e6,
        true, ""}, &Options::samples},
      {{"min_gap", "Gap kept between domain balls", 0, 0.5, false, "normalized length"},
       &Options::min_gap},
      {{"min_radius", "Smallest domain ball kept", 0, 0.5, false, "normalized length"},
       &Options::min_radius},
      {{"tau", "Prong smoothness ratio: a bump is a prong when valley / peak < tau", 0.01, 1.0,
        false, ""}, &Options::tau},
      {{"geodesic_sources", "Sources of the sampled geodesic scale function", 1, 1e5, true, ""},
       &Options::geodesic_sources},
      {{"rays", "Rays cast per point for the repulsive force field", 6, 4096, true, ""},
       &Options::rays},
      {{"force_exponent", "Exponent n of the force field F(p) = -1/K sum u_k / r_k^n", 0.5, 4,
        false, ""}, &Options::force_exponent},
      {{"shrink_step", "Initial step factor alpha when shrinking domain points along the field",
        0.001, 1, false, ""}, &Options::shrink_step},
      {{"snake_iterations", "Iterations of the snake that re-maps each link", 0, 10000, true, ""},
       &Options::snake_iterations},
      {{"seed", "Seed of every randomized step (same seed, same skeleton)", 0, 4294967295.0, true,
        ""}, &Options::seed},
  };
  return table;
}

const OptionEntry& find_option(const std::string& name) {
  for (const auto& entry : option_table()) {
    if (entry.spec.name == name) return entry;
  }
  throw InputError("unknown option '" + name + "'");
}

std::string format_number(double v) {
  std::string s = std::to_string(v);
  s.erase(s.find_last_not_of('0') + 1);
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

void check_range(const OptionSpec& spec, double value) {
  if (!std::isfinite(value) || value < spec.minimum || value > spec.maximum) {
    throw InputError("option " + spec.name + " = " + format_number(value) + " is out of range [" +
                     format_number(spec.minimum) + ", " + format_number(spec.maximum) + "]");
  }
  if (spec.integer && value != std::floor(value)) {
    throw InputError("option " + spec.name + " must be a whole number, got " +
                     format_number(value));
  }
}

double now_seconds() {
  using Clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

// --- interim graph (until stages 4-8 land) -----------------------------------------------------

// Minimum spanning tree of the complete Euclidean graph on `points` (Prim, O(k^2) time, O(k)
// memory). Fine for the few thousand domain points of stage 2.
std::vector<std::vector<int>> euclidean_mst(const Points& points) {
  const int k = static_cast<int>(points.rows());
  std::vector<std::vector<int>> adjacency(k);
  if (k == 0) return adjacency;
  std::vector<double> best(k, std::numeric_limits<double>::infinity());
  std::vector<int> parent(k, -1);
  std::vector<char> done(k, 0);
  best[0] = 0;
  for (int iter = 0; iter < k; ++iter) {
    int u = -1;
    for (int i = 0; i < k; ++i) {
      if (!done[i] && (u < 0 || best[i] < best[u])) u = i;
    }
    done[u] = 1;
    if (parent[u] >= 0) {
      adjacency[u].push_back(parent[u]);
      adjacency[parent[u]].push_back(u);
    }
    for (int i = 0; i < k; ++i) {
      if (done[i]) continue;
      const double d = (points.row(i) - points.row(u)).squaredNorm();
      if (d < best[i]) {
        best[i] = d;
        parent[i] = u;
      }
    }
  }
  return adjacency;
}

void remove_edge(std::vector<std::vector<int>>& adjacency, int a, int b) {
  auto& la = adjacency[a];
  la.erase(std::remove(la.begin(), la.end(), b), la.end());
  auto& lb = adjacency[b];
  lb.erase(std::remove(lb.begin(), lb.end(), a), lb.end());
}

// Removes leaf branches (leaf .. first junction) shorter than twice the junction's radius: they
// stand for surface bumps, not limbs. Repeats until nothing changes.
void prune_twigs(const Points& points, const Eigen::VectorXd& radii,
                 std::vector<std::vector<int>>& adjacency) {
  const int k = static_cast<int>(points.rows());
  for (bool changed = true; changed;) {
    changed = false;
    for (int leaf = 0; leaf < k; ++leaf) {
      if (adjacency[leaf].size() != 1) continue;
      std::vector<int> branch = {leaf};
      double length = 0;
      int prev = leaf, cur = adjacency[leaf][0];
      while (adjacency[cur].size() == 2) {
        length += (points.row(cur) - points.row(prev)).norm();
        branch.push_back(cur);
        const int next = adjacency[cur][0] == prev ? adjacency[cur][1] : adjacency[cur][0];
        prev = cur;
        cur = next;
      }
      if (adjacency[cur].size() < 3) continue;  // the whole tree is one path: keep it
      length += (points.row(cur) - points.row(prev)).norm();
      if (length >= 2.0 * radii[cur]) continue;
      remove_edge(adjacency, prev, cur);
      for (size_t i = 0; i + 1 < branch.size(); ++i) remove_edge(adjacency, branch[i], branch[i + 1]);
      changed = true;
    }
  }
}

// Builds the interim skeleton (normalized units) from the domain balls: key nodes are the tree's
// leaves (ends) and junctions (joints); chains between them become link polylines.
Skeleton build_interim_graph(const Balls& domain) {
  const Points& points = domain.centers;
  const int k = static_cast<int>(points.rows());
  Skeleton s;
  s.method = "interim_graph";
  if (k == 0) throw InputError("the shape has no interior: no domain ball was found");
  auto adjacency = euclidean_mst(points);
  prune_twigs(points, domain.radii, adjacency);

  // The largest ball always survives pruning (a junction's radius never shrinks its own branch),
  // so the component that holds it is the tree.
  int start = 0;
  for (int i = 1; i < k; ++i) {
    if (domain.radii[i] > domain.radii[start]) start = i;
  }
  std::vector<int> node_of(k, -1);
  std::vector<int> keys;
  {
    std::vector<char> seen(k, 0);
    std::vector<int> stack = {start};
    seen[start] = 1;
    while (!stack.empty()) {
      const int u = stack.back();
      stack.pop_back();
      if (adjacency[u].size() != 2) {
        node_of[u] = static_cast<int>(keys.size());
        keys.push_back(u);
      }
      for (int v : adjacency[u]) {
        if (!seen[v]) {
          seen[v] = 1;
          stack.push_back(v);
        }
      }
    }
  }
  if (keys.empty()) {  // a closed chain cannot come out of a tree; keep the largest ball alone
    node_of[start] = 0;
    keys.push_back(start);
  }

  const int n = static_cast<int>(keys.size());
  s.positions.resize(n, 3);
  s.radii.resize(n);
  s.significance = Eigen::VectorXd::Zero(n);
  s.kinds.resize(n);
  for (int i = 0; i < n; ++i) {
    const int u = keys[i];
    s.positions.row(i) = points.row(u);
    s.radii[i] = domain.radii[u];
    const size_t degree = adjacency[u].size();
    s.kinds[i] = degree == 1 ? NodeKind::End : degree >= 3 ? NodeKind::Joint : NodeKind::Connection;
  }
  // Walk every chain once, from each key node along each of its edges to the next key node.
  std::vector<std::pair<int, int>> links;
  for (int i = 0; i < n; ++i) {
    const int a = keys[i];
    for (int first : adjacency[a]) {
      std::vector<int> chain = {a};
      int prev = a, cur = first;
      while (node_of[cur] < 0) {
        chain.push_back(cur);
        const int next = adjacency[cur][0] == prev ? adjacency[cur][1] : adjacency[cur][0];
        prev = cur;
        cur = next;
      }
      chain.push_back(cur);
      if (node_of[cur] < i) continue;  // the same chain was walked from its other end
      links.emplace_back(i, node_of[cur]);
      Points polyline(static_cast<Eigen::Index>(chain.size()), 3);
      for (size_t j = 0; j < chain.size(); ++j) polyline.row(j) = points.row(chain[j]);
      s.polylines.push_back(std::move(polyline));
    }
  }
  s.links.resize(static_cast<Eigen::Index>(links.size()), 2);
  for (size_t l = 0; l < links.size(); ++l) s.links.row(l) << links[l].first, links[l].second;

  // Root: the joint of largest radius (the torso), else the node of largest radius.
  for (int pass = 0; pass < 2 && s.root < 0; ++pass) {
    for (int i = 0; i < n; ++i) {
      if (pass == 0 && s.kinds[i] != NodeKind::Joint) continue;
      if (s.root < 0 || s.radii[i] > s.radii[s.root]) s.root = i;
    }
  }
  return s;
}

// Stage 3 on the interim graph (normalized units): the end node nearest to each prong's peak,
// strongest prongs first and each end at most once, gets the prong's significance; ends that
// stand for no prong get 1, the weakest ratio. The graph itself is left as it is.
void mark_prong_ends(const Prongs& prongs, Skeleton& s) {
  const int n = static_cast<int>(s.positions.rows());
  std::vector<char> taken(n, 0);
  for (int i = 0; i < n; ++i)
    if (s.kinds[i] == NodeKind::End) s.significance[i] = 1.0;
  for (Eigen::Index p = 0; p < prongs.vertices.size(); ++p) {
    int best = -1;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      if (s.kinds[i] != NodeKind::End || taken[i]) continue;
      const double d2 = (s.positions.row(i) - prongs.positions.row(p)).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best = i;
      }
    }
    if (best < 0) break;
    taken[best] = 1;
    s.significance[best] = prongs.significance[p];
  }
}

}  // namespace

// --- options --------------------------------------------------------------------------------------

const std::vector<OptionSpec>& numeric_option_specs() {
  static const std::vector<OptionSpec> specs = [] {
    std::vector<OptionSpec> out;
    for (const auto& entry : option_table()) out.push_back(entry.spec);
    return out;
  }();
  return specs;
}

double get_numeric_option(const Options& options, const std::string& name) {
  const OptionEntry& entry = find_option(name);
  return std::visit([&](auto field) { return static_cast<double>(options.*field); }, entry.field);
}

void set_numeric_option(Options& options, const std::string& name, double value) {
  const OptionEntry& entry = find_option(name);
  check_range(entry.spec, value);
  std::visit(
      [&](auto field) {
        using T = std::remove_reference_t<decltype(options.*field)>;
        options.*field = static_cast<T>(value);
      },
      entry.field);
}

void Options::validate() const {
  for (const auto& entry : option_table()) check_range(entry.spec, get_numeric_option(*this, entry.spec.name));
}

Repair parse_repair(const std::string& text) {
  if (text == "auto") return Repair::Auto;
  if (text == "none") return Repair::None;
  throw InputError("option repair must be 'auto' or 'none', got '" + text + "'");
}

const char* repair_name(Repair repair) { return repair == Repair::Auto ? "auto" : "none"; }

// --- extractor ----------------------------------------------------------------------------------

Extractor::Extractor(Vertices V, Faces F, Options options, ProgressCallback progress)
    : V_(std::move(V)), F_(std::move(F)), options_(options), progress_(std::move(progress)) {
  options_.validate();
  validate_mesh(V_, F_);
}

Extractor::~Extractor() = default;

void Extractor::timed(const std::string& stage, double seconds) {
  timings_.emplace_back(stage, seconds);
}

const PreparedMesh& Extractor::prepare() {
  if (!prepared_) {
    progress_.report("prepare", 0.0);
    const double t0 = now_seconds();
    PrepareOptions po;
    po.repair = options_.repair;
    po.target_faces = options_.target_faces;
    po.seed = options_.seed;
    prepared_ = prepare_mesh(V_, F_, po);
    timed("prepare", now_seconds() - t0);
  }
  return *prepared_;
}

const SurfaceQuery& Extractor::query() { return *prepare().query; }

const Balls& Extractor::voronoi_balls() {
  if (!voronoi_) {
    const Mesh& working = prepare().working;
    progress_.report("voronoi_balls", 0.25);
    const double t0 = now_seconds();
    VoronoiBallsOptions vo;
    vo.samples = options_.samples;
    vo.seed = options_.seed;
    voronoi_ = compute_voronoi_balls(working, query(), vo);
    timed("voronoi_balls", now_seconds() - t0);
  }
  return *voronoi_;
}

const DomainBalls& Extractor::domain_balls() {
  if (!domain_) {
    const Balls& candidates = voronoi_balls();
    progress_.report("domain_balls", 0.55);
    const double t0 = now_seconds();
    DomainBallsOptions dopt;
    dopt.min_gap = options_.min_gap;
    dopt.min_radius = options_.min_radius;
    domain_ = compute_domain_balls(candidates, dopt);
    timed("domain_balls", now_seconds() - t0);
  }
  return *domain_;
}

const ProngFeatures& Extractor::prongs() {
  if (!prongs_) {
    const Mesh& working = prepare().working;
    progress_.report("prongs", 0.6);
    const double t0 = now_seconds();
    ProngOptions po;
    po.tau = options_.tau;
    po.geodesic_sources = options_.geodesic_sources;
    po.seed = options_.seed;
    prongs_ = compute_prongs(working, po);
    timed("prongs", now_seconds() - t0);
  }
  return *prongs_;
}

Prongs Extractor::prongs_at(double tau) { return prongs().hierarchy.prongs(tau); }

const EndPoints& Extractor::end_points() {
  if (!end_points_) {
    const Balls& balls = voronoi_balls();
    const Prongs& found = prongs().prongs;
    const double t0 = now_seconds();
    end_points_ = find_end_points(found, balls, query(), 0.5 * options_.min_radius);
    timed("end_points", now_seconds() - t0);
  }
  return *end_points_;
}

const Skeleton& Extractor::skeleton() {
  if (!skeleton_) {
    const DomainBalls& domain = domain_balls();
    const Prongs& found = prongs().prongs;
    progress_.report("interim_graph", 0.65);
    const double t0 = now_seconds();
    Skeleton s = build_interim_graph(domain.balls);
    mark_prong_ends(found, s);
    timed("interim_graph", now_seconds() - t0);

    // Back to the input's coordinates.
    const PreparedMesh& pm = *prepared_;
    for (Eigen::Index i = 0; i < s.positions.rows(); ++i) s.positions.row(i) = pm.to_input(s.positions.row(i));
    for (auto& polyline : s.polylines) {
      for (Eigen::Index i = 0; i < polyline.rows(); ++i) polyline.row(i) = pm.to_input(polyline.row(i));
    }
    s.radii *= pm.scale;
    s.face_labels = Eigen::VectorXi::Constant(F_.rows(), -1);  // stage 6 labels faces
    s.input_vertices = static_cast<int>(V_.rows());
    s.input_faces = static_cast<int>(F_.rows());
    s.genus = pm.genus;
    s.repaired = pm.repaired;
    s.timings = timings_;
    double total = 0;
    for (const auto& t : timings_) total += t.second;
    s.timings.emplace_back("total", total);
    progress_.report("done", 1.0);
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
