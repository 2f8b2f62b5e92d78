// Mesh files through CGAL's polygon-soup IO (this translation unit is the only one that
// includes it). See dcg/io.h.
#include "dcg/io.h"

#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "dcg/errors.h"

namespace dcg {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// CGAL's PLY reader (PLY_reader.h, init) adds each "property" to the last "element" seen
// without checking that there is one: a property line before any element line reads through
// an empty vector and crashes (found by fuzzing: tests/fuzz/corpus/read_mesh/crash-ply-*).
// This checks the header's text first; everything else is left to CGAL.
void check_ply_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  bool element = false;
  for (int number = 1; number <= 100000 && std::getline(in, line); ++number) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "end_header") return;
    if (keyword == "element") element = true;
    if (keyword == "property" && !element) {
      throw InputError(path + ": line " + std::to_string(number) +
                       " of the PLY header declares a property before any element");
    }
  }
}

}  // namespace

Mesh read_mesh(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  std::error_code ec;
  if (!fs::exists(p, ec)) throw IoError(path + ": no such file");
  if (fs::is_directory(p, ec)) throw IoError(path + ": is a directory, not a mesh file");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw IoError(path + ": cannot be opened for reading");
  }
  const std::string ext = lower_extension(p);
  if (ext != ".obj" && ext != ".off" && ext != ".ply" && ext != ".stl") {
    throw IoError(path + ": unsupported format '" + ext + "' (use .obj, .off, .ply or .stl)");
  }
  if (fs::file_size(p, ec) == 0) throw InputError(path + ": the file is empty");

  // Faces as vectors of indices: reading into std::array<size_t, 3> corrupts the heap (the OBJ
  // reader grows faces one index at a time; see ENVIRONMENT.md).
  if (ext == ".ply") check_ply_header(path);
  std::vector<Kernel::Point_3> points;
  std::vector<std::vector<std::size_t>> polygons;
  bool ok = false;
  try {
    ok = CGAL::IO::read_polygon_soup(path, points, polygons, CGAL::parameters::verbose(false));
  } catch (const std::exception& e) {
    throw IoError(path + ": cannot be parsed (" + e.what() + ")");
  }
  if (!ok && points.empty()) throw IoError(path + ": cannot be parsed as " + ext.substr(1));
  if (points.empty() || polygons.empty()) {
    throw InputError(path + ": holds no triangles (" + std::to_string(points.size()) +
                     " vertices, " + std::to_string(polygons.size()) + " faces)");
  }

  Mesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    mesh.V.row(static_cast<Eigen::Index>(i)) << points[i].x(), points[i].y(), points[i].z();
  }
  std::size_t triangles = 0;
  for (const auto& poly : polygons) triangles += poly.size() >= 3 ? poly.size() - 2 : 0;
  if (triangles == 0) throw InputError(path + ": holds no faces with 3 or more corners");
  mesh.F.resize(static_cast<Eigen::Index>(triangles), 3);
  Eigen::Index t = 0;
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const auto& poly = polygons[f];
    for (std::size_t index : poly) {
      if (index >= points.size()) {
        throw InputError(path + ": face " + std::to_string(f) + " refers to vertex " +
                         std::to_string(index) + " but the file has only " +
                         std::to_string(points.size()) + " vertices");
      }
    }
    for (std::size_t k = 1; k + 1 < poly.size(); ++k) {  // fan triangulation
      mesh.F.row(t++) << static_cast<int>(poly[0]), static_cast<int>(poly[k]),
          static_cast<int>(poly[k + 1]);
    }
  }
  return mesh;
}

}  // namespace dcg
