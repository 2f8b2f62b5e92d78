// libFuzzer target: the pipeline entry, dcg::validate_mesh and stage 0 (dcg::prepare_mesh), on
// small meshes decoded from the fuzz bytes. Stage 0 is the stage that sees the user's data as
// it is; later stages only see its closed, normalized working mesh. Expected failures are
// dcg::InputError; anything else (a crash, a sanitizer report, another exception) is a finding.
//
// Byte layout: [flags] [#V] [#F] then #V x 3 coordinate bytes and #F x 3 index bytes (missing
// bytes read as 0). A coordinate byte is a grid value in [-4, 4] or, for a few byte values, a
// special number (NaN, inf, huge, tiny) so that degenerate and non-finite input is reached.
// An index byte maps to [-1, #V], one past either end, to reach the range checks.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "dcg/errors.h"
#include "dcg/prepare.h"

namespace {

struct Reader {
  const std::uint8_t* data;
  std::size_t size;
  std::size_t at = 0;
  std::uint8_t next() { return at < size ? data[at++] : 0; }
};

double coordinate(std::uint8_t b) {
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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader in{data, size};
  const std::uint8_t flags = in.next();
  const int nv = in.next() % 33;  // up to 32 vertices and 64 faces: stage 0 stays fast
  const int nf = in.next() % 65;
  dcg::Vertices V(nv, 3);
  for (int i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) V(i, k) = coordinate(in.next());
  }
  dcg::Faces F(nf, 3);
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) F(f, k) = static_cast<int>(in.next() % (nv + 2)) - 1;
  }
  dcg::PrepareOptions options;
  options.repair = (flags & 1) ? dcg::Repair::None : dcg::Repair::Auto;
  options.target_faces = (flags & 2) ? 0 : 64 + 32 * ((flags >> 2) & 7);
  options.seed = flags >> 5;
  try {
    dcg::validate_mesh(V, F);
    const dcg::PreparedMesh prepared = dcg::prepare_mesh(V, F, options);
    // What stage 0 promises: a finite working mesh with in-range faces and a map for every
    // input vertex.
    const dcg::Mesh& w = prepared.working;
    if (!w.V.allFinite() || prepared.map_face.size() != nv) __builtin_trap();
    for (Eigen::Index f = 0; f < w.F.rows(); ++f) {
      for (int k = 0; k < 3; ++k) {
        if (w.F(f, k) < 0 || w.F(f, k) >= w.V.rows()) __builtin_trap();
      }
    }
    for (Eigen::Index i = 0; i < prepared.map_face.size(); ++i) {
      if (prepared.map_face(i) < 0 || prepared.map_face(i) >= w.F.rows()) __builtin_trap();
    }
  } catch (const dcg::InputError&) {
  }
  return 0;
}
