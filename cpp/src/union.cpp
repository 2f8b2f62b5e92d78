// The union of a mesh's closed parts for stage 0. See union.h.
//
// Why: multi-part characters (a body with detached eyes, game meshes whose limbs are separate
// closed shells pushed into the torso) are closed manifolds part by part, and the alpha wrap that
// repairs them at 1/100 of the diagonal took 2-4 s on 2k-5k faces (Q_Spider, Q_Snake): it
// rebuilds the whole surface from a Delaunay refinement of about 15,000 faces. Their union by
// corefinement takes 10-60 ms there and keeps the input's own surface (nothing offset, thin limbs
// and the gaps between them exactly as modelled).
#include "union.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <exception>
#include <functional>
#include <iterator>
#include <optional>
#include <utility>
#include <vector>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/centroid.h>
#include <tbb/parallel_for.h>

#include "canonical_order.h"
#include "dcg/errors.h"
#include "mesh_topology.h"
#include "surface_mesh_convert.h"
#include "union_find.h"

namespace dcg::internal {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using SM = CGAL::Surface_mesh<Point>;
// Exact constructions, for a union whose rounded intersection points crossed (see unite_exactly).
using EK = CGAL::Exact_predicates_exact_constructions_kernel;
using ESM = CGAL::Surface_mesh<EK::Point_3>;

// Whether triangles s and t cross each other (more than touch at a point they share: the copies
// of a split pinched vertex): each shrunk by 1e-7 about its centroid still intersects the other.
bool cross(const K::Triangle_3& s, const K::Triangle_3& t) {
  const auto shrunk = [](const K::Triangle_3& u) {
    const Point c = CGAL::centroid(u);
    const auto in = [&](const Point& p) { return p + (c - p) * 1e-7; };
    return K::Triangle_3(in(u[0]), in(u[1]), in(u[2]));
  };
  return CGAL::do_intersect(shrunk(s), t) || CGAL::do_intersect(s, shrunk(t));
}

// Whether `sm` intersects itself other than where copies of one point touch.
bool crosses_itself(const SM& sm) {
  std::vector<std::pair<SM::Face_index, SM::Face_index>> pairs;
  PMP::self_intersections(faces(sm), sm, std::back_inserter(pairs));
  const auto triangle = [&](SM::Face_index f) {
    const SM::Halfedge_index h = sm.halfedge(f);
    return K::Triangle_3(sm.point(sm.source(h)), sm.point(sm.target(h)),
                         sm.point(sm.target(sm.next(h))));
  };
  for (const auto& [f, g] : pairs) {
    const K::Triangle_3 s = triangle(f), t = triangle(g);
    bool share = false;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) share = share || s[i] == t[j];
    if (!share || cross(s, t)) return true;
  }
  return false;
}

// Whether `part` is closed and encloses a volume; turned outward in place. (Whether it crosses
// itself matters only when it is to be united with another part: a closed part on its own is
// kept as it is, like a closed input that crosses itself a little, cow.off.)
bool closed_solid(SM& part) {
  if (!CGAL::is_closed(part) || !CGAL::is_triangle_mesh(part)) return false;
  if (!PMP::is_outward_oriented(part)) PMP::reverse_face_orientations(part);
  return PMP::volume(part) > 0;
}

// The faces of `mesh` as a soup in which each pinched vertex (several fans of faces around it)
// has one copy per fan: every edge must have two faces (no border, no non-manifold edge).
void split_pinched_vertices(const Mesh& mesh, std::vector<Point>& points,
                            std::vector<std::array<std::size_t, 3>>& faces) {
  const int nv = static_cast<int>(mesh.V.rows()), nf = static_cast<int>(mesh.F.rows());
  points.clear();
  for (int i = 0; i < nv; ++i) points.emplace_back(mesh.V(i, 0), mesh.V(i, 1), mesh.V(i, 2));
  // Corners c = 3 f + k around each vertex; two corners at one vertex are in one fan when their
  // faces share an edge there (the vertex after it in one face is the one before it in the other,
  // as the faces are oriented).
  std::vector<std::vector<int>> corners(nv);
  for (int c = 0; c < 3 * nf; ++c) corners[mesh.F(c / 3, c % 3)].push_back(c);
  faces.resize(nf);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) faces[f][k] = static_cast<std::size_t>(mesh.F(f, k));
  for (int v = 0; v < nv; ++v) {
    const std::vector<int>& around = corners[v];
    UnionFind fans(static_cast<int>(around.size()));
    for (std::size_t a = 0; a < around.size(); ++a)
      for (std::size_t b = 0; b < around.size(); ++b) {
        const int fa = around[a] / 3, ka = around[a] % 3, fb = around[b] / 3, kb = around[b] % 3;
        if (mesh.F(fa, (ka + 1) % 3) == mesh.F(fb, (kb + 2) % 3)) {
          fans.unite(static_cast<int>(a), static_cast<int>(b));
        }
      }
    std::vector<std::size_t> copy(around.size(), 0);
    const int first = fans.find(0);
    for (std::size_t a = 0; a < around.size(); ++a) {
      const int root = fans.find(static_cast<int>(a));
      if (root == first) continue;
      if (copy[root] == 0) {
        copy[root] = points.size();
        points.push_back(points[v]);
      }
      faces[around[a] / 3][around[a] % 3] = copy[root];
    }
  }
}

// Groups of parts whose bounding boxes overlap (transitively): only these can intersect.
std::vector<std::vector<std::size_t>> overlapping_groups(const std::vector<SM>& parts) {
  std::vector<CGAL::Bbox_3> boxes;
  boxes.reserve(parts.size());
  for (const SM& p : parts) boxes.push_back(PMP::bbox(p));
  UnionFind uf(static_cast<int>(parts.size()));
  for (std::size_t i = 0; i < parts.size(); ++i)
    for (std::size_t j = i + 1; j < parts.size(); ++j)
      if (CGAL::do_overlap(boxes[i], boxes[j])) uf.unite(static_cast<int>(i), static_cast<int>(j));
  std::vector<std::vector<std::size_t>> groups(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    groups[uf.find(static_cast<int>(i))].push_back(i);
  }
  groups.erase(
      std::remove_if(groups.begin(), groups.end(), [](const auto& g) { return g.empty(); }),
      groups.end());
  return groups;
}

// Whether test(part) holds for every part; the parts are tested in parallel (each test changes
// only its own part).
template <class Test>
bool all_of_parts(std::vector<SM>& parts, Test test) {
  std::atomic<bool> all{true};
  tbb::parallel_for(std::size_t{0}, parts.size(), [&](std::size_t i) {
    if (all.load(std::memory_order_relaxed) && !test(parts[i])) all = false;
  });
  return all;
}

// The union of `parts` by corefinement, pairwise in rounds (1+2, 3+4, ... then the results),
// each round's pairs in parallel and `poll` called between rounds (from this thread only):
// about half the time of uniting them one after the other into a growing mesh on 2 cores
// (biped-30k, 8 parts). nullopt when a corefinement fails; CGAL's exceptions are passed on.
template <class Surface>
std::optional<Surface> unite_all(std::vector<Surface> level,
                                 const std::function<void(double)>& poll) {
  double round = 0;
  while (level.size() > 1) {
    poll(0.3 + 0.6 * (1 - 1 / (1 + ++round)));
    const std::size_t pairs = level.size() / 2;
    std::vector<Surface> next(pairs);
    std::vector<char> ok(pairs, 0);
    std::vector<std::exception_ptr> error(pairs);
    tbb::parallel_for(std::size_t{0}, pairs, [&](std::size_t p) {
      try {
        ok[p] = PMP::corefine_and_compute_union(level[2 * p], level[2 * p + 1], next[p]);
      } catch (...) {
        error[p] = std::current_exception();
      }
    });
    for (const auto& e : error)
      if (e) std::rethrow_exception(e);
    if (std::find(ok.begin(), ok.end(), 0) != ok.end()) return std::nullopt;
    if (level.size() % 2) next.push_back(std::move(level.back()));
    level = std::move(next);
  }
  return std::move(level.front());
}

// `from` with each point converted (the same vertices and faces, in order).
template <class To, class From, class Convert>
To with_points(const From& from, Convert convert) {
  To to;
  std::size_t size = 0;  // vertex indices run up to the removed ones' too
  for (const auto v : from.vertices()) size = std::max<std::size_t>(size, v.idx() + 1);
  std::vector<typename To::Vertex_index> at(size);
  for (const auto v : from.vertices()) at[v.idx()] = to.add_vertex(convert(from.point(v)));
  std::vector<typename To::Vertex_index> corners;
  for (const auto f : from.faces()) {
    corners.clear();
    for (const auto v : CGAL::vertices_around_face(from.halfedge(f), from))
      corners.push_back(at[v.idx()]);
    to.add_face(corners);
  }
  return to;
}

// The union of `parts` (unite_all) with exact constructions, its points then rounded to
// doubles. Corefinement with inexact constructions rounds each intersection point where it is
// made, and where parts meet at grazing angles the rounded edges may cross (Mannequiny's 59
// parts once its coordinates are rounded to float32, as every Blender mesh is: its union crossed
// itself, and the wrap that replaced it smoothed its fingers away); exact points are only rounded
// at the end. Several times slower, so only where the fast union failed.
std::optional<SM> unite_exactly(const std::vector<SM>& parts,
                                const std::function<void(double)>& poll) {
  std::vector<ESM> exact;
  exact.reserve(parts.size());
  for (const SM& part : parts)
    exact.push_back(
        with_points<ESM>(part, [](const Point& p) { return EK::Point_3(p.x(), p.y(), p.z()); }));
  std::optional<ESM> united = unite_all(std::move(exact), poll);
  if (!united) return std::nullopt;
  return with_points<SM>(*united, [](const EK::Point_3& p) {
    return Point(CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z()));
  });
}

// unite_all with inexact constructions; nullopt also where CGAL threw (a degenerate
// configuration of rounded points: unite_exactly may still take it).
std::optional<SM> fast_union(const std::vector<SM>& parts,
                             const std::function<void(double)>& poll) {
  try {
    return unite_all(parts, poll);
  } catch (const Cancelled&) {
    throw;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// Whether a union of `count` parts came out a closed surface that does not cross itself.
bool sound_union(const std::optional<SM>& united, std::size_t count) {
  return united && (count < 2 || (CGAL::is_closed(*united) && !crosses_itself(*united)));
}

// The soup (points, faces) as a Surface_mesh; nullopt when it is no polygon mesh.
std::optional<SM> soup_mesh(const std::vector<Point>& points,
                            const std::vector<std::array<std::size_t, 3>>& faces) {
  if (!PMP::is_polygon_soup_a_polygon_mesh(faces)) return std::nullopt;
  SM sm;
  PMP::polygon_soup_to_polygon_mesh(points, faces, sm);
  return sm;
}

// `mesh` as a Surface_mesh (its faces as they are; nullopt when they are no polygon mesh).
std::optional<SM> surface_mesh(const Mesh& mesh) {
  std::vector<Point> points;
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i)
    points.emplace_back(mesh.V(i, 0), mesh.V(i, 1), mesh.V(i, 2));
  std::vector<std::array<std::size_t, 3>> faces(static_cast<std::size_t>(mesh.F.rows()));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) faces[f][k] = static_cast<std::size_t>(mesh.F(f, k));
  return soup_mesh(points, faces);
}

// The most of the parts to be united that may cross themselves and be wrapped one by one: a few
// that a noise or a rounding crossed where their faces nearly touch (Mannequiny's head, 1 of
// 59; Q_Male_Casual's body, 1 of 7). When more cross, the whole surface is rough (the bench's
// 0.3% noise crossed 13 of Q_Spider's 15 parts, 6 of Q_Wasp's 13), and the union of their wraps
// kept tunnels between them (a loop in Q_Spider's skeleton) that the wrap of the whole closes.
constexpr double kMostRewrapped = 0.25;

// Each part that is to be united with another (its bounding box overlaps another's) and
// crosses itself replaced by rewrap(part), turned outward: how many, or -1 when more than
// kMostRewrapped of those parts cross themselves or a replacement is no closed solid. The parts
// are tested in parallel.
int rewrap_crossing_parts(std::vector<SM>& parts, const PartWrap& rewrap) {
  std::vector<char> crossing(parts.size(), 0);
  std::size_t united = 0;
  for (const auto& group : overlapping_groups(parts)) {
    if (group.size() < 2) continue;
    united += group.size();
    tbb::parallel_for(std::size_t{0}, group.size(),
                      [&](std::size_t k) { crossing[group[k]] = crosses_itself(parts[group[k]]); });
  }
  const auto crossed = static_cast<double>(std::count(crossing.begin(), crossing.end(), 1));
  if (crossed > kMostRewrapped * static_cast<double>(united)) return -1;
  int count = 0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (!crossing[i]) continue;
    std::optional<SM> wrapped = surface_mesh(rewrap(mesh_from_surface_mesh(parts[i], "a part")));
    if (!wrapped || !closed_solid(*wrapped)) return -1;
    parts[i] = std::move(*wrapped);
    ++count;
  }
  return count;
}

}  // namespace

std::optional<United> union_of_closed_parts(const Mesh& mesh,
                                            const std::function<void(double)>& poll_in,
                                            const PartWrap& rewrap) {
  const std::function<void(double)> poll = poll_in ? poll_in : [](double) {};
  std::vector<Point> points;
  std::vector<std::array<std::size_t, 3>> faces;
  split_pinched_vertices(mesh, points, faces);
  std::optional<SM> whole = soup_mesh(points, faces);
  if (!whole) return std::nullopt;
  poll(0.1);
  std::vector<SM> parts;
  PMP::split_connected_components(*whole, parts);
  if (!all_of_parts(parts, closed_solid)) return std::nullopt;
  poll(0.3);
  std::vector<Mesh> shells;
  int rewrapped = 0;
  try {
    if (rewrap) {
      rewrapped = rewrap_crossing_parts(parts, rewrap);
      if (rewrapped < 0) return std::nullopt;
    }
    for (const auto& group : overlapping_groups(parts)) {
      std::vector<SM> level;
      for (std::size_t i : group) level.push_back(std::move(parts[i]));
      // Corefinement needs parts that do not cross themselves (rewrap_crossing_parts saw to it).
      if (!rewrap && level.size() > 1 &&
          !all_of_parts(level, [](SM& p) { return !crosses_itself(p); }))
        return std::nullopt;
      std::optional<SM> united = fast_union(level, poll);
      if (!sound_union(united, group.size())) united = unite_exactly(level, poll);
      if (!sound_union(united, group.size())) return std::nullopt;
      shells.push_back(mesh_from_surface_mesh(*united, "the union of the parts"));
    }
  } catch (const Cancelled&) {
    throw;
  } catch (const std::exception&) {
    // CGAL's corefinement throws on input it cannot take (a self-intersection it found, a
    // degenerate configuration): the caller wraps instead.
    return std::nullopt;
  }
  poll(0.9);
  Mesh out;
  Eigen::Index nv = 0, nf = 0;
  for (const Mesh& s : shells) {
    nv += s.V.rows();
    nf += s.F.rows();
  }
  out.V.resize(nv, 3);
  out.F.resize(nf, 3);
  nv = nf = 0;
  for (const Mesh& s : shells) {
    out.V.middleRows(nv, s.V.rows()) = s.V;
    out.F.middleRows(nf, s.F.rows()) = s.F.array() + static_cast<int>(nv);
    nv += s.V.rows();
    nf += s.F.rows();
  }
  United united;
  united.rewrapped = rewrapped;
  united.cavities = drop_cavities(out);
  // CGAL's corefinement does not keep one order: its box intersection draws from CGAL's shared
  // random generator, so Q_Spider's union came out in a different order in every call, and the
  // remeshing after it, and so the skeleton, followed the order (123 to 139 nodes).
  united.mesh = canonical_order(out);
  return united;
}

std::optional<FilledMesh> fill_holes(const Mesh& mesh, int max_edges) {
  std::optional<SM> input = surface_mesh(mesh);
  if (!input) return std::nullopt;
  SM& sm = *input;
  std::vector<SM::Halfedge_index> cycles;
  PMP::extract_boundary_cycles(sm, std::back_inserter(cycles));
  if (cycles.empty()) return std::nullopt;
  // Every hole small enough first, so that a large one leaves the mesh untouched.
  for (const SM::Halfedge_index start : cycles)
    if (static_cast<int>(CGAL::halfedges_around_face(start, sm).size()) > max_edges)
      return std::nullopt;
  FilledMesh out;
  try {
    for (const SM::Halfedge_index start : cycles) {
      std::vector<SM::Face_index> patch;
      PMP::triangulate_hole(sm, start, std::back_inserter(patch));
      if (patch.empty()) return std::nullopt;
      ++out.holes;
    }
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (!CGAL::is_closed(sm)) return std::nullopt;
  out.mesh = mesh_from_surface_mesh(sm, "the mesh with its holes filled");
  return out;
}

}  // namespace dcg::internal
