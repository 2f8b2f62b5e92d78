// Mesh files: OBJ and STL through CGAL's polygon-soup IO (this translation unit is the only one
// that includes it), PLY and OFF through our own readers (ply_reader.cpp, off_reader.cpp), which
// bound every allocation by the file's size. See dcg/io.h.
#include "dcg/io.h"

#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <cstdint>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dcg/errors.h"
#include "mesh_readers.h"

namespace dcg {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
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
  // Our own readers for PLY and OFF (CGAL's trust the file's counts: see mesh_readers.h).
  if (ext == ".ply") return internal::read_ply(path);
  if (ext == ".off") return internal::read_off(path);
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
