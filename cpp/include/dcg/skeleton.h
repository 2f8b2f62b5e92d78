// Stage 8 (ALGORITHM.md "Skeleton"): the result the rest of the project consumes.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dcg/types.h"

namespace dcg {

class SurfaceQuery;

struct DomainGraph;
struct PreparedMesh;
struct Remapped;

enum class NodeKind { End, Joint, Connection };

/// "end", "joint" or "connection": the names used in Python, JSON and Blender.
const char* node_kind_name(NodeKind kind);

/// A node's kind from its number of links: 1 end, 3 or more joint, else connection.
NodeKind node_kind_of_degree(std::size_t degree);

/// The skeleton in the INPUT's coordinates.
struct Skeleton {
  Points positions;               ///< #N by 3 node positions
  std::vector<NodeKind> kinds;    ///< #N kinds
  Eigen::VectorXd radii;          ///< #N distance from each node to the surface
  Eigen::VectorXd significance;   ///< #N prong ratio s/p for ends (lower = stronger), else 0
  Edges links;                    ///< #L by 2 node index pairs
  std::vector<Points> polylines;  ///< #L polylines, each from links(l,0) to links(l,1) inclusive
  /// #L: the distance from each point of each polyline to the surface (the working mesh's, as
  /// the nodes' radii), where the shape narrows between nodes (a neck, a wrist); empty when not
  /// measured (a document written before they were kept).
  std::vector<Eigen::VectorXd> polyline_radii;
  int root = -1;                ///< the root node (the torso joint), -1 when empty
  Eigen::VectorXi face_labels;  ///< #F_in node per input face; -1 = not labelled yet
  /// Seconds per stage in the order they ran, then "total".
  std::vector<std::pair<std::string, double>> timings;
  // What stage 0 said about the mesh.
  int input_vertices = 0;
  int input_faces = 0;
  int genus = 0;
  bool repaired = false;
  /// The stages that produced this skeleton, e.g. "interim_graph" while stages 4-8 are missing.
  std::string method;
  /// The shape's mirror plane (dcg/symmetry.h, the working mesh's) in input coordinates: its
  /// unit normal n then its offset o (n . x = o), and how far the shape is from mirroring itself
  /// across it (mean, over the bounding-box diagonal; 1: no plane was tried).
  Eigen::Vector4d mirror_plane = Eigen::Vector4d::Zero();
  double mirror_error = 1;
};

/// Stage 8: the skeleton in NORMALIZED units (the working mesh's) from the graph of stage 6 and
/// the polylines of stage 7 (one per graph link, in the same order). Nodes keep their points'
/// positions and radii; an end node takes its prong's significance (`prong_significance`, #P
/// prongs), an end that stands for no prong (the spine of a shape without prongs) gets 1, the
/// weakest; other nodes 0. Root: the joint of largest radius, else the node of largest radius.
/// face_labels: the node of each face of the WORKING mesh. method: "dcg".
Skeleton assemble_skeleton(const DomainGraph& graph, const Remapped& remapped,
                           const Eigen::VectorXd& prong_significance);

/// Sets s.root: the joint of largest radius (the torso), else the node of largest radius
/// (-1 when there is no node).
void choose_root(Skeleton& s);

/// s.polyline_radii: the distance from each point of s's polylines to `surface` (normalized
/// units, as s).
void measure_polyline_radii(Skeleton& s, const SurfaceQuery& surface);

/// A skeleton in normalized units -> the input's coordinates (positions, polylines, radii), with
/// its face labels of the working mesh carried to the input's faces (F_in #F by 3 indices into
/// the input's vertices: the label most of a face's vertices map to through
/// prepared.map_face), and stage 0's facts (input size, genus, repaired).
void skeleton_to_input(Skeleton& s, const PreparedMesh& prepared, const Faces& F_in,
                       Eigen::Index input_vertices);

}  // namespace dcg
