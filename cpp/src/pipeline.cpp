// The pipeline: option table, stepwise Extractor and extract_skeleton(). See dcg/pipeline.h.
//
// skeleton() runs stages 0-8 (method "dcg"). The INTERIM graph of the domain points of stage 2
// (build_interim_graph below: a Euclidean minimum spanning tree, short twigs pruned, chains of
// degree-2 points turned into link polylines) is kept only as the fallback when stages 4-8 fail;
// `method` then says "interim_graph (fallback: <reason>)".
#include "dcg/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <variant>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "dcg/errors.h"
#include "dcg/surface_query.h"
#include "polling.h"

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
      {{"upsample", "1: remesh inputs smaller than target_faces / 2.5 up to target_faces (slower); "
        "0: use them as they are (with at most one sample per two faces)", 0, 1, true, ""},
       &Options::upsample},
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

// --- interim graph (the fallback when stages 4-8 fail) ------------------------------------------

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
    s.kinds[i] = node_kind_of_degree(adjacency[u].size());
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

  choose_root(s);
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

// The middle of the chord from `start` (a point just inside) along the unit direction d to the
// first wall it meets; none when the ray meets no wall or the middle is not inside.
std::optional<Eigen::Vector3d> chord_middle(const SurfaceQuery& query, const Eigen::Vector3d& start,
                                            const Eigen::Vector3d& d) {
  const double wall = query.ray_hit(start, d);
  if (!std::isfinite(wall)) return std::nullopt;
  const Eigen::Vector3d p = start + 0.5 * wall * d;
  if (!query.inside(p)) return std::nullopt;
  return p;
}

// The end point of a prong whose peak no stage-1 ball sees: the middle of the chord from the
// peak vertex inward to the opposite wall. Inward: against the vertex normal (area-weighted face
// normals), else toward the centroid of its faces, else toward `toward` (a point inside, e.g. the nearest ball center), else along the
// normal (the normal of a needle tip after remeshing can point in). `radius` receives the
// point's distance to the surface, 0 when no direction gives a point inside.
Eigen::Vector3d inward_point(const Mesh& mesh, const SurfaceQuery& query, int vertex,
                             const Eigen::Vector3d& toward, double* radius) {
  *radius = 0;
  if (vertex < 0 || vertex >= mesh.V.rows()) return Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero(), ring = Eigen::Vector3d::Zero();
  int corners = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    if (mesh.F(f, 0) != vertex && mesh.F(f, 1) != vertex && mesh.F(f, 2) != vertex) continue;
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)),
                          c = mesh.V.row(mesh.F(f, 2));
    normal += (b - a).cross(c - a);
    ring += a + b + c;
    corners += 3;
  }
  const Eigen::Vector3d peak = mesh.V.row(vertex).transpose();
  std::vector<Eigen::Vector3d> directions;
  if (normal.norm() > 0) directions.push_back(-normal.normalized());
  if (corners > 0 && (ring / corners - peak).norm() > 0) {
    directions.push_back((ring / corners - peak).normalized());  // a folded tip: its 1-ring
  }
  if ((toward - peak).norm() > 0) directions.push_back((toward - peak).normalized());
  if (normal.norm() > 0) directions.push_back(normal.normalized());
  for (const Eigen::Vector3d& d : directions) {
    const Eigen::Vector3d start = peak + 1e-6 * d;
    if (!query.inside(start)) continue;
    if (const auto p = chord_middle(query, start, d)) {
      *radius = query.distance(*p);
      return *p;
    }
  }
  return Eigen::Vector3d::Zero();
}

// Stage 1 keeps a Voronoi vertex when its signed distance is negative, a sign taken from the
// nearest face's orientation. Where the working mesh folds through itself (0.3% vertex noise on
// an octopus's thin tentacles) that sign is wrong near the fold, and circumcenters OUTSIDE the
// shape pass as balls of radius up to three times the largest true one: they then win the domain
// balls around them and take the end points of the tentacles (they "see" the tips from outside),
// and the tentacles lose their ends. A ball is dropped when two rays from its center (spread
// directions, different for each ball) do not both first meet the surface from behind (every
// ray from a point inside a closed, outward-oriented mesh leaves the shape there; a ray from
// outside meets a face from the front or nothing) AND ray parity puts it outside too. Cost: two
// first-hit rays per ball, parity only for the few that fail them (~7 ms on the hand's 13k
// balls; parity for every ball took 40 ms); on the closed public meshes it drops nothing.
Balls drop_balls_outside(Balls balls, const SurfaceQuery& query) {
  const Eigen::Index n = balls.radii.size();
  std::vector<char> keep(static_cast<std::size_t>(n), 1);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, 256),
                    [&](const tbb::blocked_range<Eigen::Index>& r) {
                      for (Eigen::Index i = r.begin(); i != r.end(); ++i) {
                        const Eigen::Vector3d c = balls.centers.row(i).transpose();
                        for (int k = 0; k < 2 && keep[i]; ++k) {
                          // Golden-angle spiral directions, indexed by ball and ray.
                          const double j = static_cast<double>(2 * i + k) + 0.5;
                          const double z = 1.0 - 2.0 * std::fmod(j * 0.6180339887498949, 1.0);
                          const double phi = j * 2.399963229728653;
                          const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
                          const Eigen::Vector3d d(s * std::cos(phi), s * std::sin(phi), z);
                          int face = -1;
                          const double t = query.ray_hit(c, d, &face);
                          keep[i] = std::isfinite(t) && face >= 0 && query.face_normal(face).dot(d) > 0;
                        }
                        // A ray may also meet a face from the front inside the shape where the
                        // mesh intersects itself (cow: ears through the head): ray parity,
                        // which counts every crossing, has the last word.
                        if (!keep[i]) keep[i] = query.inside_by_parity(c) ? 1 : 0;
                      }
                    });
  Eigen::Index m = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!keep[i]) continue;
    balls.centers.row(m) = balls.centers.row(i);
    balls.radii[m] = balls.radii[i];
    ++m;
  }
  if (m == n) return balls;
  balls.centers.conservativeResize(m, 3);
  balls.radii.conservativeResize(m);
  return balls;
}

// The middle of the inward chord from each face's centroid (along minus its normal), for the
// faces whose chord ends on the surface and whose middle is inside: one point in the middle of
// the shape behind every face, thin parts included.
Points chord_midpoints(const Mesh& mesh, const SurfaceQuery& surface) {
  const Eigen::Index nf = mesh.F.rows();
  Points mid(nf, 3);
  std::vector<char> ok(static_cast<std::size_t>(nf), 0);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, nf, 512),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
    for (Eigen::Index f = range.begin(); f != range.end(); ++f) {
      const Eigen::Vector3d& n = surface.face_normal(static_cast<int>(f));
      if (n.isZero()) continue;
      const Eigen::Vector3d c =
          (mesh.V.row(mesh.F(f, 0)) + mesh.V.row(mesh.F(f, 1)) + mesh.V.row(mesh.F(f, 2))).transpose() / 3.0;
      if (const auto m = chord_middle(surface, c - 1e-7 * n, -n)) {
        mid.row(f) = m->transpose();
        ok[static_cast<std::size_t>(f)] = 1;
      }
    }
  });
  Eigen::Index k = 0;
  for (Eigen::Index f = 0; f < nf; ++f)
    if (ok[static_cast<std::size_t>(f)]) mid.row(k++) = mid.row(f);
  mid.conservativeResize(k, 3);
  return mid;
}

// Fewest Voronoi samples of a small working mesh (Extractor::voronoi_balls).
constexpr int kMinSmallSamples = 500;

// --- keeping the skeleton inside the input surface ----------------------------------------------

// The working mesh of stage 0 may bulge out of a remeshed input (concave places, thin parts): a
// node or a polyline point at p that is not at least 1e-7 inside `surface` moves to
// q + t (q - p) / |q - p|, q its closest surface point, for the largest t among {0.5, 0.25, 0.1,
// 0.03, 0.01} x r (r its radius) and half the part's thickness there (never past the opposite
// wall) that lands at least 1e-7 inside. A point no candidate brings inside stays where it is.
void keep_point_inside(Eigen::Ref<Eigen::RowVector3d> point, double r,
                       const SurfaceQuery& surface) {
  const Eigen::Vector3d p = point.transpose();
  // Ray parity, not the pseudo-normals: the input's own winding may be inside out (mirrored).
  auto inside = [&](const Eigen::Vector3d& c, double depth) {
    return surface.inside_by_parity(c) && surface.distance(c) > depth;
  };
  if (inside(p, 1e-7)) return;
  const Eigen::Vector3d q = surface.closest_point(p);
  const Eigen::Vector3d d = q - p;
  if (d.norm() < 1e-12) return;
  const Eigen::Vector3d u = d.normalized();
  // Candidate depths below q along u, deepest first, never past the opposite wall (the chord of
  // the part there), landing at least 1e-7 inside.
  const double wall = surface.ray_hit(q + 1e-6 * u, u) + 1e-6;
  std::vector<double> depths = {0.5 * r, 0.25 * r, 0.1 * r, 0.03 * r, 0.01 * r};
  if (std::isfinite(wall) && wall > 2e-6) {
    depths.push_back(0.5 * wall);
    depths.erase(std::remove_if(depths.begin(), depths.end(), [&](double x) { return x >= wall; }),
                 depths.end());
  }
  std::sort(depths.rbegin(), depths.rend());
  for (double depth : depths) {
    const Eigen::Vector3d c = q + depth * u;
    if (inside(c, 1e-7)) {
      point = c.transpose();
      return;
    }
  }
  // Folded or self-touching input there: the nearest point inside around p (32 directions,
  // distances 0.25 to 4 r), preferring one at least r / 10 deep.
  const Points dirs = fibonacci_sphere(32);
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d chosen = p;
  for (double deep : {0.1 * r, 1e-7}) {
    for (double step : {0.25, 0.5, 1.0, 2.0, 4.0}) {
      for (Eigen::Index k = 0; k < dirs.rows(); ++k) {
        const Eigen::Vector3d c = p + step * r * dirs.row(k).transpose();
        if (step * r < best && inside(c, deep)) {
          best = step * r;
          chosen = c;
        }
      }
    }
    if (std::isfinite(best)) {
      point = chosen.transpose();
      return;
    }
  }
}

// A polyline segment between two points inside can still cross the surface: a link the snake
// could not route round the bend of a thin part (a cow's ear at the input's own resolution), or
// a point that keep_point_inside() moved. Such a segment gets its midpoint, held inside like the
// other points (radius interpolated from ra at the polyline's start to rb at its end), and each
// half is checked again, at most 6 halvings deep.
void keep_segments_inside(Points& poly, double ra, double rb, const SurfaceQuery& surface) {
  const Eigen::Index last = poly.rows() - 1;
  bool any = false;
  for (Eigen::Index i = 0; i < last && !any; ++i)
    any = surface.segment_blocked(poly.row(i).transpose(), poly.row(i + 1).transpose());
  if (!any) return;
  std::vector<Eigen::RowVector3d> out;
  // Appends the points after p up to q (q included), t = their places along the polyline.
  std::function<void(const Eigen::RowVector3d&, const Eigen::RowVector3d&, double, double, int)> refine =
      [&](const Eigen::RowVector3d& p, const Eigen::RowVector3d& q, double tp, double tq, int depth) {
        if (depth < 6 && surface.segment_blocked(p.transpose(), q.transpose())) {
          const double tm = 0.5 * (tp + tq);
          Eigen::RowVector3d m = 0.5 * (p + q);
          keep_point_inside(m, (1 - tm) * ra + tm * rb, surface);
          refine(p, m, tp, tm, depth + 1);
          refine(m, q, tm, tq, depth + 1);
        } else {
          out.push_back(q);
        }
      };
  out.push_back(poly.row(0));
  for (Eigen::Index i = 0; i < last; ++i) {
    refine(poly.row(i), poly.row(i + 1), static_cast<double>(i) / last,
           static_cast<double>(i + 1) / last, 0);
  }
  poly.resize(static_cast<Eigen::Index>(out.size()), 3);
  for (std::size_t i = 0; i < out.size(); ++i) poly.row(static_cast<Eigen::Index>(i)) = out[i];
}

// Skeleton (normalized units) against `surface`: nodes first, then polyline points (the ends of
// each polyline are its nodes), then the segments between them.
// `poll` (throttled) is called between nodes and links, for cancellation.
void keep_inside(Skeleton& s, const SurfaceQuery& surface, const std::function<void()>& poll) {
  for (Eigen::Index i = 0; i < s.positions.rows(); ++i) {
    poll();
    keep_point_inside(s.positions.row(i), s.radii[i], surface);
  }
  for (Eigen::Index l = 0; l < s.links.rows(); ++l) {
    poll();
    Points& poly = s.polylines[l];
    const int a = s.links(l, 0), b = s.links(l, 1);
    const Eigen::Index last = poly.rows() - 1;
    poly.row(0) = s.positions.row(a);
    poly.row(last) = s.positions.row(b);
    for (Eigen::Index i = 1; i < last; ++i) {
      const double t = static_cast<double>(i) / last;
      keep_point_inside(poly.row(i), (1 - t) * s.radii[a] + t * s.radii[b], surface);
    }
    keep_segments_inside(poly, s.radii[a], s.radii[b], surface);
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
    progress_.report("prepare", 0.0);
    const double t0 = now_seconds();
    PrepareOptions po;
    po.repair = options_.repair;
    po.target_faces = options_.target_faces;
    po.upsample = options_.upsample != 0;
    po.seed = options_.seed;
    prepared_ = prepare_mesh(V_, F_, po, progress_, 0.0, 0.25);
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
    // A small working mesh (a small input kept as it is) gets one sample per two faces, at
    // least 500: 4000 samples would cost more than the rest of the pipeline there, and the
    // public meshes of 898 to 5,856 faces keep their ends, joints and loops with these.
    const double faces = static_cast<double>(working.F.rows());
    if (!options_.upsample && small_for_target(faces, options_.target_faces)) {
      vo.samples = std::min(vo.samples, std::max(kMinSmallSamples, static_cast<int>(faces / 2)));
    }
    vo.seed = options_.seed;
    voronoi_ = drop_balls_outside(
        compute_voronoi_balls(working, query(), vo,
                              internal::throttled_poll(progress_, "voronoi_balls", 0.25)),
        query());
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

const ForceField& Extractor::force_field() {
  if (!field_) {
    const PreparedMesh& pm = prepare();
    progress_.report("force_field", 0.65);
    const double t0 = now_seconds();
    ForceFieldOptions fo;
    fo.rays = options_.rays;
    fo.force_exponent = options_.force_exponent;
    field_.emplace(pm.query, fo);
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
    progress_.report("connection_points", 0.7);
    const double t0 = now_seconds();
    ConnectionPointsOptions co;
    co.shrink_step = options_.shrink_step;
    connection_ = compute_connection_points(domain.balls.centers, field, co);
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
    progress_.report("domain_graph", 0.8);
    const double t0 = now_seconds();
    const Eigen::Index c = cp.positions.rows();
    std::vector<int> valid;
    for (Eigen::Index e = 0; e < ends.ball.size(); ++e)
      if (ends.ball[e] >= 0) valid.push_back(static_cast<int>(e));
    const Eigen::Index count = c + static_cast<Eigen::Index>(valid.size());
    Points points(count, 3);
    Eigen::VectorXd radii(count);
    Eigen::VectorXi prong = Eigen::VectorXi::Constant(count, -1);
    points.topRows(c) = cp.positions;
    radii.head(c) = cp.radii;
    for (std::size_t k = 0; k < valid.size(); ++k) {
      const Eigen::Index i = c + static_cast<Eigen::Index>(k);
      points.row(i) = ends.centers.row(valid[k]);
      radii[i] = ends.radii[valid[k]];
      prong[i] = valid[k];
    }
    // A prong whose peak no stage-1 ball sees (a thin, curled tip) still gets its end point:
    // the middle of the inward chord from its peak.
    std::vector<std::pair<Eigen::Vector3d, double>> extra;
    std::vector<int> extra_prong;
    for (Eigen::Index e = 0; e < ends.ball.size(); ++e) {
      if (ends.ball[e] >= 0) continue;
      double r = 0;
      // Toward the nearest domain point.
      const Eigen::Vector3d peak = prongs_->prongs.positions.row(e).transpose();
      const Points& centers = domain_->balls.centers;
      Eigen::Vector3d toward = peak;
      double best = std::numeric_limits<double>::infinity();
      for (Eigen::Index i = 0; i < centers.rows(); ++i) {
        const double d = (centers.row(i).transpose() - peak).squaredNorm();
        if (d < best) {
          best = d;
          toward = centers.row(i).transpose();
        }
      }
      Eigen::Vector3d p = inward_point(pm.working, query(), prongs_->prongs.vertices[e], toward, &r);
      // A tip that folded through itself (vertex noise on a thin tentacle) defeats the inside
      // tests right at the peak: the first point inside (by the distance's sign and by ray
      // parity) on the chord toward the nearest domain point.
      for (int k = 1; k <= 10 && !(r > 0); ++k) {
        const Eigen::Vector3d q = peak + 0.05 * k * (toward - peak);
        if (query().inside(q) && query().inside_by_parity(q)) {
          p = q;
          r = query().distance(q);
        }
      }
      // A tip crumpled by noise all around its peak (octopus-low's tentacles, perturbed): the
      // same inward chords from the working-mesh vertices within 0.03 of the peak, nearest
      // first; the first one inside by both tests.
      if (!(r > 0)) {
        std::vector<std::pair<double, int>> near;
        for (Eigen::Index v = 0; v < pm.working.V.rows(); ++v) {
          const double d = (pm.working.V.row(v).transpose() - peak).norm();
          if (d < 0.03) near.emplace_back(d, static_cast<int>(v));
        }
        std::sort(near.begin(), near.end());
        for (const auto& candidate : near) {
          double rv = 0;
          const Eigen::Vector3d q = inward_point(pm.working, query(), candidate.second, toward, &rv);
          if (rv > 0 && query().inside_by_parity(q)) {
            p = q;
            r = rv;
            break;
          }
        }
      }
      if (r > 0) {
        extra.emplace_back(p, r);
        extra_prong.push_back(static_cast<int>(e));
      }
    }
    if (!extra.empty()) {
      const Eigen::Index old = points.rows(), add = static_cast<Eigen::Index>(extra.size());
      points.conservativeResize(old + add, 3);
      radii.conservativeResize(old + add);
      prong.conservativeResize(old + add);
      for (Eigen::Index k = 0; k < add; ++k) {
        points.row(old + k) = extra[k].first.transpose();
        radii[old + k] = extra[k].second;
        prong[old + k] = extra_prong[k];
      }
    }
    graph_ = compute_domain_graph(pm.working, force_field(), points, radii, prong, pm.genus);
    timed("domain_graph", now_seconds() - t0);
  }
  return *graph_;
}

const Remapped& Extractor::remap() {
  if (!remapped_) {
    const DomainGraph& g = domain_graph();
    const ConnectionPoints& cp = connection_points();
    progress_.report("remap", 0.9);
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
    RemapOptions ro;
    ro.snake_iterations = options_.snake_iterations;
    // A link that leaves the shape where the waypoints hold no way round (a thin plate, such as
    // a cow's ear at the input's own resolution, has few stage-1 balls) tries again with one
    // more waypoint behind every face: the middle of its inward chord.
    const SurfaceQuery& surface = query();
    remapped_ = remap_links(nodes, radii, g.links, force_field(), waypoints, ro,
                            [&] { return chord_midpoints(prepared_->working, surface); });
    timed("remap", now_seconds() - t0);
  }
  return *remapped_;
}

void Extractor::finish(Skeleton& s) {
  const PreparedMesh& pm = *prepared_;
  for (Eigen::Index i = 0; i < s.positions.rows(); ++i) s.positions.row(i) = pm.to_input(s.positions.row(i));
  for (auto& polyline : s.polylines) {
    for (Eigen::Index i = 0; i < polyline.rows(); ++i) polyline.row(i) = pm.to_input(polyline.row(i));
  }
  s.radii *= pm.scale;
  // Working-mesh face labels -> input faces: the label most of the face's vertices map to.
  const Eigen::VectorXi working_labels = s.face_labels;
  s.face_labels = Eigen::VectorXi::Constant(F_.rows(), -1);
  if (working_labels.size() == pm.working.F.rows() && pm.map_face.size() == V_.rows()) {
    for (Eigen::Index f = 0; f < F_.rows(); ++f) {
      int label[3];
      for (int k = 0; k < 3; ++k) {
        const int wf = pm.map_face[F_(f, k)];
        label[k] = wf >= 0 && wf < working_labels.size() ? working_labels[wf] : -1;
      }
      int best = label[0];
      if (label[1] == label[2] && label[1] >= 0) best = label[1];
      if (best < 0) best = label[1] >= 0 ? label[1] : label[2];
      s.face_labels[f] = best;
    }
  }
  s.input_vertices = static_cast<int>(V_.rows());
  s.input_faces = static_cast<int>(F_.rows());
  s.genus = pm.genus;
  s.repaired = pm.repaired;
  s.timings = timings_;
  double total = 0;
  for (const auto& t : timings_) total += t.second;
  s.timings.emplace_back("total", total);
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
      progress_.report("skeleton", 0.97);
      const double t0 = now_seconds();
      const DomainGraph& g = *graph_;
      if (g.nodes.empty()) throw std::runtime_error("stage 6 kept no node");
      s = assemble_skeleton(g, remapped, prongs_->prongs.significance);
      // The working mesh of a remeshed input may bulge out of it in concave places: hold the
      // skeleton to the input's own surface when that is closed (else to the working mesh).
      const PreparedMesh& pm = *prepared_;
      if (pm.remeshed && !pm.repaired && pm.report.closed_manifold()) {
        Mesh normalized;
        normalized.V.resize(V_.rows(), 3);
        for (Eigen::Index i = 0; i < V_.rows(); ++i) normalized.V.row(i) = (V_.row(i) - pm.offset) / pm.scale;
        normalized.F = F_;
        // Millions of input faces take a second or more: polled for cancellation.
        const auto poll = internal::throttled_poll(progress_, "skeleton", 0.97);
        const SurfaceQuery input_surface(normalized, poll);
        keep_inside(s, input_surface, poll);
      } else {
        keep_inside(s, query(), internal::throttled_poll(progress_, "skeleton", 0.97));
      }
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
