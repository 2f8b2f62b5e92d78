// libFuzzer target: the pipeline entry, dcg::validate_mesh and stage 0 (dcg::prepare_mesh), on
// small meshes decoded from the fuzz bytes. Stage 0 is the stage that sees the user's data as
// it is; later stages only see its closed, normalized working mesh. Expected failures are
// dcg::InputError; anything else (a crash, a sanitizer report, another exception) is a finding.
//
// Byte layout: tests/fuzz/fuzz_mesh.h.
#include "dcg/errors.h"
#include "dcg/prepare.h"
#include "fuzz_mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  dcg_fuzz::Reader in{data, size};
  const dcg_fuzz::FuzzMesh mesh = dcg_fuzz::read_mesh(in);
  const std::uint8_t flags = mesh.flags;
  const dcg::Vertices& V = mesh.V;
  const dcg::Faces& F = mesh.F;
  const Eigen::Index nv = V.rows();
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
