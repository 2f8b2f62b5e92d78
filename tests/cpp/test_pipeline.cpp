// dcg/pipeline.h: the option table and validation, and the whole pipeline on shipped meshes.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "dcg/errors.h"
#include "dcg/io.h"
#include "dcg/pipeline.h"
#include "dcg/surface_query.h"

namespace {

std::string repo_file(const std::string& relative) {
  return std::string(DCG_SOURCE_DIR) + "/" + relative;
}

TEST(Options, DefaultsAreValidAndMatchTheDesign) {
  dcg::Options options;
  EXPECT_NO_THROW(options.validate());
  EXPECT_DOUBLE_EQ(dcg::get_numeric_option(options, "tau"), 0.85);
  EXPECT_DOUBLE_EQ(dcg::get_numeric_option(options, "samples"), 4000);
  EXPECT_DOUBLE_EQ(dcg::get_numeric_option(options, "min_gap"), 0.005);
  std::set<std::string> names;
  for (const auto& spec : dcg::numeric_option_specs()) {
    EXPECT_TRUE(names.insert(spec.name).second) << "duplicate option " << spec.name;
    EXPECT_FALSE(spec.description.empty()) << spec.name;
    EXPECT_LE(spec.minimum, dcg::get_numeric_option(options, spec.name)) << spec.name;
    EXPECT_GE(spec.maximum, dcg::get_numeric_option(options, spec.name)) << spec.name;
  }
}

TEST(Options, OutOfRangeUnknownAndFractionalValuesAreRejected) {
  dcg::Options options;
  EXPECT_THROW(dcg::set_numeric_option(options, "tau", 1.5), dcg::InputError);
  EXPECT_THROW(dcg::set_numeric_option(options, "tau", std::nan("")), dcg::InputError);
  EXPECT_THROW(dcg::set_numeric_option(options, "samples", 100.5), dcg::InputError);
  EXPECT_THROW(dcg::set_numeric_option(options, "no_such_option", 1), dcg::InputError);
  EXPECT_THROW(dcg::parse_repair("sometimes"), dcg::InputError);
  dcg::set_numeric_option(options, "samples", 500);
  EXPECT_EQ(options.samples, 500);
  options.rays = 1;  // set behind the table's back
  EXPECT_THROW(options.validate(), dcg::InputError);
}

TEST(Pipeline, SpotGivesAConnectedTreeInsideTheShape) {
  const dcg::Mesh mesh = dcg::read_mesh(repo_file("data/spot.obj"));
  dcg::Options options;
  options.target_faces = 6000;
  options.samples = 1500;
  std::vector<std::string> stages;
  dcg::Extractor extractor(mesh.V, mesh.F, options, [&](const std::string& stage, double) {
    stages.push_back(stage);
    return true;
  });
  const dcg::Skeleton& s = extractor.skeleton();
  const int n = static_cast<int>(s.positions.rows());
  ASSERT_GT(n, 1);
  ASSERT_EQ(s.kinds.size(), static_cast<size_t>(n));
  EXPECT_EQ(s.links.rows(), static_cast<Eigen::Index>(s.polylines.size()));
  EXPECT_EQ(s.links.rows(), n - 1) << "a genus-0 interim graph is a tree";
  EXPECT_GE(s.root, 0);
  EXPECT_EQ(s.face_labels.size(), mesh.F.rows());
  EXPECT_EQ(s.genus, 0);
  EXPECT_FALSE(stages.empty());
  EXPECT_EQ(stages.back(), "done");
  ASSERT_FALSE(s.timings.empty());
  EXPECT_EQ(s.timings.back().first, "total");

  // Every node and polyline point is inside the input mesh (a closed surface).
  dcg::SurfaceQuery inside(mesh);
  for (int i = 0; i < n; ++i) {
    EXPECT_TRUE(inside.inside(s.positions.row(i).transpose())) << "node " << i;
    EXPECT_GT(s.radii[i], 0);
  }
  for (size_t l = 0; l < s.polylines.size(); ++l) {
    const dcg::Points& p = s.polylines[l];
    ASSERT_GE(p.rows(), 2);
    EXPECT_TRUE(p.row(0).isApprox(s.positions.row(s.links(l, 0))));
    EXPECT_TRUE(p.row(p.rows() - 1).isApprox(s.positions.row(s.links(l, 1))));
  }
  // Each node's kind agrees with its degree.
  std::vector<int> degree(n, 0);
  for (Eigen::Index l = 0; l < s.links.rows(); ++l) {
    ++degree[s.links(l, 0)];
    ++degree[s.links(l, 1)];
  }
  for (int i = 0; i < n; ++i) {
    const dcg::NodeKind expected = degree[i] == 1   ? dcg::NodeKind::End
                                   : degree[i] >= 3 ? dcg::NodeKind::Joint
                                                    : dcg::NodeKind::Connection;
    EXPECT_EQ(s.kinds[i], expected) << "node " << i << " degree " << degree[i];
  }
}

TEST(Pipeline, ProgressCallbackCancels) {
  const dcg::Mesh mesh = dcg::read_mesh(repo_file("data/meshes/torus.off"));
  dcg::Extractor extractor(mesh.V, mesh.F, {}, [](const std::string&, double) { return false; });
  EXPECT_THROW(extractor.skeleton(), dcg::Cancelled);
}

TEST(Pipeline, SameInputSameSkeleton) {
  const dcg::Mesh mesh = dcg::read_mesh(repo_file("data/meshes/torus.off"));
  dcg::Options options;
  options.samples = 800;
  const dcg::Skeleton a = dcg::extract_skeleton(mesh.V, mesh.F, options);
  const dcg::Skeleton b = dcg::extract_skeleton(mesh.V, mesh.F, options);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.links, b.links);
  EXPECT_EQ(a.genus, 1);
}

}  // namespace
