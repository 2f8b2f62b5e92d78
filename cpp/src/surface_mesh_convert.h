// Internal (not installed): a triangle CGAL::Surface_mesh back to our Mesh, shared by the CGAL
// translation units of stage 0 (remesh.cpp, repair.cpp). Include it only from those: it pulls in
// CGAL's Surface_mesh.
#pragma once

#include <string>
#include <vector>

#include <CGAL/Surface_mesh.h>

#include "dcg/errors.h"
#include "dcg/types.h"

namespace dcg::internal {

/// The vertices of `sm` in its order (removed ones skipped) and its faces, which must all be
/// triangles: InputError "<what> is not a triangle mesh" otherwise.
template <class Point>
Mesh mesh_from_surface_mesh(const CGAL::Surface_mesh<Point>& sm, const std::string& what) {
  Mesh out;
  out.V.resize(sm.number_of_vertices(), 3);
  std::vector<int> index(sm.num_vertices(), -1);
  int n = 0;
  for (auto v : sm.vertices()) {
    const Point& p = sm.point(v);
    out.V.row(n) << p.x(), p.y(), p.z();
    index[v.idx()] = n++;
  }
  out.F.resize(sm.number_of_faces(), 3);
  int f = 0;
  for (auto face : sm.faces()) {
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(face), sm)) {
      if (k < 3) out.F(f, k) = index[v.idx()];
      ++k;
    }
    if (k != 3) throw InputError(what + " is not a triangle mesh");
    ++f;
  }
  return out;
}

}  // namespace dcg::internal
