// The INTERIM graph: the skeleton built from the domain points of stage 2 alone (a Euclidean
// minimum spanning tree, short twigs pruned, chains of degree-2 points turned into link
// polylines). The Extractor's fallback when stages 4-8 fail; its `method` then says
// "interim_graph (fallback: <reason>)".
#pragma once

#include "dcg/prongs.h"
#include "dcg/skeleton.h"
#include "dcg/types.h"

namespace dcg {

/// The interim skeleton (normalized units) of the domain balls (stage 2): key nodes are the
/// tree's leaves (ends) and junctions (joints); chains between them become link polylines;
/// method "interim_graph". InputError when there is no ball.
Skeleton build_interim_graph(const Balls& domain);

/// Stage 3 on the interim graph: the end node nearest to each prong's peak, strongest prongs
/// first and each end at most once, gets the prong's significance; ends that stand for no prong
/// get 1, the weakest ratio. The graph itself is left as it is.
void mark_prong_ends(const Prongs& prongs, Skeleton& s);

}  // namespace dcg
