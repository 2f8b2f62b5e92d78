// Internal (not installed): the CGAL alpha wrap behind stage 0's repair. Kept in its own
// translation unit (repair.cpp) because it takes ~40 s to compile.
#pragma once

#include <functional>

#include "dcg/types.h"

namespace dcg::internal {

/// CGAL::alpha_wrap_3 of the triangle soup (V, F): a closed, oriented 2-manifold around it.
/// `alpha` (ball radius) and `offset` (distance of the wrap from the input) are in the units of V.
/// Throws InputError when the wrap fails or comes back empty.
/// `poll` (if set) is called every 10 ms, from the calling thread, with a rough fraction done
/// while the wrap runs on a worker thread; it may throw (Cancelled): the call then returns at
/// once and the abandoned wrap stops by itself at its next check.
Mesh alpha_wrap(const Mesh& soup, double alpha, double offset,
                const std::function<void(double)>& poll = {});

}  // namespace dcg::internal
