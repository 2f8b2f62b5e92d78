// Internal (not installed): stage 0's repair of fins and inner walls, the zero-volume sheets
// that game meshes hang on their closed parts along non-manifold edges (a wing made of one quad,
// a disc closing an eye socket from inside). See fins.cpp.
#pragma once

#include <functional>
#include <optional>

#include "dcg/types.h"

namespace dcg::internal {

/// What drop_fins kept.
struct FinlessMesh {
  Mesh mesh;              ///< the input without its fins, on the vertices those faces use
  int dropped_faces = 0;  ///< faces of the fins
};

/// The mesh without its fins when what is left is made of closed manifold parts (every edge in
/// exactly two faces), else nullopt (nothing to do, or the non-manifold edges are not fins).
/// A fin is a set of faces, connected over edges of two faces, that meets the rest along edges
/// of three or more faces and leaves every such edge with at least two faces when taken away;
/// fins go one at a time, the smallest area first, so that of a wall and the shell it divides the
/// wall goes. At most half of the surface's area is dropped.
///   mesh  #V by 3 vertices, #F by 3 faces
/// `poll` (if set) is called once per fin; it may throw (Cancelled).
std::optional<FinlessMesh> drop_fins(const Mesh& mesh, const std::function<void()>& poll = {});

}  // namespace dcg::internal
