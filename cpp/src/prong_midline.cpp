// Stage 3, midline (dcg/prongs.h, ProngHierarchy's class comment): a prong on one of a pair of
// horns or ears moved to the peak between them on the mirror plane, the head's middle.
//
// Implementation notes:
// - Regions are followed through partners as for fingers (region_prong), against the prongs as
//   they were before any moved, so that the order prongs are visited in changes nothing.
// - The twin is looked for among the strongest peaks first; each candidate costs a mirror test
//   (mirrors_mesh: a thousand nearest-vertex queries), so at most kMidlineTwinTests are tried
//   per prong: a horn's twin is one of the strongest peaks of its region (spot's 2nd of 6).
#include <cmath>
#include <unordered_set>
#include <vector>

#include "dcg/prongs.h"

namespace dcg {

int ProngHierarchy::move_to_midline(std::vector<const Peak*>& kept) const {
  std::unordered_set<int> prongs;
  for (const Peak* p : kept) prongs.insert(p->vertex);
  // The peaks that may stand in for a prong or be its twin: strong enough, not prongs.
  std::vector<const Peak*> candidates;
  std::vector<int> owner;
  for (const Peak& q : peaks_) {
    if (!(q.ratio < kMidlineRatio)) break;  // sorted by ratio
    if (q.global || prongs.count(q.vertex)) continue;
    candidates.push_back(&q);
    owner.push_back(region_prong(q, prongs));
  }
  int moved = 0;
  std::vector<char> taken(candidates.size(), 0);  // a peak stands in for one prong at most
  for (const Peak*& p : kept) {
    const Peak* twin = nullptr;
    int tests = 0;
    for (std::size_t c = 0; c < candidates.size() && !twin && tests < kMidlineTwinTests; ++c) {
      const Peak& q = *candidates[c];
      if (owner[c] != p->vertex || !as_high(q, *p)) continue;  // mirror tests are counted
      ++tests;
      if (mirrors_mesh(q.vertex, p->vertex)) twin = &q;
    }
    if (!twin) continue;
    const double half = (mesh_.V.row(p->vertex) - mesh_.V.row(twin->vertex)).norm() / 2;
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      const Peak& m = *candidates[c];
      if (owner[c] != p->vertex || &m == twin || taken[c]) continue;
      if (off_halfway(p->vertex, twin->vertex, m.vertex) > kMidlinePlane * half) continue;
      p = &m;  // the strongest on the plane: candidates are sorted by ratio
      taken[c] = 1;
      ++moved;
      break;
    }
  }
  return moved;
}

}  // namespace dcg
