// Holding the skeleton inside the input surface (dcg/keep_inside.h).
#include "dcg/keep_inside.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "dcg/force_field.h"
#include "dcg/surface_query.h"
#include "polling.h"

namespace dcg {
namespace {

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
  std::function<void(const Eigen::RowVector3d&, const Eigen::RowVector3d&, double, double, int)>
      refine = [&](const Eigen::RowVector3d& p, const Eigen::RowVector3d& q, double tp, double tq,
                   int depth) {
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

}  // namespace

void keep_inside(Skeleton& s, const SurfaceQuery& surface, const Progress& progress, double from,
                 double to) {
  internal::ThrottledProgress tick(progress, "skeleton", from, to);
  const double steps = static_cast<double>(s.positions.rows() + s.links.rows());
  for (Eigen::Index i = 0; i < s.positions.rows(); ++i) {
    tick(i / steps);
    keep_point_inside(s.positions.row(i), s.radii[i], surface);
  }
  for (Eigen::Index l = 0; l < s.links.rows(); ++l) {
    tick((s.positions.rows() + l) / steps);
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

void keep_inside_input(Skeleton& s, const PreparedMesh& prepared, const Vertices& V, const Faces& F,
                       const SurfaceQuery& working_surface, const Progress& progress, double from,
                       double to) {
  // The surface to hold the skeleton in: the union of the input's parts when that was remeshed
  // (prepared.united is kept only then), the input itself when it is a remeshed closed manifold.
  Mesh input;
  const bool remeshed_input =
      prepared.remeshed && !prepared.repaired && prepared.report.closed_manifold();
  if (prepared.united.F.rows() == 0 && !remeshed_input) {
    keep_inside(s, working_surface, progress, from, to);
    return;
  }
  internal::ThrottledProgress tick(progress, "skeleton", from, to);
  tick(0);
  if (remeshed_input) {
    input.V.resize(V.rows(), 3);
    for (Eigen::Index i = 0; i < V.rows(); ++i) {
      input.V.row(i) = (V.row(i) - prepared.offset) / prepared.scale;
    }
    input.F = F;
  }
  // Millions of input faces take a second or more to index: polled for cancellation too.
  const SurfaceQuery surface(remeshed_input ? input : prepared.united, [&] { tick(0); });
  keep_inside(s, surface, progress, from + 0.5 * (to - from), to);
}

}  // namespace dcg
