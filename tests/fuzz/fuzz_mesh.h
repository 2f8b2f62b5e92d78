// The small meshes the libFuzzer targets decode from their bytes (fuzz_prepare, fuzz_pipeline).
//
// Byte layout: [flags] [#V] [#F] then #V x 3 coordinate bytes and #F x 3 index bytes (missing
// bytes read as 0). A coordinate byte is a grid value in [-4, 4] or, for a few byte values, a
// special number (NaN, inf, huge, tiny) so that degenerate and non-finite input is reached.
// An index byte maps to [-1, #V], one past either end, to reach the range checks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "dcg/types.h"

namespace dcg_fuzz {

struct Reader {
  const std::uint8_t* data;
  std::size_t size;
  std::size_t at = 0;
  std::uint8_t next() { return at < size ? data[at++] : 0; }
};

inline double coordinate(std::uint8_t b) {
  switch (b) {
    case 255:
      return std::numeric_limits<double>::quiet_NaN();
    case 254:
      return std::numeric_limits<double>::infinity();
    case 253:
      return -std::numeric_limits<double>::infinity();
    case 252:
      return 1e300;
    case 251:
      return -1e300;
    case 250:
      return 1e-300;
    case 249:
      return 1e6;
    case 248:
      return 1e-6;
    default:
      return (static_cast<int>(b % 81) - 40) / 10.0;
  }
}

struct FuzzMesh {
  std::uint8_t flags = 0;
  dcg::Vertices V;
  dcg::Faces F;
};

// Up to 32 vertices and 64 faces: the stages stay fast.
inline FuzzMesh read_mesh(Reader& in) {
  FuzzMesh m;
  m.flags = in.next();
  const int nv = in.next() % 33;
  const int nf = in.next() % 65;
  m.V.resize(nv, 3);
  for (int i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) m.V(i, k) = coordinate(in.next());
  }
  m.F.resize(nf, 3);
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) m.F(f, k) = static_cast<int>(in.next() % (nv + 2)) - 1;
  }
  return m;
}

}  // namespace dcg_fuzz
