// Stage 4: the repulsive force field. See dcg/force_field.h.
#include "dcg/force_field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "dcg/errors.h"
#include "dcg/options.h"
#include "dcg/surface_query.h"

namespace dcg {

Points fibonacci_sphere(int count) {
  Points d(std::max(count, 0), 3);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count, r = std::sqrt(std::max(0.0, 1.0 - z * z));
    d.row(i) << r * std::cos(golden * i), r * std::sin(golden * i), z;
  }
  return d;
}

ForceField::ForceField(std::shared_ptr<const SurfaceQuery> query, const ForceFieldOptions& options)
    : query_(std::move(query)), options_(options) {
  if (!query_) throw InputError("ForceField: no surface query");
  check_option("rays", options_.rays);
  check_option("force_exponent", options_.force_exponent);
  directions_ = fibonacci_sphere(options_.rays).cast<float>();
}

FieldSample ForceField::at(const Eigen::Vector3d& p) const { return sample(p, false); }

FieldSample ForceField::at_with_gradient(const Eigen::Vector3d& p) const { return sample(p, true); }

FieldSample ForceField::sample(const Eigen::Vector3d& p, bool gradient) const {
  const int k = options_.rays;
  // Small fans live on the stack; rays is at most 4096 (the option's range).
  double t_stack[256];
  unsigned char in_stack[256];
  int face_stack[256];
  std::vector<double> t_heap;
  std::vector<unsigned char> in_heap;
  std::vector<int> face_heap;
  double* t = t_stack;
  unsigned char* in = in_stack;
  int* faces = face_stack;
  if (k > 256) {
    t_heap.resize(k);
    in_heap.resize(k);
    face_heap.resize(k);
    t = t_heap.data();
    in = in_heap.data();
    faces = face_heap.data();
  }
  query_->ray_fan(p, directions_.data(), k, t, in, gradient ? faces : nullptr);
  FieldSample s;
  s.r_min = std::numeric_limits<double>::infinity();
  const double n = options_.force_exponent;
  const bool linear = n == 1.0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < k; ++i) {
    if (!in[i]) ++s.outside_rays;
    if (!std::isfinite(t[i])) continue;  // no wall in that direction: no force
    const double r = std::max(t[i], 1e-9);
    s.r_min = std::min(s.r_min, r);
    const double w = linear ? 1.0 / r : std::pow(r, -n);
    sum += w * directions_.row(i).transpose().cast<double>();
  }
  s.force = -sum / k;
  s.magnitude = s.force.norm();
  if (gradient && s.magnitude > 0) {
    // dF/dp = -(1/K) sum_k u_k (d r_k^-n / dp)^T = -(1/K) sum_k n r_k^(-n-1) u_k N_k^T / (u_k.N_k)
    // and grad |F| = (dF/dp)^T F / |F|.
    const Eigen::Vector3d unit = s.force / s.magnitude;
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (int i = 0; i < k; ++i) {
      if (!std::isfinite(t[i]) || faces[i] < 0) continue;
      const Eigen::Vector3d u = directions_.row(i).transpose().cast<double>();
      const Eigen::Vector3d& N = query_->face_normal(faces[i]);
      double un = u.dot(N);
      if (std::abs(un) < 0.2) un = un < 0 ? -0.2 : 0.2;
      const double r = std::max(t[i], 1e-9);
      const double w = n * (linear ? 1.0 / (r * r) : std::pow(r, -n - 1)) / un;
      g += w * u.dot(unit) * N;
    }
    s.gradient = -g / k;
  }
  return s;
}

FieldSamples ForceField::evaluate(const Points& points) const {
  const Eigen::Index count = points.rows();
  FieldSamples out;
  out.force.resize(count, 3);
  out.magnitude.resize(count);
  out.r_min.resize(count);
  out.outside_rays.resize(count);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, count, 16),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
                      for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
                        const FieldSample s = at(points.row(i).transpose());
                        out.force.row(i) = s.force.transpose();
                        out.magnitude[i] = s.magnitude;
                        out.r_min[i] = s.r_min;
                        out.outside_rays[i] = s.outside_rays;
                      }
                    });
  return out;
}

Eigen::VectorXd ForceField::magnitude_slopes(const Eigen::Vector3d& p,
                                             const std::vector<Eigen::Vector3d>& axes,
                                             double h) const {
  Eigen::VectorXd g(static_cast<Eigen::Index>(axes.size()));
  for (std::size_t i = 0; i < axes.size(); ++i) {
    const double plus = at(p + h * axes[i]).magnitude, minus = at(p - h * axes[i]).magnitude;
    g[static_cast<Eigen::Index>(i)] = (plus - minus) / (2 * h);
  }
  return g;
}

double ForceField::mean_magnitude(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int samples,
                                  bool* all_inside) const {
  samples = std::max(samples, 1);
  double sum = 0;
  bool inside = true;
  for (int i = 1; i <= samples; ++i) {
    const double t = static_cast<double>(i) / (samples + 1);
    const FieldSample s = at((1 - t) * a + t * b);
    sum += s.magnitude;
    inside = inside && s.inside();
  }
  if (all_inside) *all_inside = inside;
  return sum / samples;
}

}  // namespace dcg
