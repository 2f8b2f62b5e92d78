// Stage 6 (ALGORITHM.md "Domain surfaces and links", paper section 7, Def. 2-4): which point each
// face of the working mesh belongs to, the links between points whose domain surfaces touch, and
// the graph that is kept of them (a spanning tree plus at most genus-many handle cycles, pruned,
// short links contracted, nodes classified).
//
// Points: the connection points of stage 5 followed by the end points of stage 3.
//
// Face labels (domain surfaces):
//   1. the face under each point's closest surface point gets that point (its primitive visible
//      face; when two points claim one face, an end point wins, else the nearer point);
//   2. regions grow over shared edges: a face joins the region of a neighbour's point when that
//      point is the nearest point that sees the face (Embree occlusion from the point to the
//      face's centroid; the `visibility_candidates` nearest points are tried). "Nearest" is by
//      distance to the point's BALL (|c - p| - r_p), not to its center: the big ball in the
//      middle of a star owns the surface it touches between the arms, where the small balls at
//      the arms' bases are nearer by center distance and would take it, leaving the center a
//      leaf that is pruned (the arms then joined each other around it: 2-3 joints for 5 arms);
//   3. faces still without a label take the label of the nearest labelled face (Dijkstra over
//      shared edges by centroid distance: nearest first).
// Links: two points are linked when their regions share an edge. Cost = mean |F| over
// `cost_samples` points inside the segment; infinity when the segment leaves the shape. A link
// that leaves the shape between two parts of the points (grouped by the links that stay
// inside) gets a bridge where one exists: from one of its points to a neighbour of the other,
// in the other's part, by a segment inside, shortest first (a finger whose base faces went to
// its neighbours' points reached the hand only through them, outside; its bridge goes to their
// palm point).
//
// The kept graph:
//   - Kruskal's minimum spanning tree by cost, links that touch an end point taken after all
//     others, so that end points are leaves whenever the rest is connected without them;
//   - non-tree links, cheapest first, close a cycle (tree path + link) that is kept only while
//     fewer than `genus` are kept, when not all of its points see each other (it goes around a
//     handle; a segment between two of them that leaves the shape for no more than the
//     smaller of their radii only crosses a crack or a pinhole tunnel, as where Mannequiny's
//     knee parts barely meet), and when it does not duplicate a kept cycle: their symmetric
//     difference must not split into loops whose points all see each other;
//   - leaves that are not end points are pruned repeatedly; a shape with at most one end point
//     and no cycle (a sphere, an egg, a teardrop) keeps its longest tree path instead, so that
//     the skeleton still has a spine (and two end nodes);
//   - links shorter than the larger radius of their two nodes are contracted, shortest first,
//     never when the two nodes share a neighbour (that would fold a cycle) nor between two end
//     points: a non-end node is merged into the node of larger radius (which keeps its place);
//     an end point absorbs a chain node (degree 2) next to it; an end point next to a junction
//     (degree >= 3) stays, whatever its link's length (merging it there took fertility's second
//     end). An end point that lies inside the tube of another link of its junction (closer to
//     that segment than the smaller radius of its two nodes), or whose ball reaches less than
//     0.6 of a radius out of the bent tube along the circle arc through its junction and two
//     other neighbours, is a bump on the junction and merges into it: the digit eight's prongs
//     on its loops (the straight links cut inside the loop's bend, so the first test alone let
//     them through in 12 of 12 perturbed draws);
//   - two junctions (degree >= 3) whose balls overlap along the chain (over degree-2 points)
//     between them (the chain is shorter than the sum of their radii) are one junction: the
//     chain and the smaller junction merge into the larger one (never across a cycle); a merged
//     junction is the union of its balls for the next test. Two junctions linked directly (no
//     connection point between them: their domain surfaces touch, no part of the body lies
//     between them) merge while the gap between their balls is less than the larger radius,
//     i.e. when they are neighbouring balls of one part (domain balls of a part are about a ball
//     apart): a squat torso (the knight's) has its hip and shoulder balls anywhere from
//     overlapping to 2/3 of a radius apart depending on the draw (rotation, noise, seed), while
//     a torso long enough to hold a connection point of its own (the cheetah's) keeps two
//     joints; a wrist ball and a smaller palm ball, linked directly, 1.1 palm radii apart,
//     are one hand (Mannequiny's on CGAL 6: the smaller radius split its fingers two and two).
//     Which of two nearby junctions a limb hangs from changes under small perturbations; their
//     union does not;
//   - a shape that shrinks to a single point (a sphere) gets a spine: two more points on its
//     principal axis, half way from that point to the surface on either side (they own no face);
//   - kinds by degree: 1 end, >= 3 joint, else connection (an end point on a cycle becomes a
//     connection point, as the digit eight's).
//
// compute_domain_graph runs these rules as a chain of passes, each declared and documented in
// the internal header cpp/src/domain_graph_passes.h (where the tests call them one by one).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "dcg/progress.h"
#include "dcg/skeleton.h"
#include "dcg/types.h"

namespace dcg {

class ForceField;

struct DomainGraphOptions {
  int cost_samples = 8;            ///< points sampled inside each link for its cost
  int visibility_candidates = 16;  ///< nearest points tried per face for its visible owner
  bool prune = true;               ///< prune non-end leaves (off: the raw tree + cycles)
  bool contract = true;            ///< contract links shorter than their larger radius
  bool merge_joints = true;        ///< merge joints whose balls overlap along their chain (or,
                                   ///<    linked directly, are less than a ball apart), or that
                                   ///<    are closer than the body is wide across them
};

struct DomainGraph {
  // --- the points (#P): connection points, then end points ---------------------------------
  Points points;          ///< #P by 3 (plus the two spine points of a sphere, if any)
  Eigen::VectorXd radii;  ///< #P distance to the surface
  Eigen::VectorXi prong;  ///< #P prong index of an end point, -1 for connection points
  // --- domain surfaces -------------------------------------------------------------------
  Eigen::VectorXi face_labels;     ///< #F point owning each face of the working mesh
  Eigen::VectorXi primitive_face;  ///< #P the point's primitive visible face, -1 when it lost it
  Eigen::VectorXi visible_owner;   ///< #F nearest point that sees the face, -1 when none does
  int faces_seeded = 0;            ///< faces labelled by rule 1
  int faces_grown = 0;             ///< faces labelled by rule 2 (region growing)
  int faces_filled = 0;            ///< faces labelled by rule 3 (flood fill)
  // --- candidate links -------------------------------------------------------------------
  Edges candidates;                 ///< #L point pairs (a < b) whose regions share an edge
  Eigen::VectorXd costs;            ///< #L mean |F| along the segment (infinity: leaves the shape)
  Eigen::VectorXi candidate_state;  ///< #L 0 unused, 1 tree link, 2 kept cycle link
  /// candidates whose cycle points all see each other (but across cracks narrower than their
  /// radii), or whose cycle spans a disk inside the shape (its centroid inside and seeing all
  /// of them: a crotch, not a handle)
  int cycles_rejected_visible = 0;
  int cycles_rejected_duplicate = 0;  ///< candidates duplicating a kept cycle
  /// candidates added between parts that the links staying inside left apart (one step along
  /// a link that leaves the shape, by a segment inside; appended after the region-sharing ones)
  int links_bridged = 0;
  // --- the kept graph ---------------------------------------------------------------------
  std::vector<int> nodes;         ///< #N the point each node is
  Edges links;                    ///< #K node pairs (indices into nodes)
  std::vector<NodeKind> kinds;    ///< #N by degree
  Eigen::VectorXi node_of_point;  ///< #P node standing for each point (pruned and contracted
                                  ///<    points: the node that absorbed them); -1: no face
  Eigen::VectorXi face_nodes;     ///< #F node of each face's point (the segmentation)
  int cycles = 0;                 ///< independent cycles: #K - #N + components
  int components = 0;             ///< connected components of the kept graph
  int pruned = 0;                 ///< points pruned as non-end leaves
  int contracted = 0;             ///< links contracted
  int ends_absorbed = 0;          ///< end points merged into a junction (bumps)
  int joints_merged = 0;          ///< pairs of joints merged into one junction
};

/// mesh: the closed working mesh (V #V by 3, F #F by 3) that `field` was built on.
/// points: #P by 3 inside the shape; radii: #P distance to the surface; prong: #P prong index
/// (>= 0: an end point that must stay a leaf), -1 for connection points.
/// genus: the mesh's genus, the most cycles kept.
/// Progress as stage "domain_graph", see dcg/progress.h.
DomainGraph compute_domain_graph(const Mesh& mesh, const ForceField& field, const Points& points,
                                 const Eigen::VectorXd& radii, const Eigen::VectorXi& prong,
                                 int genus, const DomainGraphOptions& options = {},
                                 const Progress& progress = {}, double from = 0, double to = 1);

}  // namespace dcg
