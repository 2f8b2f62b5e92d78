// Stage 0's pass-wise edge collapse: see decimate.h. Used for inputs of more than 3 x the
// remeshing target, which it takes to 1.5 x: CGAL's quality edge collapse in remesh_uniform()
// costs about 30 us per collapse (23 s of the 35 s on a 1.4M-face mesh, 1.3 s on the 97k-face
// horse), and the isotropic remeshing after it evens the triangles out anyway.
#include "decimate.h"

#include <algorithm>
#include <array>
#include <vector>

#include "compact_mesh.h"
#include "polling.h"

namespace dcg::internal {
namespace {

// The mesh as collapsible triangles: positions, faces with alive flags, each vertex's faces.
class PassCollapse {
 public:
  PassCollapse(const Mesh& mesh, int goal, const std::function<void(double)>& poll)
      : nf_(static_cast<int>(mesh.F.rows())), goal_(goal), poll_(poll) {
    const int nv = static_cast<int>(mesh.V.rows());
    report(0);
    P_.resize(nv);
    for (int i = 0; i < nv; ++i) P_[i] = mesh.V.row(i).transpose();
    report(0);
    T_.resize(nf_);
    face_alive_.assign(nf_, 1);
    vertex_alive_.assign(nv, 1);
    moved_.assign(nv, 0);
    vf_.resize(nv);
    report(0);
    std::vector<int> degree(nv, 0);
    for (int f = 0; f < nf_; ++f)
      for (int k = 0; k < 3; ++k) ++degree[mesh.F(f, k)];
    for (int v = 0; v < nv; ++v) {
      if ((v & 65535) == 0) report(0);
      vf_[v].reserve(degree[v] + 2);
    }
    for (int f = 0; f < nf_; ++f) {
      if ((f & 65535) == 0) report(0);
      for (int k = 0; k < 3; ++k) {
        T_[f][k] = mesh.F(f, k);
        vf_[T_[f][k]].push_back(f);
      }
    }
    mark_.assign(nv, 0);
    alive_faces_ = nf_;
  }

  // One pass over the shorter half of the edges; returns the number of collapses.
  int pass();
  bool done() const { return alive_faces_ <= goal_; }
  Mesh result() const;

 private:
  struct Candidate {
    float length2;
    int a, b;
    bool operator<(const Candidate& o) const {
      return length2 < o.length2 || (length2 == o.length2 && (a < o.a || (a == o.a && b < o.b)));
    }
  };
  void report(double fraction) const {
    if (poll_) poll_(fraction);
  }
  double fraction_done() const {
    return 1.0 - static_cast<double>(alive_faces_ - goal_) / (nf_ - goal_);
  }
  bool has(int f, int v) const { return T_[f][0] == v || T_[f][1] == v || T_[f][2] == v; }
  void collect_shorter_half();
  bool is_interior_edge(int a, int b) const;
  bool link_condition(int a, int b);
  bool keeps_normals(int a, int b, const Eigen::Vector3d& m) const;
  void collapse(int a, int b, const Eigen::Vector3d& m);

  const int nf_, goal_;
  const std::function<void(double)>& poll_;
  std::vector<Eigen::Vector3d> P_;
  std::vector<std::array<int, 3>> T_;
  std::vector<char> face_alive_, vertex_alive_, moved_;
  std::vector<std::vector<int>> vf_;  // vertex -> its alive faces
  std::vector<int> mark_;             // neighbour stamps for the link condition
  int stamp_ = 0;
  int alive_faces_ = 0;
  std::vector<Candidate> candidates_;
};

// The edges of the alive faces (each once), the shorter half of them sorted by length.
void PassCollapse::collect_shorter_half() {
  candidates_.clear();
  for (int f = 0; f < nf_; ++f) {
    if ((f & 65535) == 0) report(fraction_done());
    if (!face_alive_[f]) continue;
    for (int k = 0; k < 3; ++k) {
      const int a = T_[f][k], b = T_[f][(k + 1) % 3];
      // Each edge once: its half-edge from the lower index (a closed, consistently oriented
      // surface has both).
      if (a < b) candidates_.push_back({static_cast<float>((P_[a] - P_[b]).squaredNorm()), a, b});
    }
  }
  const double pass_start = fraction_done();
  report(pass_start);
  // nth_element, then sorted in chunks between polls.
  const auto half = candidates_.begin() + static_cast<std::ptrdiff_t>(candidates_.size() / 2);
  std::nth_element(candidates_.begin(), half, candidates_.end());
  report(pass_start);
  candidates_.resize(candidates_.size() / 2);
  sort_polling(candidates_, [&] { report(pass_start); });
}

// Whether edge a-b has exactly two faces with two different opposite vertices.
bool PassCollapse::is_interior_edge(int a, int b) const {
  int shared = 0, opposite[2] = {-1, -1};
  for (int f : vf_[a]) {
    if (!has(f, b)) continue;
    if (shared == 2) return false;
    for (int v : T_[f])
      if (v != a && v != b) opposite[shared] = v;
    ++shared;
  }
  return shared == 2 && opposite[0] != opposite[1];
}

// The ends' only common neighbours are the two opposite vertices (else the collapse pinches).
bool PassCollapse::link_condition(int a, int b) {
  ++stamp_;
  for (int f : vf_[a])
    for (int v : T_[f])
      if (v != a) mark_[v] = stamp_;
  int common = 0;
  for (int f : vf_[b]) {
    for (int v : T_[f]) {
      if (v != b && mark_[v] == stamp_) {
        mark_[v] = 0;  // count each common neighbour once
        ++common;
      }
    }
  }
  return common == 2;
}

// No face around a or b (but the two on the edge) turns by more than 60 degrees or degenerates
// when its corner at a or b moves to m.
bool PassCollapse::keeps_normals(int a, int b, const Eigen::Vector3d& m) const {
  const double cos_limit = 0.5;
  auto normal = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
    return Eigen::Vector3d((q - p).cross(r - p));
  };
  for (const int v : {a, b}) {
    for (int f : vf_[v]) {
      const auto& t = T_[f];
      if (has(f, a) && has(f, b)) continue;
      Eigen::Vector3d q[3] = {P_[t[0]], P_[t[1]], P_[t[2]]};
      const Eigen::Vector3d n0 = normal(q[0], q[1], q[2]);
      for (int k = 0; k < 3; ++k)
        if (t[k] == v) q[k] = m;
      const Eigen::Vector3d n1 = normal(q[0], q[1], q[2]);
      if (n0.dot(n1) <= cos_limit * n0.norm() * n1.norm()) return false;
    }
  }
  return true;
}

// Collapses b into a, moved to m: the two faces on the edge die, b's other faces go to a.
void PassCollapse::collapse(int a, int b, const Eigen::Vector3d& m) {
  P_[a] = m;
  for (int f : vf_[b]) {
    auto& t = T_[f];
    if (has(f, a)) {
      face_alive_[f] = 0;
      --alive_faces_;
      for (int v : t) {
        if (v == b) continue;
        auto& list = vf_[v];
        list.erase(std::find(list.begin(), list.end(), f));
      }
    } else {
      for (int& v : t)
        if (v == b) v = a;
      vf_[a].push_back(f);
    }
  }
  vf_[b].clear();
  vertex_alive_[b] = 0;
  moved_[a] = 1;
}

int PassCollapse::pass() {
  report(fraction_done());
  collect_shorter_half();
  std::fill(moved_.begin(), moved_.end(), 0);
  int collapsed = 0;
  for (auto it = candidates_.begin(); it != candidates_.end() && !done(); ++it) {
    if (((it - candidates_.begin()) & 4095) == 0) report(fraction_done());
    const int a = it->a, b = it->b;
    if (!vertex_alive_[a] || !vertex_alive_[b] || moved_[a] || moved_[b]) continue;
    if (!is_interior_edge(a, b) || !link_condition(a, b)) continue;
    const Eigen::Vector3d m = 0.5 * (P_[a] + P_[b]);
    if (!keeps_normals(a, b, m)) continue;
    collapse(a, b, m);
    ++collapsed;
  }
  return collapsed;
}

Mesh PassCollapse::result() const {
  Vertices V(static_cast<Eigen::Index>(P_.size()), 3);
  for (std::size_t v = 0; v < P_.size(); ++v) V.row(v) = P_[v].transpose();
  std::vector<std::array<int, 3>> faces;
  faces.reserve(alive_faces_);
  for (int f = 0; f < nf_; ++f)
    if (face_alive_[f]) faces.push_back(T_[f]);
  return compact_mesh(V, faces);
}

}  // namespace

Mesh fast_reduce(const Mesh& mesh, int goal, const std::function<void(double)>& poll) {
  PassCollapse reducer(mesh, goal, poll);
  for (int pass = 0; !reducer.done() && pass < 64; ++pass) {
    if (reducer.pass() == 0) break;
  }
  return reducer.result();
}

}  // namespace dcg::internal
