// Stage 9 (dcg/weights.h) for Python: skin_weights from the input mesh, or from a stage-0 result
// the caller already has. Options come as one dict of public names (dcg/options.h): the weights'
// own and stage 0's; the skeleton's are accepted and unused. The Python layer (bindings/dcg/weights.py) validates the arrays and
// turns bones given as a skeleton or a bone list into heads and tails.
#include "common.h"

#include "dcg/errors.h"
#include "dcg/pipeline.h"
#include "dcg/prepare.h"
#include "dcg/weights.h"

namespace dcg_py {
namespace {

dcg::Bones make_bones(const dcg::Points& heads, const dcg::Points& tails) {
  dcg::Bones bones;
  bones.heads = heads;
  bones.tails = tails;
  return bones;
}

py::dict weights_dict(const dcg::SkinWeights& w) {
  py::dict d;
  d["rows"] = to_int64(w.rows);
  d["cols"] = to_int64(w.cols);
  d["values"] = w.values;
  d["vertex_count"] = w.vertex_count;
  d["bone_count"] = w.bone_count;
  d["working_vertices"] = w.working_vertices;
  d["unseen_vertices"] = w.unseen_vertices;
  d["blind_components"] = w.blind_components;
  d["fallback_vertices"] = w.fallback_vertices;
  d["timings"] = py::cast(w.timings);
  return d;
}

// Runs `compute` with the GIL released; a Python exception raised by the progress callable is
// re-raised as itself.
template <typename Compute>
dcg::SkinWeights run(ProgressBridge& bridge, Compute compute) {
  try {
    py::gil_scoped_release release;
    return compute(bridge.callback());
  } catch (const dcg::Cancelled&) {
    bridge.rethrow_if_failed();
    throw;
  }
}

}  // namespace

void bind_weights(py::module_& m) {
  m.def(
      "skin_weights",
      [](const dcg::Vertices& V, const Faces64& F, const dcg::Points& heads,
         const dcg::Points& tails, const py::dict& options, py::object progress) {
        const dcg::Faces faces = to_faces(F, V.rows());
        const dcg::Options o = options_from_dict(options);
        const dcg::Bones bones = make_bones(heads, tails);
        ProgressBridge bridge(std::move(progress));
        return weights_dict(run(bridge, [&](dcg::ProgressCallback cb) {
          return dcg::compute_skin_weights(V, faces, bones, o, std::move(cb));
        }));
      },
      py::arg("V"), py::arg("F"), py::arg("heads"), py::arg("tails"), py::arg("options"),
      py::arg("progress") = py::none(),
      "Bone heat weights of V's vertices (on V itself, or stage 0's working mesh when large); "
      "a dict of triplets and counts.");
  m.def(
      "weights_on_working_mesh",
      [](std::int64_t faces, const py::dict& options) {
        return dcg::weights_on_working_mesh(faces, options_from_dict(options).prepare);
      },
      py::arg("faces"), py::arg("options"),
      "Whether skin_weights solves an input of `faces` faces on stage 0's working mesh.");
  m.def(
      "skin_weights_prepared",
      [](const dcg::Vertices& working_V, const Faces64& working_F, double scale,
         const Eigen::Vector3d& offset, const Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1>& map_face,
         const dcg::Vertices& map_barycentric, const dcg::Points& heads, const dcg::Points& tails,
         const py::dict& options, py::object progress) {
        dcg::PreparedMesh prepared;
        prepared.working.V = working_V;
        prepared.working.F = to_faces(working_F, working_V.rows());
        prepared.scale = scale;
        prepared.offset = offset.transpose();
        if (map_barycentric.rows() != map_face.size()) {
          throw dcg::InputError("map_face and map_barycentric have different lengths");
        }
        prepared.map_face.resize(map_face.size());
        for (Eigen::Index i = 0; i < map_face.size(); ++i) {
          if (map_face[i] < 0 || map_face[i] >= prepared.working.F.rows()) {
            throw dcg::InputError("map_face[" + std::to_string(i) + "] is outside the working mesh");
          }
          prepared.map_face[i] = static_cast<int>(map_face[i]);
        }
        prepared.map_barycentric = map_barycentric;
        const dcg::WeightsOptions o = options_from_dict(options).weights;
        const dcg::Bones bones = make_bones(heads, tails);
        ProgressBridge bridge(std::move(progress));
        return weights_dict(run(bridge, [&](dcg::ProgressCallback cb) {
          return dcg::compute_skin_weights(prepared, bones, o, std::move(cb));
        }));
      },
      py::arg("working_V"), py::arg("working_F"), py::arg("scale"), py::arg("offset"),
      py::arg("map_face"), py::arg("map_barycentric"), py::arg("heads"), py::arg("tails"),
      py::arg("options"), py::arg("progress") = py::none(),
      "Bone heat weights from a stage-0 result (dcg.PreparedMesh's arrays).");
}

}  // namespace dcg_py
