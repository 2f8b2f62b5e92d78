// Mesh files: OBJ and STL through CGAL's polygon-soup IO (this translation unit is the only one
// that includes it), PLY and OFF through our own readers (ply_reader.cpp, off_reader.cpp), which
// bound every allocation by the file's size. See dcg/io.h.
#include "dcg/io.h"

#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "dcg/errors.h"
#include "mesh_readers.h"

namespace dcg {
namespace {

using internal::PolygonSoup;

using Kernel = CGAL::Simple_cartesian<double>;

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// OBJ and STL through CGAL. Faces as vectors of indices: reading into std::array<size_t, 3>
// corrupts the heap (the OBJ reader grows faces one index at a time; see ENVIRONMENT.md).
PolygonSoup read_with_cgal(const std::string& path, const std::string& ext) {
  std::vector<Kernel::Point_3> points;
  std::vector<std::vector<std::size_t>> polygons;
  bool ok = false;
  try {
    ok = CGAL::IO::read_polygon_soup(path, points, polygons, CGAL::parameters::verbose(false));
  } catch (const std::exception& e) {
    throw IoError(path + ": cannot be parsed (" + e.what() + ")");
  }
  if (!ok && points.empty()) throw IoError(path + ": cannot be parsed as " + ext.substr(1));
  PolygonSoup soup;
  soup.coordinates.reserve(3 * points.size());
  for (const auto& p : points)
    soup.coordinates.insert(soup.coordinates.end(), {p.x(), p.y(), p.z()});
  for (const auto& poly : polygons) {
    for (std::size_t index : poly) soup.corners.push_back(static_cast<double>(index));
    soup.sizes.push_back(poly.size());
  }
  return soup;
}

// Every reader's result becomes the mesh here: indices checked, polygons fan-triangulated.
Mesh mesh_from_soup(const std::string& path, const PolygonSoup& soup) {
  const std::size_t vertex_count = soup.coordinates.size() / 3;
  if (vertex_count == 0 || soup.sizes.empty()) {
    throw InputError(path + ": holds no triangles (" + std::to_string(vertex_count) +
                     " vertices, " + std::to_string(soup.sizes.size()) + " faces)");
  }
  std::size_t triangles = 0;
  for (std::size_t n : soup.sizes) triangles += n >= 3 ? n - 2 : 0;
  if (triangles == 0) throw InputError(path + ": holds no faces with 3 or more corners");
  Mesh mesh;
  mesh.V = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      soup.coordinates.data(), static_cast<Eigen::Index>(vertex_count), 3);
  mesh.F.resize(static_cast<Eigen::Index>(triangles), 3);
  Eigen::Index t = 0;
  std::size_t first = 0;  // the face's first corner in soup.corners
  for (std::size_t f = 0; f < soup.sizes.size(); first += soup.sizes[f], ++f) {
    const double* corner = soup.corners.data() + first;
    const std::size_t n = soup.sizes[f];
    for (std::size_t k = 0; k < n; ++k) {
      if (!(corner[k] >= 0) || corner[k] >= static_cast<double>(vertex_count)) {
        std::ostringstream index;
        index << std::setprecision(17) << corner[k];
        throw InputError(path + ": face " + std::to_string(f) + " refers to vertex " + index.str() +
                         " but the file has only " + std::to_string(vertex_count) + " vertices");
      }
    }
    for (std::size_t k = 1; k + 1 < n; ++k) {  // fan triangulation
      mesh.F.row(t++) << static_cast<int>(corner[0]), static_cast<int>(corner[k]),
          static_cast<int>(corner[k + 1]);
    }
  }
  return mesh;
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

  PolygonSoup soup;
  if (ext == ".ply") {
    soup = internal::read_ply(path);  // our own readers: CGAL's trust the file's counts
  } else if (ext == ".off") {
    soup = internal::read_off(path);
  } else {
    soup = read_with_cgal(path, ext);
  }
  return mesh_from_soup(path, soup);
}

}  // namespace dcg
