// Stage 3, fingers (dcg/prongs.h, ProngHierarchy's class comment): peaks past tau kept as
// prongs because several long, thin ones stand side by side on one prong: a hand's fingers.
//
// Implementation notes:
// - A peak's protrusion is its watershed region at its valley: the vertices with f above the
//   valley connected to the peak, found by a flood fill that gives up past kFingerVertices of
//   the mesh (a finger is small; a big region is a limb or the body, and the fill stays cheap).
//   A peak that a sibling finger ended in is cut higher, at that sibling's valley
//   (sibling_levels).
// - Its base is the region's vertices with a neighbour outside; length and width are measured
//   from the base's centre, so they do not depend on the mesh's scale or orientation.
// - Peaks are grouped by the prong their region ended in (following partners until a prong,
//   else the last peak reached), then linked when they stand within kFingerSpread lengths of
//   each other (union-find); a group of at least kFingerCount long, thin peaks is a hand.
// - A peak of another hand whose region was measured and that mirrors a finger or thumb found
//   so (f within kTwinValue, the plane halfway between the two mirroring the whole mesh:
//   mirrors_mesh) is one too: a noise moves a thumb's valley and so its aspect. Mannequiny's
//   left thumb measured 1.49-1.9 in 3 of 29 draws of a noise of 1e-5 of the diagonal (its
//   right one 2.4-3.0, kThumbAspect 2), and the rig had a thumb on one hand only.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "dcg/prongs.h"

namespace dcg {
namespace {

struct Protrusion {
  const Peak* peak = nullptr;
  int hand = -1;      // vertex of the peak whose region it ended in (a prong where one is)
  double length = 0;  // from its base's centre to its farthest vertex
  double aspect = 0;  // length over the base's mean radius (0: too big, or no base)
};

// The region {f > level} around a peak, flood-filled (mark[v] == stamp inside); false when it
// grows past `cap` vertices.
bool fill_region(const Eigen::VectorXd& f, const std::vector<int>& start,
                 const std::vector<int>& adjacency, const Peak& peak, double level, int cap,
                 std::vector<int>& mark, int stamp, std::vector<int>& region) {
  region.assign(1, peak.vertex);
  mark[peak.vertex] = stamp;
  for (std::size_t i = 0; i < region.size(); ++i) {
    const int u = region[i];
    for (int e = start[u]; e < start[u + 1]; ++e) {
      const int v = adjacency[e];
      if (mark[v] == stamp || !(f[v] > level)) continue;
      if (static_cast<int>(region.size()) >= cap) return false;
      mark[v] = stamp;
      region.push_back(v);
    }
  }
  return true;
}

// Length and aspect of a filled region (see Protrusion).
void measure(const Points& V, const std::vector<int>& start, const std::vector<int>& adjacency,
             const std::vector<int>& mark, int stamp, const std::vector<int>& region,
             Protrusion& out) {
  Eigen::RowVector3d centre = Eigen::RowVector3d::Zero();
  std::vector<int> base;
  for (const int u : region) {
    for (int e = start[u]; e < start[u + 1]; ++e) {
      if (mark[adjacency[e]] != stamp) {
        base.push_back(u);
        centre += V.row(u);
        break;
      }
    }
  }
  if (base.empty()) return;
  centre /= static_cast<double>(base.size());
  double radius = 0;
  for (const int u : base) radius += (V.row(u) - centre).norm();
  radius /= static_cast<double>(base.size());
  for (const int u : region) out.length = std::max(out.length, (V.row(u) - centre).norm());
  if (radius > 0) out.aspect = out.length / radius;
}

// The level each peak's protrusion is cut at (by peak vertex; only those above their valley):
// the valley of the highest sibling that ended in its region and stands out at least half as
// far above that valley as the peak itself (a finger beside it, not a bump on it). Without
// it, of two fingers side by side the lower one's region is its own, but the higher one's holds
// both down to the knuckles: a base twice as wide, and an aspect that flips with the order of
// the two, which a tiny noise decides (Mannequiny's middle finger: 5.1 or 3.8).
std::unordered_map<int, double> sibling_levels(const std::vector<Peak>& peaks, double max_ratio) {
  std::unordered_map<int, const Peak*> by_vertex;
  for (const Peak& p : peaks) by_vertex[p.vertex] = &p;
  std::unordered_map<int, double> level;
  for (const Peak& c : peaks) {
    if (!(c.ratio < max_ratio) || c.partner < 0) continue;
    const auto parent = by_vertex.find(c.partner);
    if (parent == by_vertex.end()) continue;
    if (c.value - c.valley < 0.5 * (parent->second->value - c.valley)) continue;
    auto [it, fresh] = level.emplace(c.partner, c.valley);
    if (!fresh) it->second = std::max(it->second, c.valley);
  }
  return level;
}

}  // namespace

std::vector<const Peak*> ProngHierarchy::fingers(double tau,
                                                 const std::vector<const Peak*>& kept) const {
  constexpr std::size_t kMaxCandidates = 256;  // the strongest; a scan's noise adds thousands
  const int n = static_cast<int>(f_.size());
  std::unordered_set<int> prong_vertices;
  for (const Peak* p : kept) prong_vertices.insert(p->vertex);

  std::vector<Protrusion> found;
  std::vector<int> mark(n, -1), region;
  const int cap = std::max(1, static_cast<int>(kFingerVertices * n));
  const std::unordered_map<int, double> siblings = sibling_levels(peaks_, kFingerRatio);
  for (const Peak& q : peaks_) {
    if (!(q.ratio < kFingerRatio) || found.size() >= kMaxCandidates) break;
    if (q.ratio < tau || q.global || prong_vertices.count(q.vertex)) continue;
    Protrusion t;
    t.peak = &q;
    const int stamp = static_cast<int>(found.size());
    const auto sibling = siblings.find(q.vertex);
    const double level = sibling == siblings.end() ? q.valley : std::max(q.valley, sibling->second);
    if (fill_region(f_, adjacency_start_, adjacency_, q, level, cap, mark, stamp, region))
      measure(mesh_.V, adjacency_start_, adjacency_, mark, stamp, region, t);
    t.hand = region_prong(q, prong_vertices);
    found.push_back(t);
  }

  // Long, thin peaks of one hand linked when close (union-find), then the groups big enough.
  const auto close = [&](const Protrusion& a, const Protrusion& b) {
    const double apart = (mesh_.V.row(a.peak->vertex) - mesh_.V.row(b.peak->vertex)).norm();
    return a.hand == b.hand && apart <= kFingerSpread * std::max(a.length, b.length);
  };
  std::vector<char> thin(found.size());
  for (std::size_t a = 0; a < found.size(); ++a) thin[a] = found[a].aspect >= kFingerAspect;
  std::vector<int> group(found.size());
  std::iota(group.begin(), group.end(), 0);
  const auto find = [&](int x) {
    while (group[x] != x) x = group[x] = group[group[x]];
    return x;
  };
  for (std::size_t a = 0; a < found.size(); ++a)
    for (std::size_t b = 0; b < a; ++b)
      if (thin[a] && thin[b] && close(found[a], found[b]))
        group[find(static_cast<int>(a))] = find(static_cast<int>(b));
  std::vector<int> members(found.size(), 0);
  for (std::size_t a = 0; a < found.size(); ++a)
    if (thin[a]) ++members[find(static_cast<int>(a))];
  std::vector<char> finger(found.size(), 0);
  for (std::size_t a = 0; a < found.size(); ++a)
    finger[a] = thin[a] && members[find(static_cast<int>(a))] >= kFingerCount;
  // A thumb: shorter, beside a finger of the same hand.
  std::vector<char> by_shape(found.size(), 0);
  for (std::size_t a = 0; a < found.size(); ++a) {
    bool thumb = false;
    for (std::size_t b = 0; b < found.size() && !finger[a] && !thumb; ++b)
      thumb = finger[b] && found[a].aspect >= kThumbAspect && close(found[a], found[b]);
    by_shape[a] = finger[a] || thumb;
  }
  // Those, and the mirror image of one of them on another hand (see the class comment).
  std::vector<const Peak*> out;
  for (std::size_t a = 0; a < found.size(); ++a) {
    bool keep = by_shape[a];
    for (std::size_t b = 0; b < found.size() && !keep && found[a].aspect > 0; ++b)
      keep = by_shape[b] && found[b].hand != found[a].hand &&
             mirror_image(*found[a].peak, *found[b].peak);
    if (keep) out.push_back(found[a].peak);
  }
  return out;
}

}  // namespace dcg
