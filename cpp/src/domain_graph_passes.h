// Internal (not installed): the passes of stage 6 (dcg/domain_graph.h), in the order
// compute_domain_graph runs them, on one shared GraphWork. Each pass reads what the ones before
// it left there; the tests run a prefix of the chain and then check one pass.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <set>
#include <utility>
#include <vector>

#include "dcg/domain_graph.h"
#include "dcg/types.h"

namespace dcg {

class SurfaceQuery;

namespace internal {

/// The graph being edited: adjacency sets over point indices. `alive` is read directly but
/// changed only through set_alive and merge, which keep `live` (its count) up to date: the
/// pruning loops ask for it once per step.
struct Graph {
  std::vector<std::set<int>> adj;
  std::vector<char> alive;
  std::vector<int> absorbed_by;  ///< point -> point that absorbed it (-1: none)
  int live = 0;

  explicit Graph(int n) : adj(n), alive(n, 0), absorbed_by(n, -1) {}
  void link(int a, int b) {
    if (a == b) return;
    adj[a].insert(b);
    adj[b].insert(a);
  }
  void unlink(int a, int b) {
    adj[a].erase(b);
    adj[b].erase(a);
  }
  int degree(int a) const { return static_cast<int>(adj[a].size()); }
  /// Removes `gone` and hands its links to `keep`.
  void merge(int keep, int gone) {
    const std::set<int> others = adj[gone];
    for (int o : others) {
      unlink(gone, o);
      if (o != keep) link(keep, o);
    }
    set_alive(gone, false);
    absorbed_by[gone] = keep;
  }
  void set_alive(int p, bool value) {
    live += static_cast<int>(value) - static_cast<int>(alive[p] != 0);
    alive[p] = value;
  }
  int count_alive() const { return live; }
};

/// What the passes share: the inputs, the result being filled (`g` holds the points, radii and
/// prongs from the start) and the graph being edited over point indices.
struct GraphWork {
  /// Copies the points, radii and prongs into `g` and computes the face centroids and
  /// adjacency; checks nothing (compute_domain_graph does).
  GraphWork(const Mesh& mesh, const ForceField& field, const Points& points,
            const Eigen::VectorXd& radii, const Eigen::VectorXi& prong);

  const Mesh& mesh;
  const ForceField& field;
  const SurfaceQuery& query;  ///< field.query()
  DomainGraph g;
  Points centroid;              ///< #F face centroids
  std::vector<int> adjacency;   ///< 3f + k: face across edge k of f, -1 on a border
  std::vector<char> has_face;   ///< #P the point owns a face (else it never lives)
  Graph graph;                  ///< the kept graph, edited pass by pass
  std::vector<int> tree_order;  ///< candidate links in the order Kruskal takes them
  std::vector<std::vector<std::pair<int, int>>> tree;  ///< #P (neighbour, link) of the tree
  std::vector<std::vector<int>> kept_cycles;  ///< sorted link sets of the kept handle cycles
  /// The cancellation poll of the passes' long loops, given the fraction of the current pass
  /// done (compute_domain_graph sets it pass by pass; empty: no polls). May throw Cancelled.
  std::function<void(double)> poll;

  bool is_end(int p) const { return g.prong[p] >= 0; }
  int point_count() const { return static_cast<int>(g.points.rows()); }
  void at(double fraction) const {
    if (poll) poll(fraction);
  }
};

// --- face labels (domain surfaces) ---------------------------------------------------------
/// Rule 1: each point claims the face under its closest surface point (end points first, then
/// the nearer): g.face_labels, g.primitive_face, g.faces_seeded.
void seed_primitive_faces(GraphWork& w);
/// The nearest point (by distance to its ball) among the `candidates` nearest that sees each
/// face's centroid: g.visible_owner.
void find_visible_owners(GraphWork& w, int candidates);
/// Rule 2: regions grow over shared edges into faces whose visible owner is their point.
void grow_regions(GraphWork& w);
/// Rule 3: faces still unlabelled take the nearest labelled face's label (Dijkstra).
void flood_fill_labels(GraphWork& w);
/// Rules 1, 2 and 3 in turn: every face gets a point (g.face_labels).
void label_faces(GraphWork& w, int visibility_candidates);

// --- links and the kept graph ----------------------------------------------------------------
/// Points whose regions share an edge, with the mean |F| along their segment as cost
/// (infinity when it leaves the shape): g.candidates, g.costs.
void link_candidates(GraphWork& w, int cost_samples);
/// Where a candidate link leaves the shape between two parts of the points (grouped by the
/// links that stay inside), tries from each of its points to the other's neighbours in the
/// other's part (one step along: a finger whose base faces went to its neighbours' points, to
/// their palm point), shortest first, and keeps each that stays inside and joins two parts:
/// new candidates (state 0), g.links_bridged. Kruskal then takes them before any link that
/// leaves the shape. Never farther: a segmented arm whose shoulder links all leave the body
/// would hang from any point it reaches inside.
void bridge_outside_links(GraphWork& w, int cost_samples);
/// Kruskal's tree by cost, links touching an end point last (so ends are leaves where they
/// can be); only points that own a face come alive.
void spanning_tree(GraphWork& w);
/// Adds non-tree links, cheapest first, whose cycle goes around a handle and duplicates no kept
/// cycle, at most `genus` of them; after the links inside, those that only graze the surface
/// (kGraze in domain_graph.cpp).
void keep_handle_cycles(GraphWork& w, int genus);
/// Prunes non-end leaves repeatedly, or, with at most one end and no cycle, keeps the longest
/// tree path (a spine for a sphere-like shape).
void prune(GraphWork& w);
/// Contracts links shorter than their larger radius, shortest first: into the larger ball, an
/// end absorbing a chain node; never two ends, an end and a junction, or a shared neighbour.
void contract_short_links(GraphWork& w);
/// Merges into its junction an end point inside the tube of another of the junction's links,
/// or barely reaching out of the bent tube through the junction.
void absorb_bumps(GraphWork& w);
/// Merges junctions whose balls overlap along the chain between them (directly linked: less
/// than a ball apart), or closer than the body is wide, never across a cycle.
void merge_joints(GraphWork& w);
/// A shape shrunk to one point gets two more on its principal axis, linked to it.
void add_spine(GraphWork& w);
/// The result's nodes, links, kinds by degree, node of each point and face, cycles, components.
void classify(GraphWork& w);

}  // namespace internal
}  // namespace dcg
