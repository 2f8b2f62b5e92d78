// dcg/io.h: reading OBJ, OFF, PLY and STL, and the errors for files that cannot be read.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "dcg/errors.h"
#include "dcg/io.h"
#include "shapes.h"

namespace {

namespace fs = std::filesystem;
using dcg::test::repo_file;

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

// PLY is read by our own reader (cpp/src/ply_reader.cpp): binary in both byte orders, any
// scalar type for the coordinates, elements and properties it does not use read past.
TEST_F(TempFiles, ReadsBinaryPlyInBothByteOrdersAndSkipsOtherElements) {
  auto header = [](const std::string& format) {
    return "ply\r\nformat " + format +
           " 1.0\r\ncomment made by a test\r\n"
           "element vertex 4\r\nproperty double x\r\nproperty float y\r\nproperty short z\r\n"
           "element edge 1\r\nproperty list ushort int pair\r\n"
           "element face 2\r\nproperty uchar flags\r\nproperty list uchar uint vertex_index\r\n"
           "end_header\r\n";
  };
  // Values written little-endian; big-endian files get each value's bytes reversed.
  auto body = [](bool big) {
    std::string out;
    auto put = [&](const auto value) {
      std::string b(reinterpret_cast<const char*>(&value), sizeof value);
      if (big) b.assign(b.rbegin(), b.rend());
      out += b;
    };
    const double xs[4] = {0, 1, 1, 0};
    const float ys[4] = {0, 0, 1, 1};
    for (int i = 0; i < 4; ++i) {
      put(xs[i]);
      put(ys[i]);
      put(static_cast<std::int16_t>(i == 3 ? -2 : 0));
    }
    put(static_cast<std::uint16_t>(2));  // the edge: two ints
    put(std::int32_t{7});
    put(std::int32_t{8});
    put(std::uint8_t{0});  // face 0: flags, then a quad
    put(std::uint8_t{4});
    for (std::uint32_t i : {0u, 1u, 2u, 3u}) put(i);
    put(std::uint8_t{1});  // face 1: a triangle
    put(std::uint8_t{3});
    for (std::uint32_t i : {0u, 2u, 1u}) put(i);
    return out;
  };
  for (const bool big : {false, true}) {
    const dcg::Mesh m = dcg::read_mesh(
        write(big ? "big.ply" : "little.ply",
              header(big ? "binary_big_endian" : "binary_little_endian") + body(big)));
    ASSERT_EQ(m.V.rows(), 4) << big;
    EXPECT_EQ(m.V.row(2), Eigen::RowVector3d(1, 1, 0)) << big;
    EXPECT_EQ(m.V(3, 2), -2) << big;
    ASSERT_EQ(m.F.rows(), 3) << big;
    EXPECT_EQ(m.F.row(1), Eigen::RowVector3i(0, 2, 3)) << big;
    EXPECT_EQ(m.F.row(2), Eigen::RowVector3i(0, 2, 1)) << big;
  }
}

TEST_F(TempFiles, MalformedPlyFilesAreInputErrorsThatSayWhy) {
  const std::string head =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n";
  const std::string vertices(36, '\0');
  struct Case {
    const char* name;
    std::string text;
    const char* says;
  };
  const Case cases[] = {
      // Found by fuzzing: CGAL read a list count of type int32 as it was and allocated it
      // (about 4.6 GB for 0xffffffff read as -1 then widened).
      {"list-count.ply",
       head + "property list int int vertex_indices\nend_header\n" + vertices +
           std::string("\xff\xff\xff\x7f", 4) + std::string(12, '\0'),
       "more than the rest of the file holds"},
      {"negative-count.ply",
       head + "property list int int vertex_indices\nend_header\n" + vertices +
           std::string("\xff\xff\xff\xff", 4),
       "more than the rest of the file holds"},
      {"truncated.ply",
       head + "property list uchar int vertex_indices\nend_header\n" + std::string(30, '\0'),
       "ends early"},
      {"index.ply",
       head + "property list uchar int vertex_indices\nend_header\n" + vertices + "\x03" +
           std::string("\x00\x00\x00\x00\x01\x00\x00\x00\x09\x00\x00\x00", 12),
       "refers to vertex 9"},
      {"no-end.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", "ends before end_header"},
      {"format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n", "format"},
      {"no-z.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "end_header\n0 0\n",
       "x, y, z"},
      {"float-index.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
       "property float y\nproperty float z\nelement face 1\n"
       "property list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n",
       "whole number"},
      {"word.ply",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n0 zero 0\n",
       "'zero'"},
  };
  for (const Case& c : cases) {
    try {
      dcg::read_mesh(write(c.name, c.text));
      ADD_FAILURE() << c.name << " was read";
    } catch (const dcg::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(c.name), std::string::npos) << what;
      EXPECT_NE(what.find(c.says), std::string::npos) << c.name << ": " << what;
    }
  }
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
