// Internal (not installed): the connectivity of a triangle mesh, as stage 0 needs it to decide
// whether the input is a closed manifold (and to tell the user what is wrong when it is not), to
// orient it outward and to find flat folds. dcg::mesh_genus (declared in dcg/prepare.h) is
// defined in mesh_topology.cpp as well, and face_barycentric (points carried between meshes).
#pragma once

#include <array>
#include <functional>
#include <utility>
#include <vector>

#include "dcg/types.h"

namespace dcg::internal {

/// What analyze_topology finds in a triangle mesh. Edges are undirected vertex pairs (by index:
/// coinciding vertices with different indices are different vertices).
struct Topology {
  int edges = 0;                  ///< undirected edges
  int border_edges = 0;           ///< edges with one incident face
  int border_loops = 0;           ///< connected sets of border edges (holes)
  int non_manifold_edges = 0;     ///< edges with more than two incident faces
  int non_manifold_vertices = 0;  ///< vertices whose faces form several fans (pinched)
  int components = 0;             ///< connected components of faces over shared edges
  double largest_hole = 0;        ///< bounding-box diagonal of the largest border loop
  /// #F by 3: the face across the edge from F(f, k) to F(f, k + 1) of face f (as F was when
  /// analyzed), -1 when that edge does not have exactly two faces.
  std::vector<std::array<int, 3>> neighbours;
  /// #F: the component of each face, 0 .. components - 1, numbered in order of first face.
  std::vector<int> component;
};

/// Counts the edges, border edges and loops, non-manifold edges and vertices and the components
/// of the triangle mesh (V, F), and records the faces' manifold neighbours for orient_outward.
///   V  #V by 3 vertex positions (only used for the extent of the holes)
///   F  #F by 3 face indices into V
/// `poll` (if set) is called every few thousand edges or vertices; it may throw to stop.
Topology analyze_topology(const Vertices& V, const Faces& F,
                          const std::function<void()>& poll = {});

/// What orient_outward did.
struct Orientation {
  /// The faces could be oriented consistently over the manifold edges (false: a Moebius strip
  /// or the like; some faces are then left inconsistent).
  bool orientable = true;
  /// Sum over the components of |signed volume| (divergence theorem): about zero for a closed
  /// surface that folds flat onto itself, meaningless for an open one.
  double enclosed_volume = 0;
};

/// Makes the orientation of the faces consistent over manifold edges, by breadth-first search
/// from the first face of each component, then flips every component whose signed volume is
/// negative, so that closed components face outward.
///   V  #V by 3 vertex positions
///   F  #F by 3 face indices into V, reordered in place (two corners of a face swapped)
///   topology  analyze_topology(V, F) of the same F
/// `poll` (if set) is called every few thousand faces; it may throw to stop.
Orientation orient_outward(const Vertices& V, Faces& F, const Topology& topology,
                           const std::function<void()>& poll = {});

/// Removes the cavities of a closed, consistently oriented mesh: its components whose signed
/// volume is negative, inner shells that face inward (the walls of a void that the solid
/// encloses), unless no other component would be left. Returns how many it removed.
///   mesh  V #V by 3, F #F by 3; the vertices that only the cavities used go with them
int drop_cavities(Mesh& mesh);

/// The number of edges of a closed, consistently oriented mesh whose two faces fold flat onto
/// each other: their unit normals opposite to within 1e-8 (a dihedral angle of about 1e-4 rad
/// or less). mesh: V #V by 3, F #F by 3.
int folded_edges(const Mesh& mesh);

/// Holes of a mesh: border_edges as vertex pairs (indices into V, #V by 3) grouped into
/// connected loops. Returns (number of loops, bounding-box diagonal of the largest loop).
std::pair<int, double> border_loops(const Vertices& V,
                                    const std::vector<std::pair<int, int>>& border_edges);

/// Barycentric coordinates of q (a point on face f of `mesh`) in that face, clamped into the
/// triangle; (1/3, 1/3, 1/3) on a degenerate face.
Eigen::Vector3d face_barycentric(const Mesh& mesh, int f, const Eigen::Vector3d& q);

}  // namespace dcg::internal
