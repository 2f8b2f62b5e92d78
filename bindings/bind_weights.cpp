// Stage 9 (dcg/weights.h) for Python: skin_weights from the input mesh, or from a stage-0 result
// the caller already has; the SkinWeights result; BoneHeat (precompute once, solve for many bone
// sets). Options come as one dict of public names (dcg/options.h): the weights' own and stage
// 0's; the skeleton's are accepted and unused. The Python layer (bindings/dcg/weights.py)
// validates the arrays and turns bones given as a skeleton or a bone list into heads and tails.
#include "result_class.h"

#include <limits>
#include "dcg/errors.h"
#include "dcg/pipeline.h"

#include "dcg/prepare.h"
#include "dcg/weights.h"

namespace dcg_py {
namespace {

// parents: None (found from the bones' ends, see dcg::Bones) or #B indices, -1 at a root.
// deform: None (every bone deforms) or #B flags (see dcg::Bones::deform).
dcg::Bones make_bones(const dcg::Points& heads, const dcg::Points& tails,
                      const py::object& parents = py::none(),
                      const py::object& deform = py::none()) {
  dcg::Bones bones;
  bones.heads = heads;
  bones.tails = tails;
  if (!deform.is_none()) {
    for (const bool flag : deform.cast<std::vector<bool>>()) bones.deform.push_back(flag ? 1 : 0);
  }
  if (!parents.is_none()) {
    const auto p = parents.cast<Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1>>();
    bones.parents.resize(p.size());
    for (Eigen::Index b = 0; b < p.size(); ++b) {
      if (p[b] < -1 || p[b] > std::numeric_limits<int>::max()) {
        throw dcg::InputError("bone " + std::to_string(b) + " has parent " + std::to_string(p[b]) +
                              ", not -1 or another bone");
      }
      bones.parents[b] = static_cast<int>(p[b]);
    }
  }
  return bones;
}

void bind_skin_weights_class(py::module_& m) {
  using W = dcg::SkinWeights;
  ResultClass<W>(m, "SkinWeights",
                 "Per-vertex bone weights as sparse triplets (dcg/weights.h); unpacks as (rows, "
                 "cols, values).")
      .field("rows", &W::rows)
      .field("cols", &W::cols)
      .field("values", &W::values)
      .field("vertex_count", &W::vertex_count)
      .field("bone_count", &W::bone_count)
      .field("working_vertices", &W::working_vertices)
      .field("unseen_vertices", &W::unseen_vertices)
      .field("blind_components", &W::blind_components)
      .field("rigid_parts", &W::rigid_parts)
      .field("fallback_vertices", &W::fallback_vertices)
      .field("timings", &W::timings)
      .def("dense", &W::dense, "The #V x #B weight matrix.")
      .def("__iter__", [](py::object self) {
        return py::iter(py::make_tuple(self.attr("rows"), self.attr("cols"), self.attr("values")));
      });
}

/// dcg::BoneHeat: precompute once on a closed mesh, solve for many bone sets.
void bind_bone_heat(py::module_& m) {
  using H = dcg::BoneHeat;
  py::class_<H>(m, "BoneHeat")
      .def(py::init([](const dcg::Vertices& V, const Faces64& F) {
             dcg::Mesh mesh{V, to_faces(F, V.rows())};
             py::gil_scoped_release release;
             return std::make_unique<H>(mesh);
           }),
           py::arg("V"), py::arg("F"))
      .def(
          "solve",
          [](const H& heat, const dcg::Points& heads, const dcg::Points& tails,
             const py::dict& options, py::object progress, const py::object& parents,
             const py::object& deform) {
            const dcg::WeightsOptions o = options_from_dict(options).weights;
            const dcg::Bones bones = make_bones(heads, tails, parents, deform);
            ProgressBridge bridge(std::move(progress));
            return run_released(bridge, [&] {
              return heat.solve(bones, o, nullptr, dcg::Progress(bridge.callback()));
            });
          },
          py::arg("heads"), py::arg("tails"), py::arg("options"), py::arg("progress") = py::none(),
          py::arg("parents") = py::none(), py::arg("deform") = py::none(),
          "#V x #B weights of the mesh's vertices.")
      .def(
          "nearest_visible_bones",
          [](const H& heat, const dcg::Points& heads, const dcg::Points& tails) {
            Eigen::VectorXi bone;
            Eigen::VectorXd distance;
            {
              py::gil_scoped_release release;
              heat.nearest_visible_bones(make_bones(heads, tails), bone, distance);
            }
            return py::make_tuple(to_int64(bone), distance);
          },
          py::arg("heads"), py::arg("tails"))
      .def_property_readonly("areas", &H::areas, py::return_value_policy::reference_internal);
}

}  // namespace

void bind_weights(py::module_& m) {
  bind_skin_weights_class(m);
  bind_bone_heat(m);
  m.def(
      "skin_weights",
      [](const dcg::Vertices& V, const Faces64& F, const dcg::Points& heads,
         const dcg::Points& tails, const py::dict& options, py::object progress,
         const py::object& parents, const py::object& deform) {
        const dcg::Faces faces = to_faces(F, V.rows());
        const dcg::Options o = options_from_dict(options);
        const dcg::Bones bones = make_bones(heads, tails, parents, deform);
        ProgressBridge bridge(std::move(progress));
        return run_released(bridge, [&] {
          return dcg::compute_skin_weights(V, faces, bones, o, bridge.callback());
        });
      },
      py::arg("V"), py::arg("F"), py::arg("heads"), py::arg("tails"), py::arg("options"),
      py::arg("progress") = py::none(), py::arg("parents") = py::none(),
      py::arg("deform") = py::none(),
      "Bone heat weights of V's vertices (on V itself, or stage 0's working mesh when large), "
      "as SkinWeights.");
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
         const Eigen::Vector3d& offset,
         const Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1>& map_face,
         const dcg::Vertices& map_barycentric, const dcg::Points& heads, const dcg::Points& tails,
         const py::dict& options, py::object progress, const py::object& parents,
         const py::object& deform) {
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
            throw dcg::InputError("map_face[" + std::to_string(i) +
                                  "] is outside the working mesh");
          }
          prepared.map_face[i] = static_cast<int>(map_face[i]);
        }
        prepared.map_barycentric = map_barycentric;
        const dcg::WeightsOptions o = options_from_dict(options).weights;
        const dcg::Bones bones = make_bones(heads, tails, parents, deform);
        ProgressBridge bridge(std::move(progress));
        return run_released(bridge, [&] {
          return dcg::compute_skin_weights(prepared, bones, o, bridge.callback());
        });
      },
      py::arg("working_V"), py::arg("working_F"), py::arg("scale"), py::arg("offset"),
      py::arg("map_face"), py::arg("map_barycentric"), py::arg("heads"), py::arg("tails"),
      py::arg("options"), py::arg("progress") = py::none(), py::arg("parents") = py::none(),
      py::arg("deform") = py::none(),
      "Bone heat weights from a stage-0 result (dcg.PreparedMesh's arrays).");
}

}  // namespace dcg_py
