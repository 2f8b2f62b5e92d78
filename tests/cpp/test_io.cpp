// dcg/io.h: reading OBJ, OFF, PLY and STL, and the errors for files that cannot be read.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "dcg/errors.h"
#include "dcg/io.h"

namespace {

namespace fs = std::filesystem;

std::string repo_file(const std::string& relative) {
  return std::string(DCG_SOURCE_DIR) + "/" + relative;
}

// A file in a fresh temporary folder, removed with the fixture.
class TempFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dcg_io_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  fs::path dir_;
};

const char* kTetraObj =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
    "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

TEST(ReadMesh, ReadsTheBundledSpot) {
  const dcg::Mesh mesh = dcg::read_mesh(repo_file("data/spot.obj"));
  EXPECT_EQ(mesh.V.rows(), 2930);
  EXPECT_EQ(mesh.F.rows(), 5856);
  EXPECT_GE(mesh.F.minCoeff(), 0);
  EXPECT_LT(mesh.F.maxCoeff(), mesh.V.rows());
}

TEST(ReadMesh, ReadsOff) {
  const dcg::Mesh mesh = dcg::read_mesh(repo_file("data/meshes/torus.off"));
  EXPECT_EQ(mesh.V.rows(), 576);
  EXPECT_EQ(mesh.F.rows(), 1152);
}

TEST_F(TempFiles, FanTriangulatesPolygons) {
  const std::string path = write("quad.obj",
                                 "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
                                 "f 1 2 3 4\nf 1 2 5\n");
  const dcg::Mesh mesh = dcg::read_mesh(path);
  ASSERT_EQ(mesh.F.rows(), 3);
  EXPECT_EQ(mesh.F.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(mesh.F.row(1), Eigen::RowVector3i(0, 2, 3));
}

TEST_F(TempFiles, ReadsAsciiPlyAndStl) {
  const std::string ply = write("t.ply",
                                "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                                "property float y\nproperty float z\nelement face 4\n"
                                "property list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  EXPECT_EQ(dcg::read_mesh(ply).F.rows(), 4);
  const std::string stl = write("t.stl",
                                "solid t\n"
                                "facet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\n"
                                "vertex 1 0 0\nendloop\nendfacet\n"
                                "facet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                "vertex 0 0 1\nendloop\nendfacet\nendsolid t\n");
  const dcg::Mesh m = dcg::read_mesh(stl);
  EXPECT_EQ(m.F.rows(), 2);
  EXPECT_GE(m.V.rows(), 4);
}

TEST(ReadMesh, MissingFileIsAnIoErrorNamingThePath) {
  try {
    dcg::read_mesh("/nonexistent/dir/mesh.obj");
    FAIL() << "expected IoError";
  } catch (const dcg::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/mesh.obj"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("no such file"), std::string::npos);
  }
}

TEST_F(TempFiles, EmptyFileIsAnInputError) {
  EXPECT_THROW(dcg::read_mesh(write("empty.obj", "")), dcg::InputError);
}

TEST_F(TempFiles, UnknownExtensionIsAnIoError) {
  EXPECT_THROW(dcg::read_mesh(write("mesh.xyz", kTetraObj)), dcg::IoError);
}

TEST_F(TempFiles, OutOfRangeIndexIsAnInputError) {
  const std::string path = write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n");
  try {
    dcg::read_mesh(path);
    FAIL() << "expected InputError";
  } catch (const dcg::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("face 1"), std::string::npos) << e.what();
  } catch (const dcg::IoError&) {
    // CGAL's reader may refuse the file itself: also a clean, catchable error.
  }
}

TEST_F(TempFiles, GarbageIsACleanError) {
  const std::string path = write("garbage.off", "OFF\n3 1 0\n0 0 zero\n");
  EXPECT_ANY_THROW(dcg::read_mesh(path));
}

}  // namespace
