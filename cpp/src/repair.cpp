// CGAL alpha wrap for stage 0's repair. See repair.h.
#include "repair.h"

#include <array>
#include <atomic>
#include <exception>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>

#include "dcg/errors.h"
#include "polling.h"
#include "surface_mesh_convert.h"

namespace dcg::internal {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;

// Thrown inside the worker (never outside this file) to stop a wrap nobody waits for any more.
struct WrapAbandoned {};

// One wrap on a worker thread. It owns its input and output, so that it can outlive the call
// that started it: see alpha_wrap.
struct WrapJob {
  std::vector<Point> points;
  std::vector<std::array<std::size_t, 3>> faces;
  double alpha = 0, offset = 0;
  CGAL::Surface_mesh<Point> wrap;
  std::exception_ptr error;
  std::atomic<bool> abandon{false};
  std::atomic<double> fraction{0};  // rough: 0 during the flood fill, 0.9 after it
  Completion finished;
};

// Records the wrap's progress for the waiting thread and stops the wrap once it is abandoned
// (the visitor's calls come before each facet the flood fill treats, and at its end).
struct PollingVisitor : CGAL::Alpha_wraps_3::internal::Wrapping_default_visitor {
  WrapJob* job = nullptr;
  template <typename Wrapper, typename Gate>
  void before_facet_treatment(const Wrapper&, const Gate&) {
    if (job->abandon.load(std::memory_order_relaxed)) throw WrapAbandoned();
  }
  template <typename Wrapper>
  void on_flood_fill_end(const Wrapper&) {
    job->fraction = 0.9;
    if (job->abandon.load(std::memory_order_relaxed)) throw WrapAbandoned();
  }
};

void run_wrap(WrapJob& job) {
  try {
    PollingVisitor visitor;
    visitor.job = &job;
    CGAL::alpha_wrap_3(job.points, job.faces, job.alpha, job.offset, job.wrap,
                       CGAL::parameters::default_values(), CGAL::parameters::visitor(visitor));
  } catch (const WrapAbandoned&) {
  } catch (...) {
    job.error = std::current_exception();
  }
}

}  // namespace

Mesh alpha_wrap(const Mesh& soup, double alpha, double offset,
                const std::function<void(double)>& poll) {
  auto job = std::make_shared<WrapJob>();
  job->alpha = alpha;
  job->offset = offset;
  job->points.reserve(soup.V.rows());
  for (Eigen::Index i = 0; i < soup.V.rows(); ++i) {
    job->points.emplace_back(soup.V(i, 0), soup.V(i, 1), soup.V(i, 2));
  }
  job->faces.reserve(soup.F.rows());
  for (Eigen::Index f = 0; f < soup.F.rows(); ++f) {
    job->faces.push_back({static_cast<std::size_t>(soup.F(f, 0)),
                          static_cast<std::size_t>(soup.F(f, 1)),
                          static_cast<std::size_t>(soup.F(f, 2))});
  }
  if (!poll) {
    run_wrap(*job);
  } else {
    // CGAL builds its AABB tree and seeds its triangulation before the visitor's first call,
    // and extracts the surface after its last: 3.2 s and 1.2 s without a call on a 1.4M-face
    // open scan, too long to keep a cancel waiting (0.5 s at most). So the wrap runs on a worker
    // thread while this one polls every 10 ms. On a cancel the job is marked abandoned and left
    // to stop at the visitor's next call on its own (it owns its data through the shared
    // pointer); this thread rethrows at once. `poll` is only ever called from this thread.
    std::thread([job] {
      run_wrap(*job);
      job->finished.set();
    }).detach();
    try {
      job->finished.wait_polling([&] { poll(job->fraction); });
    } catch (...) {
      job->abandon = true;
      throw;
    }
  }
  if (job->error) std::rethrow_exception(job->error);
  if (poll) poll(1.0);
  const CGAL::Surface_mesh<Point>& wrap = job->wrap;
  if (wrap.number_of_faces() < 4) {
    throw InputError("repair failed: the alpha wrap (alpha " + std::to_string(alpha) +
                     ") of the mesh is empty");
  }
  return mesh_from_surface_mesh(wrap, "repair failed: the alpha wrap");
}

}  // namespace dcg::internal
